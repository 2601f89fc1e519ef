#include "common/config_schema.hpp"

#include <cctype>
#include <cstdio>

namespace mft::config {
namespace {

constexpr double kPi = 3.141592653589793;
constexpr double kSeedMax = 2147483647.0;

// Grouped by file. A range is what a legged robot of this size can physically use (a swing apex below the
// leg length, a gain the 1 kHz loop can integrate), wide enough for every shipped file and profile.
const std::vector<KeyRange> kRobot = {
    {"robot", "gravity_mps2", 1.0, 30.0, "m/s^2", "gravitational acceleration"},
    {"robot", "torso.mass_kg", 0.5, 500.0, "kg", "torso mass"},
    {"robot", "torso.com_m", -1.0, 1.0, "m", "torso centre of mass [x, z] from the hip axis"},
    {"robot", "torso.inertia_kgm2", 1e-4, 100.0, "kg m^2", "torso pitch inertia"},
    {"robot", "torso.size_m", 0.01, 3.0, "m", "torso box [length, height]"},
    {"robot", "torso.imu_position_m", -1.0, 1.0, "m", "IMU [x, z] from the hip axis"},
    {"robot", "leg.hip_spacing_m", 0.0, 1.0, "m", "distance between the rear and fore hips"},
    {"robot", "leg.thigh.length_m", 0.02, 2.0, "m", "thigh length l1"},
    {"robot", "leg.thigh.mass_kg", 0.01, 100.0, "kg", "thigh mass"},
    {"robot", "leg.thigh.com_from_hip_m", 0.0, 2.0, "m", "thigh centre of mass from the hip"},
    {"robot", "leg.thigh.inertia_kgm2", 1e-7, 10.0, "kg m^2", "thigh inertia"},
    {"robot", "leg.shank.length_m", 0.02, 2.0, "m", "shank length l2"},
    {"robot", "leg.shank.mass_kg", 0.01, 100.0, "kg", "shank mass"},
    {"robot", "leg.shank.com_from_knee_m", 0.0, 2.0, "m", "shank centre of mass from the knee"},
    {"robot", "leg.shank.inertia_kgm2", 1e-7, 10.0, "kg m^2", "shank inertia"},
    {"robot", "leg.foot_radius_m", 0.0, 0.2, "m", "foot radius"},
    {"robot", "joint_limits.rear_hip_rad", -kPi, kPi, "rad", "rear hip range"},
    {"robot", "joint_limits.fore_hip_rad", -kPi, kPi, "rad", "fore hip range"},
    {"robot", "joint_limits.rear_knee_rad", -kPi, kPi, "rad", "rear knee range"},
    {"robot", "joint_limits.fore_knee_rad", -kPi, kPi, "rad", "fore knee range"},
    {"robot", "joint_limits.knee_hard_stop_margin_rad", 0.0, 0.5, "rad", "hard stops inside the knee ranges"},
    {"robot", "actuator.gear_ratio", 1.0, 1000.0, "-", "gear ratio n"},
    {"robot", "actuator.rotor_inertia_kgm2", 1e-8, 0.1, "kg m^2", "rotor inertia J_m"},
    {"robot", "actuator.motor_peak_torque_Nm", 1e-3, 1000.0, "N m", "motor peak torque"},
    {"robot", "actuator.gearbox_efficiency", 0.05, 1.0, "-", "gearbox efficiency"},
    {"robot", "actuator.output_speed_limit_radps", 0.1, 1000.0, "rad/s", "joint speed limit"},
    {"robot", "actuator.sea.spring_stiffness_Nmprad", 1.0, 1e7, "N m/rad", "series spring stiffness"},
    {"robot", "actuator.sea.natural_frequency_radps", 1.0, 1e5, "rad/s", "torque loop natural frequency"},
    {"robot", "actuator.sea.damping_ratio", 0.05, 10.0, "-", "torque loop damping ratio"},
    {"robot", "actuator.sea.settling_time_s", 1e-4, 10.0, "s", "SEA settling time t_s"},
    {"robot", "contact.friction_coefficient", 0.01, 5.0, "-", "foot-ground friction coefficient"},
    {"robot", "contact.stiffness_Npm", 100.0, 1e9, "N/m", "ground spring"},
    {"robot", "contact.damping_Nspm", 0.0, 1e7, "N s/m", "ground damper"},
};

const std::vector<KeyRange> kWbc = {
    {"wbc", "horizon_settling_times", 0.1, 20.0, "-", "prediction horizon in SEA settling times"},
    {"wbc", "weights.base_z", 0.0, 1e8, "1/(m/s^2)^2", "base height task weight"},
    {"wbc", "weights.base_pitch", 0.0, 1e8, "1/(rad/s^2)^2", "base pitch task weight"},
    {"wbc", "weights.swing_foot", 0.0, 1e8, "1/(m/s^2)^2", "swing foot task weight"},
    {"wbc", "weights.support_foot", 0.0, 1e8, "1/(m/s^2)^2", "support foot task weight"},
    {"wbc", "weights.contact_force", 0.0, 1e8, "1/N^2", "contact force regularization"},
    {"wbc", "weights.contact_force_rate", 0.0, 1e8, "1/N^2", "contact force rate regularization"},
    {"wbc", "weights.slack", 0.0, 1e8, "1/rad^2", "MFT slack weight"},
    {"wbc", "weights.qdd_regularization", 0.0, 1e8, "1/(rad/s^2)^2", "acceleration regularization"},
    {"wbc", "weights.base_x", 0.0, 1e8, "1/(m/s^2)^2", "base x task weight (standing)"},
    // kp dt^2 and kd dt stay far below the stability limit of the 1 ms loop.
    {"wbc", "gains.base_z.kp", 0.0, 1e5, "1/s^2", "base height stiffness"},
    {"wbc", "gains.base_z.kd", 0.0, 1000.0, "1/s", "base height damping"},
    {"wbc", "gains.base_pitch.kp", 0.0, 1e5, "1/s^2", "base pitch stiffness"},
    {"wbc", "gains.base_pitch.kd", 0.0, 1000.0, "1/s", "base pitch damping"},
    {"wbc", "gains.swing_foot.kp", 0.0, 1e5, "1/s^2", "swing foot stiffness [x, z]"},
    {"wbc", "gains.swing_foot.kd", 0.0, 1000.0, "1/s", "swing foot damping [x, z]"},
    {"wbc", "gains.support_foot.kp", 0.0, 1e5, "1/s^2", "support foot stiffness [x, z]"},
    {"wbc", "gains.support_foot.kd", 0.0, 1000.0, "1/s", "support foot damping [x, z]"},
    {"wbc", "gains.base_x.kp", 0.0, 1e5, "1/s^2", "base x stiffness (standing)"},
    {"wbc", "gains.base_x.kd", 0.0, 1000.0, "1/s", "base x damping (standing)"},
    {"wbc", "limits.qdd_base_max", 0.1, 1000.0, "m/s^2, rad/s^2", "base acceleration box [x, z, pitch]"},
    {"wbc", "limits.qdd_joint_max_radps2", 1.0, 1e4, "rad/s^2", "joint acceleration box"},
    {"wbc", "limits.torque_limit_fraction", 0.0, 1.0, "-", "share of the actuator peak torque"},
    {"wbc", "contact.friction_fraction", 0.0, 5.0, "-", "share of robot.yaml's friction coefficient"},
    {"wbc", "contact.normal_force_max_N", 1.0, 1e5, "N", "largest normal force of a stance foot"},
    {"wbc", "sa.rear_knee_rad", -kPi, kPi, "rad", "SA-WBC rear knee bounds"},
    {"wbc", "sa.fore_knee_rad", -kPi, kPi, "rad", "SA-WBC fore knee bounds"},
    {"wbc", "safety.hold_ticks", 0.0, 10000.0, "ticks", "ticks the last good command is held"},
    {"wbc", "safety.damping_Nms_per_rad", 0.0, 100.0, "N m s/rad", "damping command gain"},
};

const std::vector<KeyRange> kPlanner = {
    {"planner", "gait.step_duration_s", 0.05, 5.0, "s", "swing duration T"},
    {"planner", "gait.double_support_s", 0.0, 5.0, "s", "double support after touchdown"},
    {"planner", "gait.min_touchdown_phase", 0.0, 1.0, "-", "earliest touchdown phase"},
    {"planner", "gait.max_extension_s", 0.0, 5.0, "s", "longest late-touchdown extension"},
    // Below the leg length (0.48 m): a higher apex cannot be reached.
    {"planner", "swing.lift_height_m", 0.0, 0.3, "m", "swing foot apex above the ground"},
    {"planner", "swing.touchdown_speed_mps", 0.0, 5.0, "m/s", "downward foot speed at touchdown"},
    {"planner", "swing.replan_until_phase", 0.0, 1.0, "-", "phase after which the target is frozen"},
    {"planner", "swing.late_replan_speed_mps", 0.0, 10.0, "m/s", "foot speed toward a late re-plan"},
    // eq. 13: the LIP orbit needs k_v = 1/sigma1, a fraction of a second for any walking robot.
    {"planner", "foot_placement.k_v", 0.0, 2.0, "s", "velocity gain k_v of eq. 13"},
    {"planner", "foot_placement.k_p", 0.0, 2.0, "s", "speed error gain k_p of eq. 13"},
    {"planner", "foot_placement.max_offset_m", 0.001, 1.0, "m", "clamp of the foot target from the CoM"},
    {"planner", "command.height_margin_m", 0.0, 0.2, "m", "margin inside the reachable heights"},
    {"planner", "command.height_window_m", 0.05, 2.0, "m", "operating height window"},
    {"planner", "command.max_speed_mps", 0.0, 5.0, "m/s", "largest speed command"},
    {"planner", "command.height_rate_mps", 0.001, 5.0, "m/s", "height reference rate"},
    {"planner", "command.initial.height_m", 0.05, 2.0, "m", "height command at start"},
    {"planner", "command.initial.speed_mps", -5.0, 5.0, "m/s", "speed command at start"},
};

const std::vector<KeyRange> kEstimator = {
    {"estimator", "timing.nominal_dt_s", 1e-5, 0.1, "s", "nominal update period"},
    {"estimator", "timing.max_dt_s", 1e-5, 1.0, "s", "longest period integrated"},
    {"estimator", "kalman.accel_noise_density_mps2_per_sqrt_hz", 1e-6, 100.0, "m/s^2/sqrt(Hz)", "IMU noise"},
    {"estimator", "kalman.foot_slip_density_m_per_sqrt_s", 1e-6, 10.0, "m/sqrt(s)", "foot slip noise"},
    {"estimator", "kalman.kinematic_position_std_m", 1e-6, 1.0, "m", "leg kinematics position noise"},
    {"estimator", "kalman.kinematic_velocity_std_mps", 1e-6, 10.0, "m/s", "leg kinematics velocity noise"},
    {"estimator", "kalman.ground_height_m", -100.0, 100.0, "m", "assumed ground height"},
    {"estimator", "kalman.ground_height_std_m", 1e-6, 10.0, "m", "ground height uncertainty"},
    {"estimator", "kalman.initial_position_std_m", 1e-6, 10.0, "m", "initial position uncertainty"},
    {"estimator", "kalman.initial_velocity_std_mps", 1e-6, 10.0, "m/s", "initial velocity uncertainty"},
    {"estimator", "pitch.correction_time_constant_s", 1e-3, 1000.0, "s", "accelerometer pitch correction"},
    {"estimator", "pitch.gyro_bias_gain_per_s2", 0.0, 100.0, "1/s^2", "gyro bias estimation gain"},
    {"estimator", "pitch.accel_gate_mps2", 1e-3, 100.0, "m/s^2", "acceleration gate of the correction"},
    {"estimator", "pitch.acceleration_filter_s", 1e-4, 10.0, "s", "accelerometer low-pass"},
    {"estimator", "contact.force_on_N", 0.0, 1e4, "N", "contact on above this force"},
    {"estimator", "contact.force_off_N", 0.0, 1e4, "N", "contact off below this force"},
    {"estimator", "ground_truth.contact_force_N", 0.0, 1e4, "N", "ground-truth contact threshold"},
};

const std::vector<KeyRange> kSim = {
    {"sim", "control_period_s", 1e-6, 0.1, "s", "control period"},
    {"sim", "substeps", 1.0, 100.0, "-", "physics steps per control period"},
    {"sim", "world.erp", 0.0, 1.0, "-", "ODE error reduction parameter"},
    {"sim", "world.cfm", 0.0, 1e-3, "-", "ODE constraint force mixing"},
    {"sim", "contact.foot_collision_radius_m", 1e-4, 0.05, "m", "foot collision sphere"},
    {"sim", "contact.friction_coefficient", 0.01, 5.0, "-", "simulated ground friction"},
    {"sim", "contact.stiffness_Npm", 100.0, 1e9, "N/m", "simulated ground spring"},
    {"sim", "contact.damping_Nspm", 0.0, 1e7, "N s/m", "simulated ground damper"},
    {"sim", "contact.max_contacts_per_geom", 1.0, 16.0, "-", "contact points per collision"},
    {"sim", "contact.switch_threshold_N", 0.0, 1e4, "N", "reported contact above this force"},
    {"sim", "contact.link_collision_radius_m", 1e-3, 0.1, "m", "leg link collision capsules"},
    {"sim", "hard_stops.stiffness_Nmprad", 1.0, 1e9, "N m/rad", "knee hard stop spring"},
    {"sim", "hard_stops.damping_Nmsprad", 0.0, 1e6, "N m s/rad", "knee hard stop damper"},
    {"sim", "actuators.speed_limit_band_radps", 1e-3, 100.0, "rad/s", "torque fade band at the speed limit"},
    {"sim", "actuators.damping_mode_gain_Nmsprad", 0.0, 1000.0, "N m s/rad", "damping command gain"},
    {"sim", "actuators.sea_motor.reflected_damping_Nmsprad", 0.0, 1000.0, "N m s/rad", "motor reflected damping"},
    {"sim", "actuators.sea_motor.torque_loop_period_s", 1e-6, 0.1, "s", "SEA torque loop period"},
    {"sim", "noise.seed", 0.0, kSeedMax, "-", "noise seed"},
    {"sim", "noise.encoder_position_std_rad", 0.0, 0.1, "rad", "encoder position noise"},
    {"sim", "noise.encoder_velocity_std_radps", 0.0, 10.0, "rad/s", "encoder velocity noise"},
    {"sim", "noise.sea_torque_std_Nm", 0.0, 100.0, "N m", "SEA torque noise"},
    {"sim", "noise.gyro_std_radps", 0.0, 10.0, "rad/s", "gyro noise"},
    {"sim", "noise.gyro_bias_radps", -10.0, 10.0, "rad/s", "gyro bias"},
    {"sim", "noise.accel_std_mps2", 0.0, 100.0, "m/s^2", "accelerometer noise"},
    {"sim", "noise.accel_bias_mps2", -100.0, 100.0, "m/s^2", "accelerometer bias [x, z]"},
};

const std::vector<KeyRange> kMftSpace = {
    {"mft_space", "thresholds.lti", 0.0, 1.0, "-", "LTI range of a preferable configuration"},
    {"mft_space", "thresholds.raci_N_per_sqrt_kg", 0.0, 1e4, "N/sqrt(kg)", "RACI range"},
    {"mft_space", "thresholds.accel_max_mps2", 0.1, 1e4, "m/s^2", "RACI acceleration"},
    {"mft_space", "thresholds.drive_k", 1e-6, 100.0, "sqrt(kg) m", "fixed drive n sqrt(J_m)"},
    {"mft_space", "thresholds.gearbox_efficiency", 1e-6, 1.0, "-", "gearbox efficiency of the RACI"},
    {"mft_space", "grid.joint_step_rad", 1e-4, 1.0, "rad", "joint grid step"},
    {"mft_space", "grid.cartesian_step_m", 1e-4, 1.0, "m", "Cartesian grid step"},
    {"mft_space", "grid.reachable_cells", 0.0, 1e9, "-", "reachable grid cells"},
    {"mft_space", "grid.preferable_cells", 0.0, 1e9, "-", "preferable grid cells"},
    {"mft_space", "fit.edges", 3.0, 64.0, "-", "polygon edges"},
    {"mft_space", "fit.starts", 1.0, 1e4, "-", "fit restarts"},
    {"mft_space", "fit.rng_seed", 0.0, kSeedMax, "-", "fit seed"},
    {"mft_space", "fit.area_rad2", 0.0, 4.0 * kPi * kPi, "rad^2", "polygon area"},
    {"mft_space", "fit.coverage", 0.0, 1.0, "-", "share of preferable cells covered"},
    {"mft_space", "fit.r_max_rad", 0.0, 2.0 * kPi, "rad", "largest distance of a bad cell inside"},
    {"mft_space", "fit.bad_cells_inside", 0.0, 1e9, "-", "bad cells inside the polygon"},
    {"mft_space", "leg_polygon.A", -1.0, 1.0, "-", "unit-normal rows of the leg polygon"},
    {"mft_space", "leg_polygon.b", -10.0, 10.0, "rad", "offsets of the leg polygon"},
    {"mft_space", "leg_polygon.vertices", -2.0 * kPi, 2.0 * kPi, "rad", "vertices of the leg polygon"},
    {"mft_space", "augmented.A", -1.0, 1.0, "-", "rows over both legs"},
    {"mft_space", "augmented.b", -10.0, 10.0, "rad", "offsets over both legs"},
};

const std::vector<KeyRange> kScenario = {
    {"scenario", "duration_s", 0.001, 3600.0, "s", "run length"},
    {"scenario", "initial_base_height_m", 0.1, 1.0, "m", "base height at start"},
    {"scenario", "initial_stance_width_m", 0.0, 0.4, "m", "distance between the feet at start"},
    {"scenario", "fall.base_height_below_m", 0.0, 1.0, "m", "fallen below this base height"},
    {"scenario", "fall.pitch_beyond_rad", 0.0, 3.2, "rad", "fallen beyond this pitch"},
    {"scenario", "recovery.window_s", 0.1, 10.0, "s", "recovery window after a push"},
    {"scenario", "recovery.max_speed_mps", 0.0, 10.0, "m/s", "recovered below this speed"},
    {"scenario", "recovery.height_band_m", 0.0, 1.0, "m", "recovered within this height band"},
    {"scenario", "recovery.max_pitch_rad", 0.0, 3.2, "rad", "recovered within this pitch"},
    {"scenario", "recovery.min_touchdowns", 0.0, 100.0, "-", "touchdowns a stepping recovery needs"},
    {"scenario", "commands[].at_s", 0.0, 3600.0, "s", "command time"},
    {"scenario", "commands[].z_cmd_m", 0.1, 1.0, "m", "height command"},
    {"scenario", "commands[].v_cmd_mps", -3.0, 3.0, "m/s", "speed command"},
    {"scenario", "pushes[].impulse_Ns", -100.0, 100.0, "N s", "push impulse"},
    {"scenario", "pushes[].at_s", 0.0, 3600.0, "s", "push time"},
    {"scenario", "pushes[].at_phase", 0.0, 1.0, "-", "push at this phase of the swing"},
};

const std::vector<KeyRange> kTerrain = {
    {"terrain", "start_x_m", -1000.0, 1000.0, "m", "x of the first segment"},
    {"terrain", "start_height_m", -100.0, 100.0, "m", "ground height before the first segment"},
    {"terrain", "terrain[].length_m", 1e-3, 1e4, "m", "segment length"},
    {"terrain", "terrain[].friction", 0.0, 5.0, "-", "segment friction coefficient"},
    {"terrain", "terrain[].height_m", 1e-4, 1.0, "m", "board height"},
    {"terrain", "terrain[].angle_deg", -45.0, 45.0, "deg", "slope angle"},
    {"terrain", "terrain[].amplitude_m", 0.0, 0.5, "m", "rough ground amplitude"},
    {"terrain", "terrain[].spacing_m", 1e-3, 10.0, "m", "rough ground sample spacing"},
    {"terrain", "terrain[].seed", 0.0, kSeedMax, "-", "rough ground seed"},
};

std::string shortNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// "commands[12].at_s" -> "commands[].at_s".
std::string withoutIndices(const std::string& key) {
  std::string out;
  for (std::size_t i = 0; i < key.size(); ++i) {
    out += key[i];
    if (key[i] != '[') continue;
    while (i + 1 < key.size() && std::isdigit(static_cast<unsigned char>(key[i + 1]))) ++i;
  }
  return out;
}

}  // namespace

const std::vector<KeyRange>& configSchema() {
  static const std::vector<KeyRange> all = [] {
    std::vector<KeyRange> v;
    for (const auto* group : {&kRobot, &kWbc, &kPlanner, &kEstimator, &kSim, &kMftSpace, &kScenario, &kTerrain})
      v.insert(v.end(), group->begin(), group->end());
    return v;
  }();
  return all;
}

const KeyRange* findKeyRange(const std::string& stem, const std::string& key) {
  const std::string plain = withoutIndices(key);
  for (const auto& r : configSchema())
    if (stem == r.stem && plain == r.key) return &r;
  return nullptr;
}

std::string rangeViolation(const KeyRange& range, double v) {
  if (v >= range.lo && v <= range.hi) return "";
  const std::string unit = std::string(range.unit) == "-" ? "" : std::string(" ") + range.unit;
  return "must lie in [" + shortNumber(range.lo) + ", " + shortNumber(range.hi) + "]" + unit + " (got " +
         shortNumber(v) + ")";
}

std::string schemaMarkdown() {
  std::string out;
  std::string stem;
  for (const auto& r : configSchema()) {
    if (stem != r.stem) {
      stem = r.stem;
      out += std::string(out.empty() ? "" : "\n") + "### " + stem + "\n\n| key | min | max | unit | meaning |\n" +
             "|---|---|---|---|---|\n";
    }
    out += std::string("| `") + r.key + "` | " + shortNumber(r.lo) + " | " + shortNumber(r.hi) + " | " + r.unit +
           " | " + r.meaning + " |\n";
  }
  return out;
}

}  // namespace mft::config
