#include "sim/terrain.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>

#include "common/strict_yaml.hpp"
#include "sim/random.hpp"

namespace mft::sim {
namespace {

using config::ConfigError;
using config::EnumName;
using config::StrictNode;

constexpr EnumName<SegmentType> kSegmentTypeNames[] = {{SegmentType::Flat, "flat"},
                                                       {SegmentType::Board, "board"},
                                                       {SegmentType::Slope, "slope"},
                                                       {SegmentType::Rough, "rough"}};

// StrictNode reads mappings only; a list of segments is split into one strict mapping per entry.
StrictNode strictFromYaml(const YAML::Node& node, const std::string& origin) {
  YAML::Emitter out;
  out << node;
  return StrictNode::loadString(out.c_str(), origin);
}

TerrainSegment readSegment(StrictNode& n, double x0, double z0) {
  TerrainSegment s;
  s.x0 = x0;
  s.z0 = z0;
  const std::string type = n.text("type");
  s.length = n.inRange("length_m", 1e-3, 1e4);
  if (n.has("friction")) s.friction = n.inRange("friction", 0.0, 10.0);
  if (!config::parseName(kSegmentTypeNames, type, &s.type))
    n.fail("type", "expected " + config::nameList(kSegmentTypeNames) + ", got '" + type + "'");
  if (s.type == SegmentType::Board) {
    s.height = n.inRange("height_m", 1e-4, 1.0);
  } else if (s.type == SegmentType::Slope) {
    s.angle_rad = n.inRange("angle_deg", -45.0, 45.0) * M_PI / 180.0;
  } else if (s.type == SegmentType::Rough) {
    const double amplitude = n.inRange("amplitude_m", 0.0, 0.5);
    const double spacing = n.inRange("spacing_m", 1e-3, 10.0);
    const int seed = n.nonNegativeInteger("seed");
    const int cells = std::max(2, static_cast<int>(std::lround(s.length / spacing)));
    s.spacing = s.length / cells;
    SplitMix64 rng(static_cast<std::uint64_t>(seed));
    s.samples.resize(static_cast<std::size_t>(cells) + 1);
    for (std::size_t i = 0; i < s.samples.size(); ++i) s.samples[i] = amplitude * rng.uniform();
    s.samples.front() = 0.0;  // join the level ground on both sides
    s.samples.back() = 0.0;
  }
  n.finish();
  return s;
}

Terrain read(const YAML::Node& root, const std::string& origin) {
  if (!root.IsMap()) throw ConfigError(origin + ": expected a mapping of keys at the top level");
  YAML::Node list = root["terrain"];
  if (!list) throw ConfigError(origin + ": terrain: missing key");
  if (!list.IsSequence()) throw ConfigError(origin + ": terrain: expected a list of segments");
  YAML::Node top = YAML::Clone(root);
  top.remove("terrain");
  Terrain t;
  t.source_file = origin;
  auto head = strictFromYaml(top, origin);
  head.useSchema("terrain");
  head.expectSchemaVersion(1);
  t.start_x = head.number("start_x_m");
  t.start_height = head.number("start_height_m");
  head.finish();
  double x = t.start_x, z = t.start_height;
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (!list[i].IsMap()) throw ConfigError(origin + ": terrain[" + std::to_string(i) + "]: expected a mapping");
    auto seg = strictFromYaml(list[i], origin + ": terrain[" + std::to_string(i) + "]");
    seg.useSchema("terrain", "terrain[]");
    t.segments.push_back(readSegment(seg, x, z));
    x = t.segments.back().x1();
    z = t.segments.back().endLevel();
  }
  return t;
}

}  // namespace

const char* segmentTypeName(SegmentType t) { return config::nameOf(kSegmentTypeNames, t); }

double TerrainSegment::endLevel() const {
  return type == SegmentType::Slope ? z0 + length * std::tan(angle_rad) : z0;
}

double TerrainSegment::heightAt(double x) const {
  switch (type) {
    case SegmentType::Flat: return z0;
    case SegmentType::Board: return z0 + height;
    case SegmentType::Slope: return z0 + (x - x0) * std::tan(angle_rad);
    case SegmentType::Rough: {
      // Piecewise linear between the samples, exactly like the collision solids.
      const double u = std::clamp((x - x0) / spacing, 0.0, static_cast<double>(samples.size() - 1));
      const std::size_t i = std::min(static_cast<std::size_t>(u), samples.size() - 2);
      const double f = u - static_cast<double>(i);
      return z0 + (1.0 - f) * samples[i] + f * samples[i + 1];
    }
  }
  return z0;
}

double Terrain::heightAt(double x) const {
  if (segments.empty() || x < start_x) return start_height;
  for (const auto& s : segments)
    if (x <= s.x1()) return s.heightAt(x);
  return endHeight();
}

double Terrain::frictionAt(double x) const {
  for (const auto& s : segments)
    if (x >= s.x0 && x <= s.x1()) return s.friction;
  return -1.0;
}

Terrain Terrain::flat() {
  Terrain t;
  t.source_file = "(flat)";
  return t;
}

Terrain loadTerrain(const std::string& path) { return read(config::readYamlFile(path), path); }

Terrain parseTerrain(const std::string& yaml_text, const std::string& origin) {
  return read(config::readYamlText(yaml_text, origin), origin);
}

}  // namespace mft::sim
