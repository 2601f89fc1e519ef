#pragma once
// Terrain scenarios (config/terrain/*.yaml): segments placed one after another along x. Each segment starts at
// the height where the previous one ended; the ground is flat before the first segment and after the last.
// Heights are those of the model's point foot resting on the ground (see foot_collision_radius_m in sim.yaml).
#include <cstdint>
#include <string>
#include <vector>

namespace mft::sim {

enum class SegmentType {
  Flat,   // level ground
  Board,  // a plank lying on the ground: steps up by height_m at its start, down again at its end
  Slope,  // a ramp at angle_deg (positive = uphill in +x)
  Rough,  // seeded random bumps of up to amplitude_m above the level, every spacing_m (ends at the level)
};

struct TerrainSegment {
  SegmentType type = SegmentType::Flat;
  double x0 = 0.0, length = 0.0;  // [x0, x0 + length]
  double z0 = 0.0;                // level at the start
  double height = 0.0;            // board
  double angle_rad = 0.0;         // slope
  double friction = -1.0;         // Coulomb coefficient; < 0 = the robot description's
  std::vector<double> samples;    // rough: heights above z0 at x0 + i * spacing
  double spacing = 0.0;
  double x1() const { return x0 + length; }
  double endLevel() const;
  double heightAt(double x) const;  // x inside the segment
};

struct Terrain {
  std::string source_file;
  double start_x = 0.0;
  double start_height = 0.0;
  std::vector<TerrainSegment> segments;

  // Nominal height of the resting foot point at x (flat continuation outside the segments).
  double heightAt(double x) const;
  // Friction coefficient at x (< 0: the robot description's).
  double frictionAt(double x) const;
  double endX() const { return segments.empty() ? start_x : segments.back().x1(); }
  double endHeight() const { return segments.empty() ? start_height : segments.back().endLevel(); }

  // Level ground at z = 0 with the description's friction.
  static Terrain flat();
};

// Strict loading: a missing or unknown key is a config::ConfigError naming the file and the segment.
Terrain loadTerrain(const std::string& path);
Terrain parseTerrain(const std::string& yaml_text, const std::string& origin);

const char* segmentTypeName(SegmentType t);

}  // namespace mft::sim
