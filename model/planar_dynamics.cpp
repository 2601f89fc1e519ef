#include "model/planar_dynamics.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <stdexcept>
#include <string>

#include "model/five_bar.hpp"

namespace mft::model {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;
using PointJacobian = Eigen::Matrix<double, 2, kNq>;
using BodyKinematicsArray = std::array<BodyKinematics, kNq>;

// ---- planar spatial algebra: motion (omega, v_x, v_z), force (moment, f_x, f_z), origin-based ----

Eigen::Matrix2d rotation(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Eigen::Matrix2d R;
  R << c, -s, s, c;
  return R;
}

// Velocity of the point r under a unit CCW rotation about the origin (omega x r in the plane).
Vector2d perp(const Vector2d& r) { return {-r.y(), r.x()}; }

// Motion transform from a parent frame to a child frame whose origin sits at p (parent coordinates) and whose
// axes are turned by theta: the velocity is carried to the new origin, then rotated into the child axes.
Matrix3d motionTransform(double theta, const Vector2d& p) {
  const double c = std::cos(theta), s = std::sin(theta);
  Matrix3d X;
  X << 1.0, 0.0, 0.0,  //
      s * p.x() - c * p.y(), c, s,  //
      c * p.x() + s * p.y(), -s, c;
  return X;
}

// Spatial inertia about the body origin of a body with its CoM at c (body coordinates).
Matrix3d spatialInertia(const PlanarBody& b) {
  const double m = b.mass, cx = b.com.x(), cz = b.com.y();
  Matrix3d I;
  I << b.inertia + m * (cx * cx + cz * cz), -m * cz, m * cx,  //
      -m * cz, m, 0.0,  //
      m * cx, 0.0, m;
  return I;
}

// v x m for motion vectors (crm).
Vector3d crossMotion(const Vector3d& v, const Vector3d& m) {
  return {0.0, v(2) * m(0) - v(0) * m(2), -v(1) * m(0) + v(0) * m(1)};
}
// v x* f for force vectors (crf = -crm').
Vector3d crossForce(const Vector3d& v, const Vector3d& f) {
  return {-v(2) * f(1) + v(1) * f(2), -v(0) * f(2), v(0) * f(1)};
}

Vector3d motionSubspace(JointType type) {
  switch (type) {
    case JointType::PrismaticX: return {0.0, 1.0, 0.0};
    case JointType::PrismaticZ: return {0.0, 0.0, 1.0};
    case JointType::Revolute: break;
  }
  return {1.0, 0.0, 0.0};
}

// Unit translation direction of a prismatic joint in its parent frame (zero for a revolute joint).
Vector2d prismaticAxis(JointType type) {
  switch (type) {
    case JointType::PrismaticX: return {1.0, 0.0};
    case JointType::PrismaticZ: return {0.0, 1.0};
    case JointType::Revolute: break;
  }
  return {0.0, 0.0};
}

// Child origin in the parent frame and child rotation relative to the parent, at joint coordinate qi.
void jointPlacement(const PlanarBody& b, double qi, Vector2d* offset, double* theta) {
  *offset = b.joint_offset + prismaticAxis(b.joint) * qi;
  *theta = b.joint == JointType::Revolute ? qi : 0.0;
}

void checkModel(const PlanarModel& model) {
  if (static_cast<int>(model.bodies.size()) != kNq)
    throw std::invalid_argument("PlanarModel: expected " + std::to_string(kNq) + " bodies, got " +
                                std::to_string(model.bodies.size()));
  for (int i = 0; i < kNq; ++i) {
    if (model.bodies[i].parent >= i || model.bodies[i].parent < -1)
      throw std::invalid_argument("PlanarModel: body " + std::to_string(i) + " must have a parent in [-1, " +
                                  std::to_string(i - 1) + "]");
  }
}

void checkBody(int body) {
  if (body < 0 || body >= kNq) throw std::invalid_argument("PlanarModel: no body " + std::to_string(body));
}

// World-frame pose (and, with qd, velocity and bias acceleration) of every body frame, root to leaves.
void worldKinematics(const PlanarModel& model, const VectorQ& q, const VectorQ* qd, BodyKinematicsArray* out) {
  BodyKinematicsArray& k = *out;
  const BodyKinematics world{};
  for (int i = 0; i < kNq; ++i) {
    const PlanarBody& b = model.bodies[i];
    const BodyKinematics& p = b.parent < 0 ? world : k[b.parent];
    Vector2d offset;
    double theta;
    jointPlacement(b, q(i), &offset, &theta);
    const Eigen::Matrix2d R_parent = rotation(p.angle);
    const Vector2d r = R_parent * offset;  // parent origin -> child origin, world axes
    BodyKinematics& c = k[i];
    c.origin = p.origin + r;
    c.angle = p.angle + theta;
    if (qd != nullptr) {
      const double qdi = (*qd)(i);
      const Vector2d slide = R_parent * prismaticAxis(b.joint) * qdi;  // prismatic joint velocity, world axes
      c.omega = p.omega + (b.joint == JointType::Revolute ? qdi : 0.0);
      c.velocity = p.velocity + p.omega * perp(r) + slide;
      // Centripetal term of the rotating offset plus the Coriolis term of a slide on a rotating parent.
      c.bias_acceleration = p.bias_acceleration - p.omega * p.omega * r + 2.0 * p.omega * perp(slide);
    }
  }
}

Vector2d worldPoint(const BodyKinematics& k, const Vector2d& point) { return k.origin + rotation(k.angle) * point; }

// Adds scale * d(point)/dq to J for a world point fixed in `body` (columns of the body's ancestors only).
void addPointJacobian(const PlanarModel& model, const BodyKinematicsArray& k, int body, const Vector2d& point_world,
                      double scale, PointJacobian* J) {
  for (int j = body; j >= 0; j = model.bodies[j].parent) {
    const PlanarBody& b = model.bodies[j];
    if (b.joint == JointType::Revolute) {
      J->col(j) += scale * perp(point_world - k[j].origin);
    } else {
      const double parent_angle = b.parent < 0 ? 0.0 : k[b.parent].angle;
      J->col(j) += scale * (rotation(parent_angle) * prismaticAxis(b.joint));
    }
  }
}

// Acceleration of a world point fixed in `body` at qdd = 0: origin bias plus the centripetal term.
Vector2d pointBiasAcceleration(const BodyKinematics& k, const Vector2d& point_world) {
  return k.bias_acceleration - k.omega * k.omega * (point_world - k.origin);
}

// Parent-to-body and world-to-body transforms and motion subspaces.
void computeTransforms(const PlanarModel& model, const VectorQ& q, ModelData* data) {
  for (int i = 0; i < kNq; ++i) {
    const PlanarBody& b = model.bodies[i];
    Vector2d offset;
    double theta;
    jointPlacement(b, q(i), &offset, &theta);
    data->X_up[i] = motionTransform(theta, offset);
    data->X_base[i] = b.parent < 0 ? data->X_up[i] : Matrix3d(data->X_up[i] * data->X_base[b.parent]);
    data->S[i] = motionSubspace(b.joint);
  }
}

// Composite-rigid-body algorithm; needs computeTransforms.
void compositeRigidBody(const PlanarModel& model, ModelData* data) {
  for (int i = 0; i < kNq; ++i) data->Ic[i] = spatialInertia(model.bodies[i]);
  for (int i = kNq - 1; i >= 0; --i) {
    const int parent = model.bodies[i].parent;
    if (parent >= 0) data->Ic[parent] += data->X_up[i].transpose() * data->Ic[i] * data->X_up[i];
  }
  data->M.setZero();
  for (int i = 0; i < kNq; ++i) {
    Vector3d F = data->Ic[i] * data->S[i];
    data->M(i, i) = data->S[i].dot(F);
    for (int j = i; model.bodies[j].parent >= 0;) {
      F = data->X_up[j].transpose() * F;
      j = model.bodies[j].parent;
      data->M(i, j) = data->M(j, i) = data->S[j].dot(F);
    }
  }
}

// Recursive Newton-Euler at qdd = 0 with gravity as a fictitious upward base acceleration; needs
// computeTransforms. data->a keeps the velocity-product accelerations only (no gravity).
void recursiveNewtonEuler(const PlanarModel& model, const VectorQ& qd, ModelData* data) {
  const Vector3d base_gravity_lift(0.0, 0.0, model.gravity);
  for (int i = 0; i < kNq; ++i) {
    const int parent = model.bodies[i].parent;
    const Vector3d vJ = data->S[i] * qd(i);
    if (parent < 0) {
      data->v[i] = vJ;
      data->a[i].setZero();
    } else {
      data->v[i] = data->X_up[i] * data->v[parent] + vJ;
      data->a[i] = data->X_up[i] * data->a[parent] + crossMotion(data->v[i], vJ);
    }
    const Matrix3d I = spatialInertia(model.bodies[i]);
    data->f[i] = I * (data->a[i] + data->X_base[i] * base_gravity_lift) + crossForce(data->v[i], I * data->v[i]);
  }
  for (int i = kNq - 1; i >= 0; --i) {
    data->h(i) = data->S[i].dot(data->f[i]);
    const int parent = model.bodies[i].parent;
    if (parent >= 0) data->f[parent] += data->X_up[i].transpose() * data->f[i];
  }
}

}  // namespace

PlanarModel buildBipedModel(const RobotDescription& d) {
  PlanarModel model;
  model.gravity = d.gravity_mps2;
  model.shank_length = d.shank.length_m;
  model.bodies.resize(kNq);
  // Massless carriages of the boom: x slide, then z slide, then the torso pitches.
  model.bodies[kBaseX] = {-1, JointType::PrismaticX, {0, 0}, 0.0, {0, 0}, 0.0};
  model.bodies[kBaseZ] = {kBaseX, JointType::PrismaticZ, {0, 0}, 0.0, {0, 0}, 0.0};
  model.bodies[kBasePitch] = {kBaseZ, JointType::Revolute, {0, 0}, d.torso_mass_kg,
                              {d.torso_com_m[0], d.torso_com_m[1]}, d.torso_inertia_kgm2};
  const FiveBarGeometry g = FiveBarGeometry::from(d);
  const Vector2d thigh_com(0.0, -d.thigh.com_from_joint_m), shank_com(0.0, -d.shank.com_from_joint_m);
  const Vector2d knee_offset(0.0, -d.thigh.length_m);
  for (int leg = 0; leg < kNumLegs; ++leg) {
    model.bodies[hipRearIndex(leg)] = {kBasePitch, JointType::Revolute, g.hipRear(), d.thigh.mass_kg, thigh_com,
                                       d.thigh.inertia_kgm2};
    model.bodies[kneeRearIndex(leg)] = {hipRearIndex(leg), JointType::Revolute, knee_offset, d.shank.mass_kg,
                                        shank_com, d.shank.inertia_kgm2};
    model.bodies[hipForeIndex(leg)] = {kBasePitch, JointType::Revolute, g.hipFore(), d.thigh.mass_kg, thigh_com,
                                       d.thigh.inertia_kgm2};
    model.bodies[kneeForeIndex(leg)] = {hipForeIndex(leg), JointType::Revolute, knee_offset, d.shank.mass_kg,
                                        shank_com, d.shank.inertia_kgm2};
  }
  return model;
}

void updateModel(const PlanarModel& model, const VectorQ& q, const VectorQ& qd, ModelData* data) {
  checkModel(model);
  data->q = q;
  data->qd = qd;
  computeTransforms(model, q, data);
  compositeRigidBody(model, data);
  recursiveNewtonEuler(model, qd, data);

  worldKinematics(model, q, &qd, &data->body);
  const BodyKinematicsArray& k = data->body;
  const Vector2d tip = model.shankTip();
  PointJacobian J_rear, J_fore;
  for (int leg = 0; leg < kNumLegs; ++leg) {
    const int rear = model.rearShankBody(leg), fore = model.foreShankBody(leg);
    const Vector2d rear_tip = worldPoint(k[rear], tip), fore_tip = worldPoint(k[fore], tip);
    J_rear.setZero();
    J_fore.setZero();
    addPointJacobian(model, k, rear, rear_tip, 1.0, &J_rear);
    addPointJacobian(model, k, fore, fore_tip, 1.0, &J_fore);
    const Vector2d rear_bias = pointBiasAcceleration(k[rear], rear_tip);
    const int row = 2 * leg;
    data->foot_pos.segment<2>(row) = rear_tip;
    data->Jc.middleRows<2>(row) = J_rear;
    data->foot_vel.segment<2>(row) = J_rear * qd;
    data->Jc_dot_qd.segment<2>(row) = rear_bias;
    data->closure_error.segment<2>(row) = rear_tip - fore_tip;
    data->Jh.middleRows<2>(row) = J_rear - J_fore;
    data->Jh_dot_qd.segment<2>(row) = rear_bias - pointBiasAcceleration(k[fore], fore_tip);
  }

  // Centre of mass: the mass-weighted average of the body CoMs, and its derivatives likewise.
  double total_mass = 0.0;
  for (const PlanarBody& b : model.bodies) total_mass += b.mass;
  data->total_mass = total_mass;
  data->com.setZero();
  data->Jcom.setZero();
  data->Jcom_dot_qd.setZero();
  if (total_mass > 0.0) {
    for (int i = 0; i < kNq; ++i) {
      const PlanarBody& b = model.bodies[i];
      if (b.mass == 0.0) continue;
      const double weight = b.mass / total_mass;
      const Vector2d c = worldPoint(k[i], b.com);
      data->com += weight * c;
      addPointJacobian(model, k, i, c, weight, &data->Jcom);
      data->Jcom_dot_qd += weight * pointBiasAcceleration(k[i], c);
    }
  }
  data->com_vel = data->Jcom * qd;
}

void massMatrix(const PlanarModel& model, const VectorQ& q, ModelData* data) {
  checkModel(model);
  computeTransforms(model, q, data);
  compositeRigidBody(model, data);
}

void biasForces(const PlanarModel& model, const VectorQ& q, const VectorQ& qd, ModelData* data) {
  checkModel(model);
  computeTransforms(model, q, data);
  recursiveNewtonEuler(model, qd, data);
}

Eigen::Vector2d pointPosition(const PlanarModel& model, const VectorQ& q, int body, const Eigen::Vector2d& point) {
  checkModel(model);
  checkBody(body);
  BodyKinematicsArray k;
  worldKinematics(model, q, nullptr, &k);
  return worldPoint(k[body], point);
}

void pointJacobian(const PlanarModel& model, const VectorQ& q, int body, const Eigen::Vector2d& point,
                   Eigen::Matrix<double, 2, kNq>* J) {
  checkModel(model);
  checkBody(body);
  BodyKinematicsArray k;
  worldKinematics(model, q, nullptr, &k);
  J->setZero();
  addPointJacobian(model, k, body, worldPoint(k[body], point), 1.0, J);
}

Eigen::Vector2d pointJdotQd(const PlanarModel& model, const VectorQ& q, const VectorQ& qd, int body,
                            const Eigen::Vector2d& point) {
  checkModel(model);
  checkBody(body);
  BodyKinematicsArray k;
  worldKinematics(model, q, &qd, &k);
  return pointBiasAcceleration(k[body], worldPoint(k[body], point));
}

Eigen::Vector3d bodyPose(const PlanarModel& model, const VectorQ& q, int body) {
  checkModel(model);
  checkBody(body);
  BodyKinematicsArray k;
  worldKinematics(model, q, nullptr, &k);
  return {k[body].origin.x(), k[body].origin.y(), k[body].angle};
}

double kineticEnergy(const ModelData& data, const VectorQ& qd) { return 0.5 * qd.dot(data.M * qd); }

double potentialEnergy(const PlanarModel& model, const VectorQ& q) {
  checkModel(model);
  BodyKinematicsArray k;
  worldKinematics(model, q, nullptr, &k);
  double energy = 0.0;
  for (int i = 0; i < kNq; ++i) {
    const PlanarBody& b = model.bodies[i];
    energy += b.mass * model.gravity * worldPoint(k[i], b.com).y();
  }
  return energy;
}

void constrainedForwardDynamics(const ModelData& data, const VectorA& tau, const VectorC& f_c, VectorQ* qdd,
                                VectorH* f_h) {
  // Range-space (Schur complement) solution of the KKT system of (6): M is SPD, so
  //   qdd = M^-1 (rhs + Jh' f_h),  (Jh M^-1 Jh') f_h = -Jdot_h qd - Jh M^-1 rhs.
  VectorQ rhs = data.Jc.transpose() * f_c - data.h;
  for (int i = 0; i < kNa; ++i) rhs(kActuatedIndex[i]) += tau(i);
  const Eigen::LLT<MatrixQ> M_llt(data.M);
  const VectorQ qdd_free = M_llt.solve(rhs);
  const Eigen::Matrix<double, kNq, kNh> Minv_JhT = M_llt.solve(data.Jh.transpose());
  const Eigen::Matrix<double, kNh, kNh> closure_inertia_inv = data.Jh * Minv_JhT;
  const VectorH closure_force =
      closure_inertia_inv.llt().solve(-data.Jh_dot_qd - data.Jh * qdd_free);
  *qdd = qdd_free + Minv_JhT * closure_force;
  if (f_h != nullptr) *f_h = closure_force;
}

void closureProjection(const ModelData& data, ClosureProjection* out) {
  out->Minv = data.M.llt().solve(MatrixQ::Identity());
  out->Minv = 0.5 * (out->Minv + out->Minv.transpose()).eval();  // exact symmetry for the products below
  const Eigen::Matrix<double, kNq, kNh> Minv_JhT = out->Minv * data.Jh.transpose();
  const Eigen::Matrix<double, kNh, kNh> closure_inertia_inv = data.Jh * Minv_JhT;
  out->Lambda_h = closure_inertia_inv.llt().solve(Eigen::Matrix<double, kNh, kNh>::Identity());
  out->N_h = MatrixQ::Identity() - Minv_JhT * out->Lambda_h * data.Jh;
}

bool actuatedTorqueMap(const ModelData& data, const ClosureProjection& proj, ActuatedTorqueMap* out) {
  // The actuated rows of (7): S_a M, S_a N_h', S_a J_h'.
  ProjectedDynamicsRows<kNa> actuated;
  projectedDynamicsRows<kNa>(data, proj, kActuatedIndex, &actuated);
  const Eigen::Matrix<double, kNa, kNq>& SaNhT = actuated.NhT;
  const Eigen::Matrix<double, kNa, kNq>& SaM = actuated.M;
  const Eigen::Matrix<double, kNa, kNh>& SaJhT = actuated.JhT;
  Eigen::Matrix<double, kNa, kNa> SaNhTSaT;  // S_a N_h' S_a'
  for (int k = 0; k < kNa; ++k) SaNhTSaT.col(k) = SaNhT.col(kActuatedIndex[k]);
  // 4x4 with a closed-form inverse in Eigen: no pivoting search, no allocation.
  const Eigen::Matrix<double, kNa, kNa> K = SaNhTSaT.inverse();
  out->tau_qdd.noalias() = K * SaM;
  const Eigen::Matrix<double, kNa, kNc> SaNhTJcT = SaNhT * data.Jc.transpose();
  out->tau_fc.noalias() = -K * SaNhTJcT;
  const VectorH lambda_jdqd = proj.Lambda_h * data.Jh_dot_qd;
  const VectorA inner = SaNhT * data.h + SaJhT * lambda_jdqd;
  out->tau_0.noalias() = K * inner;
  return out->tau_qdd.allFinite() && out->tau_fc.allFinite() && out->tau_0.allFinite();
}

VectorA actuatedTorque(const ActuatedTorqueMap& map, const VectorQ& qdd, const VectorC& f_c) {
  VectorA tau = map.tau_0;
  tau.noalias() += map.tau_qdd * qdd;
  tau.noalias() += map.tau_fc * f_c;
  return tau;
}

VectorA inverseDynamicsActuated(const ModelData& data, const ClosureProjection& proj, const VectorQ& qdd,
                                const VectorQ& qd, const VectorC& f_c) {
  (void)qd;  // the velocity enters only through data.Jh_dot_qd (and data.h), computed by updateModel at it
  ActuatedTorqueMap map;
  actuatedTorqueMap(data, proj, &map);  // a non-finite map gives a non-finite torque, which callers check
  return actuatedTorque(map, qdd, f_c);
}

VectorQ closedLoopConfiguration(const RobotDescription& d, const Eigen::Vector3d& base_pose,
                                const Eigen::Vector2d& right_foot_in_base, const Eigen::Vector2d& left_foot_in_base) {
  if (!base_pose.allFinite() || !right_foot_in_base.allFinite() || !left_foot_in_base.allFinite())
    throw std::invalid_argument("closedLoopConfiguration: non-finite base pose or foot position");
  const FiveBarGeometry g = FiveBarGeometry::from(d);
  VectorQ q = VectorQ::Zero();
  q.head<3>() = base_pose;
  const Vector2d feet[kNumLegs] = {right_foot_in_base, left_foot_in_base};
  for (int leg = 0; leg < kNumLegs; ++leg) {
    FiveBarPose pose;
    const FiveBarStatus status = fiveBarInverse(g, feet[leg], &pose);
    if (status != FiveBarStatus::Ok) {
      throw std::invalid_argument(std::string("closedLoopConfiguration: the ") + (leg == kRightLeg ? "right" : "left") +
                                  " foot (" + std::to_string(feet[leg].x()) + ", " + std::to_string(feet[leg].y()) +
                                  ") in the base frame is out of the leg's reach");
    }
    q(hipRearIndex(leg)) = pose.q_rear;
    q(kneeRearIndex(leg)) = pose.knee_rear;
    q(hipForeIndex(leg)) = pose.q_fore;
    q(kneeForeIndex(leg)) = pose.knee_fore;
  }
  return q;
}

}  // namespace mft::model
