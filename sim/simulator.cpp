#include "sim/simulator.hpp"

#include <ode/ode.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdarg>
#include <cstring>
#include <iterator>
#include <limits>
#include <mutex>
#include <stdexcept>

#include "model/five_bar.hpp"
#include "model/mft_indices.hpp"
#include "sim/ode_robot.hpp"
#include "sim/ode_terrain.hpp"
#include "sim/sea_actuator.hpp"
#include "sim/sensor_noise.hpp"

static_assert(sizeof(dReal) == 8, "mft_sim needs libode built with double precision (dDOUBLE)");

namespace mft::sim {
namespace {

using Eigen::Vector2d;
using model::kNa;
using model::kNumLegs;

std::atomic<std::uint64_t> g_ode_messages{0};
void countMessage(int, const char*, va_list) { ++g_ode_messages; }

void initOdeForThisThread() {
  static std::once_flag once;
  std::call_once(once, [] {
    dInitODE2(0);
    dSetMessageHandler(&countMessage);  // warnings (e.g. LCP internal errors) are counted, not printed
  });
  dAllocateODEDataForThread(dAllocateMaskAll);
  if (!dCheckConfiguration("ODE_double_precision"))
    throw std::runtime_error("mft_sim: libode is not built with double precision (dCheckConfiguration)");
}

Vector2d rot(double a, const Vector2d& v) {
  const double c = std::cos(a), s = std::sin(a);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

constexpr int kTerrainGeomsPerFoot = 4;  // contacts from up to this many terrain solids per foot and step

}  // namespace

struct Simulator::Impl {
  explicit Impl(const NoiseOptions& n) : noise(n) {}
  ~Impl() {
    destroyRobotGeoms(&robot);
    if (world) dWorldDestroy(world);
    if (contact_group) dJointGroupDestroy(contact_group);
  }

  dWorldID world = nullptr;
  dJointGroupID contact_group = nullptr;
  std::unique_ptr<OdeTerrain> terrain;
  OdeRobot robot;
  std::array<SeaActuator, kNa> sea;
  std::array<SeaMotorActuator, kNa> sea_motor;  // ActuatorModel::SeaMotor
  std::array<double, kNa> sea_command{};        // SeaMotor: the command held over the physics step
  std::array<double, kNa> sea_input{};
  std::array<double, kNa> applied{};  // joint torque of the last physics step (the SEA torque sensor)
  SensorNoise noise;

  // Contacts: the feedback pool is sized once and never reallocated during a step (docs/reference/simulation.md#contacts).
  std::vector<dContact> buffer;
  std::vector<dJointFeedback> feedback;
  std::vector<int> feedback_leg;
  std::vector<Vector2d> feedback_normal;
  std::size_t n_feedback = 0;
  bool body_contact = false;
  BodyContact step_body_contact;  // the first body contact found in this physics step
  double soft_erp = 0.0, soft_cfm = 0.0, friction = 0.8;
  const Terrain* terrain_desc = nullptr;

  // Per control period.
  std::array<Vector2d, kNumLegs> force_sum{{Vector2d::Zero(), Vector2d::Zero()}};
  std::array<double, kNumLegs> normal_sum{};
  std::array<bool, kNumLegs> in_contact{};
  std::array<bool, kNumLegs> liftoff_flag{};
  std::vector<ImpulseSpec> pending;
  std::uint64_t messages_at_reset = 0;

  // The robot geom being collided, and its leg (-1: link or torso).
  dGeomID current_geom = nullptr;
  int current_leg = -1;
  int current_body = -1;  // index of current_geom in robot.body_geoms (-1: a foot)

  static void nearCallback(void* data, dGeomID o1, dGeomID o2);
  void collide();
};

void Simulator::Impl::nearCallback(void* data, dGeomID o1, dGeomID o2) {
  auto* self = static_cast<Impl*>(data);
  if (o1 != self->current_geom) std::swap(o1, o2);  // o1 = robot geom: normals point into it
  const int max = static_cast<int>(self->buffer.size());
  const int n = dCollide(o1, o2, max, &self->buffer[0].geom, sizeof(dContact));
  dBodyID body = dGeomGetBody(o1);
  for (int i = 0; i < n; ++i) {
    dContact& c = self->buffer[static_cast<std::size_t>(i)];
    const int leg = self->current_leg;
    if (leg >= 0 && self->n_feedback >= self->feedback.size()) break;  // pool full: keep the rows we have
    const double mu = self->terrain_desc->frictionAt(c.geom.pos[0]);
    c.surface.mode = dContactApprox1 | dContactSoftERP | dContactSoftCFM | dContactMu2 | dContactFDir1;
    c.surface.mu = mu >= 0.0 ? mu : self->friction;  // Approx1: a Coulomb coefficient (docs/reference/simulation.md#contacts)
    c.surface.mu2 = 0.0;
    c.surface.soft_erp = self->soft_erp;
    c.surface.soft_cfm = self->soft_cfm;
    c.surface.bounce = 0.0;
    // One sagittal friction row: fdir1 = lateral (ODE z) x normal.
    const double nx = c.geom.normal[0], ny = c.geom.normal[1];
    const double nn = std::hypot(nx, ny);
    c.fdir1[0] = -ny / nn;
    c.fdir1[1] = nx / nn;
    c.fdir1[2] = 0.0;
    if (leg >= 0) {
      // The model's point foot is the ankle: apply the contact force there (no friction moment about it).
      const dReal* centre = dGeomGetPosition(o1);
      c.geom.pos[0] = centre[0];
      c.geom.pos[1] = centre[1];
      c.geom.pos[2] = centre[2];
    } else {
      if (!self->body_contact) {
        BodyContact& b = self->step_body_contact;
        b.seen = true;
        b.body = self->current_body;
        b.point = Vector2d(c.geom.pos[0], c.geom.pos[1]);
        b.normal = Vector2d(nx, ny);
        b.depth_m = c.geom.depth;
      }
      self->body_contact = true;
    }
    dJointID j = dJointCreateContact(self->world, self->contact_group, &c);
    dJointAttach(j, body, nullptr);
    if (leg >= 0) {
      dJointSetFeedback(j, &self->feedback[self->n_feedback]);
      self->feedback_leg[self->n_feedback] = leg;
      self->feedback_normal[self->n_feedback] = Vector2d(nx, ny);
      ++self->n_feedback;
    }
  }
}

void Simulator::Impl::collide() {
  n_feedback = 0;
  body_contact = false;
  dGeomID space = reinterpret_cast<dGeomID>(terrain->space());
  // Fixed order (feet, then links) keeps the constraint order, hence the trajectory, reproducible.
  for (int leg = 0; leg < kNumLegs; ++leg) {
    current_geom = robot.foot[leg];
    current_leg = leg;
    dSpaceCollide2(current_geom, space, this, &nearCallback);
  }
  current_leg = -1;
  for (std::size_t i = 0; i < robot.body_geoms.size(); ++i) {
    current_geom = robot.body_geoms[i];
    current_body = static_cast<int>(i);
    dSpaceCollide2(current_geom, space, this, &nearCallback);
  }
  current_body = -1;
}

const char* robotBodyName(int body) {
  // The order of OdeRobot::body_geoms (buildRobot): the torso box, then per leg (right, left) and side (rear,
  // fore) the thigh and the shank capsule.
  static const char* const kNames[] = {"torso",           "right rear thigh", "right rear shank",
                                       "right fore thigh", "right fore shank", "left rear thigh",
                                       "left rear shank",  "left fore thigh",  "left fore shank"};
  return body >= 0 && body < static_cast<int>(std::size(kNames)) ? kNames[body] : "none";
}

Simulator::Simulator(const model::RobotDescription& robot, const SimOptions& options, const Terrain& terrain)
    : robot_(robot), options_(options), terrain_(terrain), h_(options.physicsStep()) {
  initOdeForThisThread();
  impl_ = std::make_unique<Impl>(options_.noise);
  Impl& m = *impl_;
  m.terrain_desc = &terrain_;
  const double kp = options_.contact_override_description ? options_.contact_stiffness_Npm : robot_.contact_stiffness_Npm;
  const double kd = options_.contact_override_description ? options_.contact_damping_Nspm : robot_.contact_damping_Nspm;
  m.friction = options_.contact_override_description ? options_.friction_coefficient : robot_.friction_coefficient;
  // Spring-damper contacts from the physics step (docs/reference/simulation.md#contacts).
  m.soft_erp = h_ * kp / (h_ * kp + kd);
  m.soft_cfm = 1.0 / (h_ * kp + kd);
  m.terrain = std::make_unique<OdeTerrain>(terrain_, options_.foot_collision_radius_m);
  m.contact_group = dJointGroupCreate(0);
  m.buffer.resize(static_cast<std::size_t>(options_.max_contacts_per_geom));
  const std::size_t pool = static_cast<std::size_t>(kNumLegs * kTerrainGeomsPerFoot * options_.max_contacts_per_geom);
  m.feedback.resize(pool);
  m.feedback_leg.resize(pool);
  m.feedback_normal.resize(pool);
  const auto& a = robot_.actuator;
  const SeaLimits limits{a.outputPeakTorque(), a.output_speed_limit_radps, options_.speed_limit_band_radps};
  for (auto& s : m.sea) s = SeaActuator(a.sea.natural_frequency_radps, a.sea.damping_ratio, h_, limits);
  if (options_.actuator_model == ActuatorModel::SeaMotor) {
    SeaMotorParams mp;
    mp.reflected_inertia_kgm2 = a.gear_ratio * a.gear_ratio * a.rotor_inertia_kgm2;
    mp.spring_stiffness_Nmprad = a.sea.spring_stiffness_Nmprad;
    mp.reflected_damping_Nmsprad = options_.sea_motor_reflected_damping_Nmsprad;
    mp.natural_frequency_radps = a.sea.natural_frequency_radps;
    mp.damping_ratio = a.sea.damping_ratio;
    mp.loop_period_s = options_.sea_motor_torque_loop_period_s;
    for (auto& s : m.sea_motor) s = SeaMotorActuator(mp, h_, limits);
  }
  reset(StandingPose{});
}

Simulator::~Simulator() = default;

Simulator::StandingConfiguration Simulator::standingConfiguration(const StandingPose& pose) const {
  StandingConfiguration out;
  const double weight = robot_.totalMass() * robot_.gravity_mps2;
  const double kp = options_.contact_override_description ? options_.contact_stiffness_Npm : robot_.contact_stiffness_Npm;
  const double sink = pose.settle && pose.leg_length_m <= 0.0 ? 0.5 * weight / kp : 0.0;  // static spring deflection, half the weight per foot
  const Vector2d base(pose.base_x_m, terrain_.heightAt(pose.base_x_m) + pose.base_height_m);
  out.q[model::kBaseX] = base.x();
  out.q[model::kBaseZ] = base.y();
  out.q[model::kBasePitch] = pose.pitch_rad;
  const auto g = model::FiveBarGeometry::from(robot_);
  for (int leg = 0; leg < kNumLegs; ++leg) {
    const double x = pose.base_x_m + pose.foot_offset_x_m[static_cast<std::size_t>(leg)];
    const Vector2d foot_in_base =
        pose.leg_length_m > 0.0 ? Vector2d(pose.foot_offset_x_m[static_cast<std::size_t>(leg)], -pose.leg_length_m)
                                : rot(-pose.pitch_rad, Vector2d(x, footRestHeight(x, sink)) - base);
    model::FiveBarPose p;
    if (model::fiveBarInverse(g, foot_in_base, &p) != model::FiveBarStatus::Ok)
      throw std::invalid_argument("Simulator::reset: the foot of leg " + std::to_string(leg) + " is out of reach");
    const auto c = model::legCoordinates(p);
    for (int i = 0; i < 4; ++i) out.q[3 + 4 * leg + i] = c[static_cast<std::size_t>(i)];
    if (pose.settle && pose.leg_length_m <= 0.0) {
      const Eigen::Vector2d f = rot(-pose.pitch_rad, Vector2d(0.0, 0.5 * weight));  // ground on foot, base frame
      const Eigen::Vector2d tau = -model::fiveBarFootJacobian(g, p).transpose() * f;
      out.holding_torque[2 * leg] = tau[0];
      out.holding_torque[2 * leg + 1] = tau[1];
    }
  }
  return out;
}

void Simulator::reset(const StandingPose& pose) {
  const auto c = standingConfiguration(pose);
  setState(c.q, model::VectorQ::Zero(), c.holding_torque);
}

void Simulator::setState(const model::VectorQ& q, const model::VectorQ& qd, const model::VectorA& sea_torque) {
  rebuild(q, qd, sea_torque);
}

void Simulator::rebuild(const model::VectorQ& q, const model::VectorQ& qd, const model::VectorA& sea_torque) {
  initOdeForThisThread();
  Impl& m = *impl_;
  // A fresh world per episode: the state after a reset never depends on what ran before (determinism).
  destroyRobotGeoms(&m.robot);
  if (m.world) dWorldDestroy(m.world);
  m.world = dWorldCreate();
  dWorldSetGravity(m.world, 0.0, -robot_.gravity_mps2, 0.0);  // Y-up ODE world
  dWorldSetERP(m.world, options_.erp);
  dWorldSetCFM(m.world, options_.cfm);
  RobotBuildParams p;
  p.foot_radius = options_.foot_collision_radius_m;
  const double ks = options_.hard_stop_stiffness_Nmprad, ds = options_.hard_stop_damping_Nmsprad;
  p.stop_erp = h_ * ks / (h_ * ks + ds);
  p.stop_cfm = 1.0 / (h_ * ks + ds);
  try {
    buildRobot(m.world, robot_, options_, p, q, qd, &m.robot);
  } catch (...) {
    destroyRobotGeoms(&m.robot);
    throw;
  }
  for (int i = 0; i < kNa; ++i) {
    m.sea[static_cast<std::size_t>(i)].reset(sea_torque[i]);
    m.sea_motor[static_cast<std::size_t>(i)].reset(sea_torque[i], qd[model::kActuatedIndex[static_cast<std::size_t>(i)]]);
    m.sea_command[static_cast<std::size_t>(i)] = sea_torque[i];
    m.sea_input[static_cast<std::size_t>(i)] = sea_torque[i];
    m.applied[static_cast<std::size_t>(i)] = sea_torque[i];
  }
  command_ = model::ActuatorCommand{};
  command_.tau = sea_torque;  // hold what the SEAs already deliver until the first command
  tick_ = 0;
  time_ = 0.0;
  stats_ = SimStats{};
  m.pending.clear();
  m.liftoff_flag = {};
  m.force_sum.fill(Vector2d::Zero());
  m.normal_sum = {};
  m.noise.reseed();
  m.messages_at_reset = g_ode_messages.load();
  for (int leg = 0; leg < kNumLegs; ++leg) {
    const Vector2d a = ankle(m.robot, leg, options_);
    m.in_contact[static_cast<std::size_t>(leg)] =
        m.terrain->sphereDepth(a.x(), a.y(), options_.foot_collision_radius_m) > 0.0;
  }
  const Vector2d v = imuVelocity();
  refreshOutputs(v);
  for (int leg = 0; leg < kNumLegs; ++leg) sensors_.contact[static_cast<std::size_t>(leg)] = m.in_contact[static_cast<std::size_t>(leg)];
}

Eigen::Vector2d Simulator::imuVelocity() const {
  dVector3 v;
  dBodyGetRelPointVel(impl_->robot.torso, robot_.imu_position_m[0] - robot_.torso_com_m[0],
                      robot_.imu_position_m[1] - robot_.torso_com_m[1], 0.0, v);
  return {v[0], v[1]};
}

void Simulator::setCommand(const model::ActuatorCommand& command) { command_ = command; }

void Simulator::scheduleImpulse(const ImpulseSpec& impulse) {
  if (impulse.trigger == ImpulseTrigger::AtLiftOff && (impulse.leg < 0 || impulse.leg >= kNumLegs))
    throw std::invalid_argument("Simulator::scheduleImpulse: leg must be 0 (right) or 1 (left)");
  impl_->pending.push_back(impulse);
  if (impulse.trigger == ImpulseTrigger::AtLiftOff) impl_->liftoff_flag[static_cast<std::size_t>(impulse.leg)] = false;
}

void Simulator::physicsStep(int substep) {
  Impl& m = *impl_;
  const double t0 = time_ + substep * h_;
  // Actuators: the SEA output at the start of the step drives the joint; the drive limits act on its input.
  for (int i = 0; i < kNa; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    dJointID j = m.robot.joints[static_cast<std::size_t>(model::kActuatedIndex[ui] - 3)].joint;
    const double omega = dJointGetHingeAngleRate(j);
    const double cmd = command_.mode == model::CommandMode::Damping ? -options_.damping_mode_gain_Nmsprad * omega
                                                                    : command_.tau[i];
    if (options_.actuator_model == ActuatorModel::SeaMotor) {
      // The spring drives the joint; the drive limits act on the motor inside the SEA.
      m.sea_command[ui] = cmd;
      m.applied[ui] = m.sea_motor[ui].torque();
      dJointAddHingeTorque(j, m.applied[ui]);
      continue;
    }
    m.sea_input[ui] = m.sea[ui].limitedInput(cmd, omega);
    if (options_.actuator_model == ActuatorModel::Ideal) m.sea[ui].reset(m.sea_input[ui]);
    // The same limits on the output: without them the SEA's 25 ms lag let a hard-driven leg overshoot the
    // speed limit by ~25 %.
    m.applied[ui] = m.sea[ui].limitedInput(m.sea[ui].torque(), omega);
    dJointAddHingeTorque(j, m.applied[ui]);  // +torque on the thigh, -torque on the torso
  }
  // Pushes: force J/h during exactly this physics step (ODE clears accumulators after each step).
  for (auto it = m.pending.begin(); it != m.pending.end();) {
    const bool due = it->trigger == ImpulseTrigger::AtTime ? t0 >= it->time_s - 1e-12
                                                            : m.liftoff_flag[static_cast<std::size_t>(it->leg)];
    if (due && !options_.fix_torso) {
      dBodyAddForce(m.robot.torso, it->impulse_Ns.x() / h_, it->impulse_Ns.y() / h_, 0.0);
      stats_.impulses.push_back({it->impulse_Ns, t0, it->id});
      it = m.pending.erase(it);
    } else {
      ++it;
    }
  }
  m.liftoff_flag = {};

  m.collide();
  dWorldStep(m.world, h_);

  std::array<Vector2d, kNumLegs> force;  // Eigen vectors are not zeroed by {}
  force.fill(Vector2d::Zero());
  std::array<double, kNumLegs> normal{};
  for (std::size_t k = 0; k < m.n_feedback; ++k) {
    const auto leg = static_cast<std::size_t>(m.feedback_leg[k]);
    const Vector2d f(m.feedback[k].f1[0], m.feedback[k].f1[1]);
    force[leg] += f;
    normal[leg] += f.dot(m.feedback_normal[k]);
  }
  dJointGroupEmpty(m.contact_group);
  for (std::size_t leg = 0; leg < static_cast<std::size_t>(kNumLegs); ++leg) {
    m.force_sum[leg] += force[leg];
    m.normal_sum[leg] += normal[leg];
    const bool now = normal[leg] > options_.contact_switch_threshold_N;
    if (now && !m.in_contact[leg]) ++stats_.touchdowns[leg];
    if (!now && m.in_contact[leg]) {
      ++stats_.liftoffs[leg];
      stats_.last_liftoff_time_s[leg] = t0 + h_;
      m.liftoff_flag[leg] = true;
    }
    m.in_contact[leg] = now;
  }
  if (m.body_contact) {
    ++stats_.body_contact_steps;
    if (!stats_.first_body_contact.seen) {
      stats_.first_body_contact = m.step_body_contact;
      stats_.first_body_contact.time_s = t0;
    }
  }
  if (options_.actuator_model == ActuatorModel::Sea)
    for (std::size_t i = 0; i < static_cast<std::size_t>(kNa); ++i) m.sea[i].advance(m.sea_input[i]);
  if (options_.actuator_model == ActuatorModel::SeaMotor)
    for (std::size_t i = 0; i < static_cast<std::size_t>(kNa); ++i) {
      // ODE moved the joint by h times its new rate: that rate is the joint's mean rate over the step.
      dJointID j = m.robot.joints[static_cast<std::size_t>(model::kActuatedIndex[i] - 3)].joint;
      m.sea_motor[i].advance(m.sea_command[i], dJointGetHingeAngleRate(j));
    }
  updateRobotAfterStep(&m.robot, options_.fix_torso);
  double err = 0.0;
  for (int leg = 0; leg < kNumLegs; ++leg) err = std::max(err, closureError(m.robot, leg, options_));
  stats_.closure_error_m = err;
  stats_.max_closure_error_m = std::max(stats_.max_closure_error_m, err);
  ++stats_.physics_steps;
}

void Simulator::step() {
  dAllocateODEDataForThread(dAllocateMaskAll);  // cheap when already done; lets any owning thread step
  Impl& m = *impl_;
  const Vector2d v = imuVelocity();
  const Vector2d imu_vel_before = v;
  m.force_sum.fill(Vector2d::Zero());
  m.normal_sum = {};
  for (int s = 0; s < options_.substeps; ++s) physicsStep(s);
  ++tick_;
  time_ = static_cast<double>(tick_) * options_.control_period_s;  // no accumulated round-off
  ++stats_.control_steps;
  stats_.ode_messages = g_ode_messages.load() - m.messages_at_reset;
  refreshOutputs(imu_vel_before);
}

void Simulator::refreshOutputs(const Vector2d& imu_vel_before) {
  Impl& m = *impl_;
  truth_.tick = tick_;
  truth_.time_s = time_;
  readRobotState(m.robot, robot_, &truth_.q, &truth_.qd);
  const double inv_n = 1.0 / options_.substeps;
  for (int leg = 0; leg < kNumLegs; ++leg) {
    const auto l = static_cast<std::size_t>(leg);
    truth_.contact_force.segment<2>(2 * leg) = m.force_sum[l] * inv_n;  // mean over the control period
    truth_.lti[l] = model::legTransmissionIndex(truth_.q, leg);
  }
  model::SensorReadings& s = sensors_;
  s.tick = tick_;
  s.time_s = time_;
  for (int i = 0; i < kNa; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    s.actuated_pos[ui] = truth_.q[model::kActuatedIndex[ui]];
    s.actuated_vel[ui] = truth_.qd[model::kActuatedIndex[ui]];
    s.passive_pos[ui] = truth_.q[model::kPassiveIndex[ui]];
    s.passive_vel[ui] = truth_.qd[model::kPassiveIndex[ui]];
    s.sea_torque[ui] = m.applied[ui];
  }
  s.gyro_pitch_rate = truth_.qd[model::kBasePitch];
  const Vector2d v = imuVelocity();
  // Specific force: (dv/dt - g) in the body frame; with semi-implicit Euler this is the integrator's own
  // acceleration over the period.
  const Vector2d a = (v - imu_vel_before) / options_.control_period_s;
  const Vector2d f = rot(-truth_.q[model::kBasePitch], a + Vector2d(0.0, robot_.gravity_mps2));
  s.accel = {f.x(), f.y()};
  for (int leg = 0; leg < kNumLegs; ++leg)
    s.contact[static_cast<std::size_t>(leg)] = m.normal_sum[static_cast<std::size_t>(leg)] * inv_n > options_.contact_switch_threshold_N;
  m.noise.apply(&s);
}

std::uint64_t Simulator::stateHash() const {
  std::uint64_t h = 1469598103934665603ull;
  auto add = [&h](double v) {
    unsigned char b[sizeof v];
    std::memcpy(b, &v, sizeof v);
    for (unsigned char c : b) h = (h ^ c) * 1099511628211ull;
  };
  const Impl& m = *impl_;
  for (dBodyID b : m.robot.bodies()) {
    for (const dReal* p : {dBodyGetPosition(b), dBodyGetLinearVel(b), dBodyGetAngularVel(b)})
      for (int i = 0; i < 3; ++i) add(p[i]);
    const dReal* q = dBodyGetQuaternion(b);
    for (int i = 0; i < 4; ++i) add(q[i]);
  }
  for (const auto& s : m.sea) add(s.torque()), add(s.rate());
  if (options_.actuator_model == ActuatorModel::SeaMotor)
    for (const auto& s : m.sea_motor) add(s.deflection()), add(s.motorSpeed());
  for (const auto& e : m.robot.joints) add(e.unwrapped);
  add(m.robot.pitch_unwrapped);
  add(time_);
  return h;
}

double Simulator::mechanicalEnergy() const {
  double e = 0.0;
  for (dBodyID b : impl_->robot.bodies()) {
    dMass mass;
    dBodyGetMass(b, &mass);
    const dReal* v = dBodyGetLinearVel(b);
    const dReal* w = dBodyGetAngularVel(b);
    const dReal* p = dBodyGetPosition(b);
    e += 0.5 * mass.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    e += 0.5 * mass.I[0] * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);  // isotropic inertia
    e += mass.mass * robot_.gravity_mps2 * p[1];
  }
  return e;
}

Eigen::Vector2d Simulator::linearMomentum() const {
  Vector2d p(0, 0);
  for (dBodyID b : impl_->robot.bodies()) {
    dMass mass;
    dBodyGetMass(b, &mass);
    const dReal* v = dBodyGetLinearVel(b);
    p += mass.mass * Vector2d(v[0], v[1]);
  }
  return p;
}

Eigen::Vector2d Simulator::anklePosition(int leg) const { return ankle(impl_->robot, leg, options_); }

model::VectorA Simulator::seaTorque() const {
  model::VectorA t;
  for (int i = 0; i < kNa; ++i) t[i] = impl_->applied[static_cast<std::size_t>(i)];
  return t;
}

model::VectorA Simulator::motorTorque() const {
  model::VectorA t;
  for (int i = 0; i < kNa; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    t[i] = options_.actuator_model == ActuatorModel::SeaMotor ? impl_->sea_motor[ui].meanMotorTorque() : impl_->sea_input[ui];
  }
  return t;
}

model::VectorA Simulator::motorSpeed() const {
  model::VectorA w;
  for (int i = 0; i < kNa; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    w[i] = options_.actuator_model == ActuatorModel::SeaMotor ? impl_->sea_motor[ui].motorSpeed()
                                                               : truth_.qd[model::kActuatedIndex[ui]];
  }
  return w;
}

double Simulator::rayTerrain(double x, double z_from) const { return impl_->terrain->rayDown(x, z_from); }

double Simulator::footRestHeight(double x, double depth) const {
  const double r = options_.foot_collision_radius_m;
  if (!(depth >= 0.0 && depth < 0.9 * r))
    throw std::invalid_argument("Simulator::footRestHeight: depth must lie in [0, 0.9 * foot radius)");
  const double h = terrain_.heightAt(x);
  double lo = h - 0.9 * r, hi = h + 0.2;  // depth(lo) >= 0.9 r > depth >= depth(hi) = 0
  for (int i = 0; i < 64 && hi - lo > 1e-12; ++i) {
    const double mid = 0.5 * (lo + hi);
    (impl_->terrain->sphereDepth(x, mid, r) > depth ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace mft::sim
