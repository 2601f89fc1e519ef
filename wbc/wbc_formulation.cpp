#include "wbc/wbc_formulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "model/config/enum_names.hpp"

namespace mft::wbc {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
using model::kNa;
using model::kNq;

// Eq. 17 for one coordinate.
double pdAcceleration(const Setpoint1& ref, double pos, double vel, const PdGains1& g) {
  return ref.acc + g.kp * (ref.pos - pos) + g.kd * (ref.vel - vel);
}

// Floating-base coordinate task (height or pitch): J = unit row, Jdot qd = 0. Weights and gains are read from
// the parameters at every tick, so a live change (WholeBodyController::setTuning) acts from the next tick.
Task baseCoordinateTask(const char* name, int index, const WbcWeights& w, double WbcWeights::*weight_member,
                        const Setpoint1 WbcReference::*ref_member, const PdGains1 WbcGains::*gains_member) {
  return Task(name, VarBlock::Qdd, 1, w.*weight_member,
              [index, weight_member, ref_member, gains_member](const TickContext& c, Task* t) {
    t->weight = c.params->weights.*weight_member;
    t->A.setZero();
    t->A(0, index) = 1.0;
    t->b(0) = pdAcceleration(c.ref->*ref_member, c.state->q[index], c.state->qd[index], c.params->gains.*gains_member);
  });
}

// Base x task for standing: J = unit row, weight w_x only while the planner holds base x (Stand mode) and both
// feet are in stance, 0 otherwise (stepping leaves base x passive, as in the paper).
Task baseXTask() {
  return Task("base_x", VarBlock::Qdd, 1, 0.0, [](const TickContext& c, Task* t) {
    const bool active = c.ref->hold_base_x && c.ref->foot_in_stance[0] && c.ref->foot_in_stance[1];
    t->weight = active ? c.params->weights.base_x : 0.0;
    t->A.setZero();
    t->A(0, model::kBaseX) = 1.0;
    t->b(0) = active ? pdAcceleration(c.ref->base_x, c.state->q[model::kBaseX], c.state->qd[model::kBaseX],
                                      c.params->gains.base_x)
                     : 0.0;
  });
}

// Foot point task: J_c rows of the foot; swing or support weight and gains from the contact schedule.
Task footTask(const char* name, int leg) {
  return Task(name, VarBlock::Qdd, 2, 0.0, [leg](const TickContext& c, Task* t) {
    const bool stance = c.ref->foot_in_stance[leg];
    const WbcParams& p = *c.params;
    const PdGains2& g = stance ? p.gains.support_foot : p.gains.swing_foot;
    t->weight = stance ? p.weights.support_foot : p.weights.swing_foot;
    const int r = 2 * leg;
    t->A = c.model->Jc.middleRows<2>(r);
    for (int i = 0; i < 2; ++i) {
      const Setpoint1 ref{c.ref->foot_pos[r + i], c.ref->foot_vel[r + i], c.ref->foot_acc[r + i]};
      const double xdd_des = pdAcceleration(ref, c.model->foot_pos[r + i], c.model->foot_vel[r + i], {g.kp[i], g.kd[i]});
      t->b(i) = xdd_des - c.model->Jc_dot_qd[r + i];
    }
  });
}

// weight * || x_block - target ||^2 with an identity A (keeps the f_c / eps parts of H diagonal).
Task identityTask(const char* name, VarBlock block, const WbcWeights& w, double WbcWeights::*weight_member,
                  bool track_fc_prev) {
  Task t(name, block, blockSize(block), w.*weight_member, [weight_member, track_fc_prev](const TickContext& c, Task* task) {
    task->weight = c.params->weights.*weight_member;
    if (track_fc_prev) task->b = c.fc_prev;
  });
  t.A.setIdentity();
  return t;
}

}  // namespace

const char* toString(VarBlock b) {
  static constexpr config::EnumName<VarBlock> kNames[] = {
      {VarBlock::Qdd, "qdd"}, {VarBlock::Fc, "f_c"}, {VarBlock::Eps, "eps"}};
  return config::nameOf(kNames, b);
}

WbcParams makeWbcParams(const model::RobotDescription& robot, const WbcConfig& config, const WbcPolytope* polytope) {
  validateWbcConfig(config, robot);
  WbcParams p;
  p.variant = config.variant;
  p.dt = config.horizon_settling_times * robot.actuator.sea.settling_time_s;
  p.weights = config.weights;
  p.gains = config.gains;
  p.tau_max.setConstant(config.limits.torque_limit_fraction * robot.actuator.outputPeakTorque());
  p.mu = config.contact.friction_fraction * robot.friction_coefficient;  // one coefficient with the ground
  p.fz_max = config.contact.normal_force_max_N;
  p.qdd_base_max = config.limits.qdd_base_max;
  p.qdd_joint_max = config.limits.qdd_joint_max_radps2;
  // S_ua order [q5, q7, q9, q11] = rear knee, fore knee of each leg.
  p.passive_lo << config.sa.rear_knee_rad.lo, config.sa.fore_knee_rad.lo, config.sa.rear_knee_rad.lo,
      config.sa.fore_knee_rad.lo;
  p.passive_hi << config.sa.rear_knee_rad.hi, config.sa.fore_knee_rad.hi, config.sa.rear_knee_rad.hi,
      config.sa.fore_knee_rad.hi;
  if (polytope) {
    if (!polytope->A.allFinite() || !polytope->b.allFinite())
      throw std::invalid_argument("WBC: the MFT polytope has non-finite entries");
    p.mft = *polytope;
  } else if (config.variant == WbcVariant::Mft) {
    throw std::invalid_argument("WBC: variant 'mft' needs the MFT polytope (config/mft_space.yaml)");
  }
  return p;
}

Formulation buildFormulation(const WbcParams& params) {
  Formulation f;
  const WbcWeights& w = params.weights;

  // --- Cost, eq. 15 ---
  // 15a: operational-space tracking through the PD law of eq. 17.
  f.tasks.push_back(baseCoordinateTask("base_z", model::kBaseZ, w, &WbcWeights::base_z, &WbcReference::base_z, &WbcGains::base_z));
  f.tasks.push_back(
      baseCoordinateTask("base_pitch", model::kBasePitch, w, &WbcWeights::base_pitch, &WbcReference::base_pitch, &WbcGains::base_pitch));
  f.tasks.push_back(footTask("foot_right", model::kRightLeg));
  f.tasks.push_back(footTask("foot_left", model::kLeftLeg));
  // 15b: contact force regularization and rate penalty ||f_c - f_c^-||.
  f.tasks.push_back(identityTask("contact_force", VarBlock::Fc, w, &WbcWeights::contact_force, false));
  f.tasks.push_back(identityTask("contact_force_rate", VarBlock::Fc, w, &WbcWeights::contact_force_rate, true));
  // 15c: slack of the MFT soft constraint (kept in every variant so H stays positive definite; eps is fixed
  // to 0 by its bounds when there is no MFT row).
  f.tasks.push_back(identityTask("slack", VarBlock::Eps, w, &WbcWeights::slack, false));
  // Not in the paper: a small ||qdd||^2 term. The tasks above constrain only 6 of the 11 accelerations; the
  // rest would be fixed by the equalities alone, and the dual active-set solver needs H positive definite.
  f.tasks.push_back(identityTask("qdd_regularization", VarBlock::Qdd, w, &WbcWeights::qdd_regularization, false));
  // Not in the paper: base x while standing in double support (eq. 12 plans only z and pitch). Last, so the
  // indices of the paper's terms stay as they were.
  f.tasks.push_back(baseXTask());

  // --- Constraints, eq. 16 and the loop closure ---
  using Type = Constraint::Type;
  // 16a: S_f (M qdd + N_h' h) = S_f N_h' J_c' f_c.
  f.constraints.emplace_back("eq_base_dyn", Type::Equality, 3, [](const TickContext& c, Constraint* k) {
    k->A.block<3, kNqdd>(0, 0) = c.model->M.topRows<3>();
    k->A.block<3, kNfc>(0, kNqdd).noalias() = -c.dyn->base_NhT * c.model->Jc.transpose();
    k->lower.noalias() = -c.dyn->base_NhT * c.model->h;
  });
  // Loop closure J_h qdd = -Jdot_h qd (the second row of eq. 1).
  f.constraints.emplace_back("eq_closure", Type::Equality, model::kNh, [](const TickContext& c, Constraint* k) {
    k->A.block<model::kNh, kNqdd>(0, 0) = c.model->Jh;
    k->lower = -c.model->Jh_dot_qd;
  });
  // 16b: friction pyramid U f_c <= 0: +-f_x - mu f_z <= 0 per foot (f_z >= 0 is a bound).
  f.constraints.emplace_back("in_friction", Type::Inequality, 4, [](const TickContext& c, Constraint* k) {
    for (int foot = 0; foot < 2; ++foot) {
      for (int s = 0; s < 2; ++s) {
        const int r = 2 * foot + s;
        k->A(r, kNqdd + 2 * foot) = s == 0 ? 1.0 : -1.0;
        k->A(r, kNqdd + 2 * foot + 1) = -c.params->mu;
        k->lower(r) = -kInf;
        k->upper(r) = 0.0;
      }
    }
  });
  // 16c: tau_min <= tau_a(qdd, f_c) <= tau_max through the affine map of eq. 7.
  f.constraints.emplace_back("in_torque", Type::Inequality, kNa, [](const TickContext& c, Constraint* k) {
    k->A.block<kNa, kNqdd>(0, 0) = c.dyn->torque.tau_qdd;
    k->A.block<kNa, kNfc>(0, kNqdd) = c.dyn->torque.tau_fc;
    k->lower = -c.params->tau_max - c.dyn->torque.tau_0;
    k->upper = c.params->tau_max - c.dyn->torque.tau_0;
  });
  // 16e with eq. 10-11 (J = S_a, Jdot qd = 0): C qdd - eps <= d, C = dt^2/2 A S_a, d = b - A (q_a + qd_a dt).
  if (params.variant == WbcVariant::Mft) {
    f.constraints.emplace_back("in_mft", Type::Inequality, kNeps, [](const TickContext& c, Constraint* k) {
      const WbcParams& p = *c.params;
      model::VectorA qa_pred;
      for (int i = 0; i < kNa; ++i) {
        const int j = model::kActuatedIndex[i];
        qa_pred[i] = predictedCoordinate(c.state->q[j], c.state->qd[j], 0.0, p.dt);
        k->A.col(j) = 0.5 * p.dt * p.dt * p.mft.A.col(i);
      }
      k->A.block<kNeps, kNeps>(0, kNqdd + kNfc) = -Eigen::Matrix<double, kNeps, kNeps>::Identity();
      k->lower.setConstant(-kInf);
      k->upper.noalias() = p.mft.b - p.mft.A * qa_pred;
    });
  }
  // Eq. 14 (SA-WBC): q_ua_min <= S_ua (q + qd dt + qdd dt^2 / 2) <= q_ua_max.
  if (params.variant == WbcVariant::Sa) {
    f.constraints.emplace_back("in_passive", Type::Inequality, kNa, [](const TickContext& c, Constraint* k) {
      const WbcParams& p = *c.params;
      const double s = 0.5 * p.dt * p.dt;
      // What the qdd box can change in dt: a row needing more is clipped to it, so an estimate already past a
      // boundary asks for the strongest correction instead of making the QP infeasible.
      const double reach = s * p.qdd_joint_max;
      for (int i = 0; i < kNa; ++i) {
        const int j = model::kPassiveIndex[i];
        const double nominal = predictedCoordinate(c.state->q[j], c.state->qd[j], 0.0, p.dt);
        k->A(i, j) = s;
        k->lower(i) = std::min(p.passive_lo[i] - nominal, reach);
        k->upper(i) = std::max(p.passive_hi[i] - nominal, -reach);
      }
    });
  }

  // Lay the rows out once: equalities then inequalities, each in list order.
  for (Constraint& k : f.constraints) {
    if (k.type == Type::Equality) {
      k.row_offset = f.neq;
      f.neq += k.rows();
    } else {
      k.row_offset = f.nin;
      f.nin += k.rows();
    }
  }
  return f;
}

void updateBounds(const TickContext& ctx, VariableBounds* bounds) {
  const WbcParams& p = *ctx.params;
  for (int i = 0; i < kNqdd; ++i) {
    const double m = i < 3 ? p.qdd_base_max[i] : p.qdd_joint_max;
    bounds->lb[i] = -m;
    bounds->ub[i] = m;
  }
  for (int foot = 0; foot < 2; ++foot) {
    const int ix = kNqdd + 2 * foot;
    bounds->lb[ix] = -kInf;  // f_x: limited by the pyramid
    bounds->ub[ix] = kInf;
    bounds->lb[ix + 1] = 0.0;
    bounds->ub[ix + 1] = ctx.ref->foot_in_stance[foot] ? p.fz_max : 0.0;
  }
  const bool soft_mft = p.variant == WbcVariant::Mft;
  bounds->lb.tail<kNeps>().setConstant(soft_mft ? -kInf : 0.0);
  bounds->ub.tail<kNeps>().setConstant(soft_mft ? kInf : 0.0);
}

int findTask(const Formulation& f, const std::string& name) {
  for (std::size_t i = 0; i < f.tasks.size(); ++i)
    if (f.tasks[i].name == name) return static_cast<int>(i);
  return -1;
}

int findConstraint(const Formulation& f, const std::string& name) {
  for (std::size_t i = 0; i < f.constraints.size(); ++i)
    if (f.constraints[i].name == name) return static_cast<int>(i);
  return -1;
}

}  // namespace mft::wbc
