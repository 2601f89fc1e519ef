#include "wbc/wbc_formulation.hpp"

#include <stdexcept>

#include "common/enum_names.hpp"

namespace mft::wbc {
namespace {

using model::kNa;
using model::kNq;

// Floating-base coordinate task (height or pitch), (15a) with the PD law (17). Weights and gains are read from
// the parameters at every tick, so a live change (WholeBodyController::setTuning) acts from the next tick.
Task baseCoordinateTask(const char* name, int index, const WbcWeights& w, double WbcWeights::*weight_member,
                        const Setpoint1 WbcReference::*ref_member, const PdGains1 WbcGains::*gains_member) {
  return Task(name, VarBlock::Qdd, 1, w.*weight_member,
              [index, weight_member, ref_member, gains_member](const TickContext& c, Task* t) {
    t->weight = c.params->weights.*weight_member;
    coordinateTaskRows(index,
                       pdAcceleration(c.ref->*ref_member, c.state->q[index], c.state->qd[index],
                                      c.params->gains.*gains_member),
                       &t->A, &t->b);
  });
}

// Base x task for standing: J = unit row, weight w_x only while the planner holds base x (Stand mode) and both
// feet are in stance, 0 otherwise (stepping leaves base x passive, as in the paper).
Task baseXTask() {
  return Task("base_x", VarBlock::Qdd, 1, 0.0, [](const TickContext& c, Task* t) {
    const bool active = c.ref->hold_base_x && c.ref->foot_in_stance[0] && c.ref->foot_in_stance[1];
    t->weight = active ? c.params->weights.base_x : 0.0;
    coordinateTaskRows(model::kBaseX,
                       active ? pdAcceleration(c.ref->base_x, c.state->q[model::kBaseX],
                                               c.state->qd[model::kBaseX], c.params->gains.base_x)
                              : 0.0,
                       &t->A, &t->b);
  });
}

// Foot point task, (15a) with (17) per axis: swing or support weight and gains from the contact schedule.
Task footTask(const char* name, int leg) {
  return Task(name, VarBlock::Qdd, 2, 0.0, [leg](const TickContext& c, Task* t) {
    const bool stance = c.ref->foot_in_stance[leg];
    const WbcParams& p = *c.params;
    const PdGains2& g = stance ? p.gains.support_foot : p.gains.swing_foot;
    t->weight = stance ? p.weights.support_foot : p.weights.swing_foot;
    const int r = 2 * leg;
    Eigen::Vector2d xdd_des;
    for (int i = 0; i < 2; ++i) {
      const Setpoint1 ref{c.ref->foot_pos[r + i], c.ref->foot_vel[r + i], c.ref->foot_acc[r + i]};
      xdd_des[i] = pdAcceleration(ref, c.model->foot_pos[r + i], c.model->foot_vel[r + i], {g.kp[i], g.kd[i]});
    }
    footTaskRows(c.model->Jc, c.model->Jc_dot_qd, leg, xdd_des, &t->A, &t->b);
  });
}

// A task whose weight is a WbcWeights member and whose rows come from one of the equation functions. Used for
// (15b), (15c) and the qdd regularization: identity A, so the f_c / eps parts of H stay diagonal.
using TaskRows = void (*)(const TickContext&, TaskMatrix*, TaskVector*);
Task weightedTask(const char* name, VarBlock block, const WbcWeights& w, double WbcWeights::*weight_member,
                  TaskRows rows) {
  return Task(name, block, blockSize(block), w.*weight_member, [weight_member, rows](const TickContext& c, Task* t) {
    t->weight = c.params->weights.*weight_member;
    rows(c, &t->A, &t->b);
  });
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

  // --- Cost, (15) ---
  // 15a: operational-space tracking through the PD law of (17).
  f.tasks.push_back(baseCoordinateTask("base_z", model::kBaseZ, w, &WbcWeights::base_z, &WbcReference::base_z, &WbcGains::base_z));
  f.tasks.push_back(
      baseCoordinateTask("base_pitch", model::kBasePitch, w, &WbcWeights::base_pitch, &WbcReference::base_pitch, &WbcGains::base_pitch));
  f.tasks.push_back(footTask("foot_right", model::kRightLeg));
  f.tasks.push_back(footTask("foot_left", model::kLeftLeg));
  // 15b: contact force regularization and rate penalty ||f_c - f_c^-||.
  f.tasks.push_back(weightedTask("contact_force", VarBlock::Fc, w, &WbcWeights::contact_force,
                                 [](const TickContext&, TaskMatrix* A, TaskVector* b) { contactForceTaskRows(A, b); }));
  f.tasks.push_back(weightedTask("contact_force_rate", VarBlock::Fc, w, &WbcWeights::contact_force_rate,
                                 [](const TickContext& c, TaskMatrix* A, TaskVector* b) {
    contactForceRateTaskRows(c.fc_prev, A, b);
  }));
  // 15c: slack of the MFT soft constraint (kept in every variant so H stays positive definite; eps is fixed
  // to 0 by its bounds when there is no MFT row).
  f.tasks.push_back(weightedTask("slack", VarBlock::Eps, w, &WbcWeights::slack,
                                 [](const TickContext&, TaskMatrix* A, TaskVector* b) { slackTaskRows(A, b); }));
  // Not in the paper: a small ||qdd||^2 term. The tasks above constrain only 6 of the 11 accelerations; the
  // rest would be fixed by the equalities alone, and the dual active-set solver needs H positive definite.
  f.tasks.push_back(weightedTask("qdd_regularization", VarBlock::Qdd, w, &WbcWeights::qdd_regularization,
                                 [](const TickContext&, TaskMatrix* A, TaskVector* b) {
    A->setIdentity(kNqdd, kNqdd);
    b->setZero(kNqdd);
  }));
  // Not in the paper: base x while standing in double support ((18) plans only z and pitch). Last, so the
  // indices of the paper's terms stay as they were.
  f.tasks.push_back(baseXTask());

  // --- Constraints, (16) and the loop closure ---
  using Type = Constraint::Type;
  // (8) = (16a): S_f (M qdd + N_h' H) = S_f N_h' J_c' f_c.
  f.constraints.emplace_back("eq_base_dyn", Type::Equality, 3, [](const TickContext& c, Constraint* k) {
    baseDynamicsRows(c.model->M, c.model->h, c.model->Jc, c.dyn->base_NhT, &k->A, &k->lower);
  });
  // Loop closure J_h qdd = -Jdot_h qd (the second block row of (6)).
  f.constraints.emplace_back("eq_closure", Type::Equality, model::kNh, [](const TickContext& c, Constraint* k) {
    loopClosureRows(c.model->Jh, c.model->Jh_dot_qd, &k->A, &k->lower);
  });
  // (16b): friction pyramid U f_c <= 0 (f_z >= 0 is a bound).
  f.constraints.emplace_back("in_friction", Type::Inequality, 4, [](const TickContext& c, Constraint* k) {
    frictionPyramidRows(c.params->mu, &k->A, &k->lower, &k->upper);
  });
  // (16c): tau_min <= tau_a(qdd, f_c) <= tau_max through the affine map of (9).
  f.constraints.emplace_back("in_torque", Type::Inequality, kNa, [](const TickContext& c, Constraint* k) {
    torqueLimitRows(c.dyn->torque, c.params->tau_max, &k->A, &k->lower, &k->upper);
  });
  // (16e) = (11) with (13)-(14): C qdd - eps <= d.
  if (params.variant == WbcVariant::Mft) {
    f.constraints.emplace_back("in_mft", Type::Inequality, kNeps, [](const TickContext& c, Constraint* k) {
      const WbcParams& p = *c.params;
      mftPolytopeRows(p.mft.A, p.mft.b, c.state->q, c.state->qd, p.dt, &k->A, &k->lower, &k->upper);
    });
  }
  // (20) (SA-WBC): q_ua_min <= S_ua (q + qd dt + qdd dt^2 / 2) <= q_ua_max, clipped to the qdd box's reach.
  if (params.variant == WbcVariant::Sa) {
    f.constraints.emplace_back("in_passive", Type::Inequality, kNa, [](const TickContext& c, Constraint* k) {
      const WbcParams& p = *c.params;
      passiveJointRows(c.state->q, c.state->qd, p.dt, p.passive_lo, p.passive_hi, p.qdd_joint_max, &k->A, &k->lower,
                       &k->upper);
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
  accelerationBounds(p.qdd_base_max, p.qdd_joint_max, bounds);  // (16d)
  contactForceBounds(ctx.ref->foot_in_stance, p.fz_max, bounds);  // (16b), f_z
  slackBounds(p.variant == WbcVariant::Mft, bounds);              // (16e), eps
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
