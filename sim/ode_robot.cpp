#include "sim/ode_robot.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "model/five_bar.hpp"

namespace mft::sim {
namespace {

using Eigen::Vector2d;

Vector2d rot(double a, const Vector2d& v) {
  const double c = std::cos(a), s = std::sin(a);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}
// omega (about +z) x r in the plane.
Vector2d cross(double w, const Vector2d& r) { return {-w * r.y(), w * r.x()}; }

struct PlanarState {
  Vector2d p{0, 0}, v{0, 0};
  double a = 0.0, w = 0.0;
};

dBodyID makeBody(dWorldID world, const PlanarState& s, double mass, double inertia) {
  dBodyID b = dBodyCreate(world);
  dMass m;
  // Mass centred on the body origin (docs/reference/simulation.md#bodies-and-masses). Isotropic inertia: only the pitch moment matters in
  // the plane, and an isotropic tensor has no gyroscopic term whatever the body's orientation.
  dMassSetParameters(&m, mass, 0, 0, 0, inertia, inertia, inertia, 0, 0, 0);
  dBodySetMass(b, &m);
  dBodySetPosition(b, s.p.x(), s.p.y(), 0.0);
  dMatrix3 R;
  dRFromAxisAndAngle(R, 0, 0, 1, s.a);
  dBodySetRotation(b, R);
  dBodySetLinearVel(b, s.v.x(), s.v.y(), 0.0);
  dBodySetAngularVel(b, 0.0, 0.0, s.w);
  return b;
}

void addCapsule(dBodyID body, const Vector2d& from, const Vector2d& to, double radius, std::vector<dGeomID>* out) {
  const Vector2d axis = to - from;
  if (axis.norm() < 1e-6) return;
  dGeomID g = dCreateCapsule(nullptr, radius, axis.norm());
  dGeomSetBody(g, body);
  const Vector2d mid = 0.5 * (from + to);
  dGeomSetOffsetWorldPosition(g, mid.x(), mid.y(), 0.0);
  dMatrix3 R;
  dRFromZAxis(R, axis.x(), axis.y(), 0.0);
  dGeomSetOffsetWorldRotation(g, R);
  out->push_back(g);
}

}  // namespace

void HingeEncoder::update() {
  const double raw = dJointGetHingeAngle(joint);
  unwrapped += model::wrapAngle(raw - last_raw);
  last_raw = raw;
}

void buildRobot(dWorldID world, const model::RobotDescription& d, const SimOptions& o, const RobotBuildParams& p,
                const model::VectorQ& q, const model::VectorQ& qd, OdeRobot* r) {
  using namespace model;
  *r = OdeRobot{};
  const double pitch = q[kBasePitch], pitch_rate = qd[kBasePitch];
  const Vector2d base(q[kBaseX], q[kBaseZ]), base_vel(qd[kBaseX], qd[kBaseZ]);
  const Vector2d com_offset = rot(pitch, Vector2d(d.torso_com_m[0], d.torso_com_m[1]));
  PlanarState torso{base + com_offset, base_vel + cross(pitch_rate, com_offset), pitch, pitch_rate};
  r->torso = makeBody(world, torso, d.torso_mass_kg, d.torso_inertia_kgm2);
  if (o.fix_torso) {
    dBodySetKinematic(r->torso);
  } else {
    r->plane = dJointCreatePlane2D(world, nullptr);
    dJointAttach(r->plane, r->torso, nullptr);
  }
  if (o.link_collisions) {
    dGeomID box = dCreateBox(nullptr, d.torso_size_m[0], d.torso_size_m[1], 0.2);
    dGeomSetBody(box, r->torso);
    r->body_geoms.push_back(box);
  }

  const double l1 = d.thigh.length_m, l2 = d.shank.length_m;
  const Interval stops[4] = {
      d.rear_hip_rad,
      {d.rear_knee_rad.lo + d.knee_hard_stop_margin_rad, d.rear_knee_rad.hi - d.knee_hard_stop_margin_rad},
      d.fore_hip_rad,
      {d.fore_knee_rad.lo + d.knee_hard_stop_margin_rad, d.fore_knee_rad.hi - d.knee_hard_stop_margin_rad}};
  auto makeHinge = [&](dBodyID b1, dBodyID b2, const Vector2d& anchor, int qi, const Interval& stop) {
    if (q[qi] < stop.lo - 1e-9 || q[qi] > stop.hi + 1e-9)
      throw std::invalid_argument("Simulator: q[" + std::to_string(qi) + "] = " + std::to_string(q[qi]) +
                                  " lies outside its hard stops [" + std::to_string(stop.lo) + ", " +
                                  std::to_string(stop.hi) + "]");
    dJointID j = dJointCreateHinge(world, nullptr);
    dJointAttach(j, b1, b2);
    dJointSetHingeAnchor(j, anchor.x(), anchor.y(), 0.0);
    // ODE's zero is the pose at SetAxis time (here q). Positive = body1 (the distal link) turning CCW relative
    // to body2: the model's sign. (dJointSetHingeAxisOffset was not used: in ODE 0.16 its reading came out as
    // 2 * relative angle - offset with absolute body rotations.)
    dJointSetHingeAxis(j, 0, 0, 1);
    dJointSetHingeParam(j, dParamLoStop, stop.lo - q[qi]);
    dJointSetHingeParam(j, dParamHiStop, stop.hi - q[qi]);
    dJointSetHingeParam(j, dParamStopERP, p.stop_erp);
    dJointSetHingeParam(j, dParamStopCFM, p.stop_cfm);
    dJointSetHingeParam(j, dParamBounce, 0.0);
    HingeEncoder& e = r->joints[static_cast<std::size_t>(qi - 3)];
    e.joint = j;
    e.centre = q[qi];
    e.unwrapped = 0.0;
    e.last_raw = dJointGetHingeAngle(j);
  };

  for (int leg = 0; leg < kNumLegs; ++leg) {
    Vector2d tip[2], tip_vel[2];
    for (int c = 0; c < 2; ++c) {
      const int hi = c == 0 ? hipRearIndex(leg) : hipForeIndex(leg);
      const int ki = c == 0 ? kneeRearIndex(leg) : kneeForeIndex(leg);
      const Vector2d hip = base + rot(pitch, Vector2d((c == 0 ? -0.5 : 0.5) * d.hip_spacing_m, 0.0));
      const Vector2d hip_vel = base_vel + cross(pitch_rate, hip - base);
      const double a_thigh = pitch + q[hi], w_thigh = pitch_rate + qd[hi];
      const double a_shank = a_thigh + q[ki], w_shank = w_thigh + qd[ki];
      const Vector2d knee = hip + l1 * linkDirection(a_thigh);
      const Vector2d knee_vel = hip_vel + cross(w_thigh, knee - hip);
      const Vector2d thigh_com = hip + d.thigh.com_from_joint_m * linkDirection(a_thigh);
      const Vector2d shank_com = knee + d.shank.com_from_joint_m * linkDirection(a_shank);
      tip[c] = knee + l2 * linkDirection(a_shank);
      tip_vel[c] = knee_vel + cross(w_shank, tip[c] - knee);
      r->thigh[leg][c] = makeBody(world, {thigh_com, hip_vel + cross(w_thigh, thigh_com - hip), a_thigh, w_thigh},
                                  d.thigh.mass_kg, d.thigh.inertia_kgm2);
      r->shank[leg][c] = makeBody(world, {shank_com, knee_vel + cross(w_shank, shank_com - knee), a_shank, w_shank},
                                  d.shank.mass_kg, d.shank.inertia_kgm2);
      makeHinge(r->thigh[leg][c], r->torso, hip, hi, stops[2 * c]);
      makeHinge(r->shank[leg][c], r->thigh[leg][c], knee, ki, stops[2 * c + 1]);
      if (o.link_collisions) {
        // body_geoms order (robotBodyName): torso, then per leg and side the thigh, then the shank.
        // Shank capsules stop short of the ankle so that only the foot sphere touches the ground when standing.
        const double cut = p.foot_radius + o.link_collision_radius_m + 0.01;
        addCapsule(r->thigh[leg][c], hip, knee, o.link_collision_radius_m, &r->body_geoms);
        addCapsule(r->shank[leg][c], knee, knee + (l2 - cut) * linkDirection(a_shank), o.link_collision_radius_m,
                   &r->body_geoms);
      }
    }
    if ((tip[0] - tip[1]).norm() > 1e-6 || (tip_vel[0] - tip_vel[1]).norm() > 1e-6)
      throw std::invalid_argument("Simulator: the loop of leg " + std::to_string(leg) +
                                  " is not closed (ankle mismatch " + std::to_string((tip[0] - tip[1]).norm()) +
                                  " m, " + std::to_string((tip_vel[0] - tip_vel[1]).norm()) + " m/s)");
    if (o.loop_closure == LoopClosureJoint::Ball) {
      r->closure[leg] = dJointCreateBall(world, nullptr);
      dJointAttach(r->closure[leg], r->shank[leg][0], r->shank[leg][1]);
      dJointSetBallAnchor(r->closure[leg], tip[0].x(), tip[0].y(), 0.0);
    } else {
      r->closure[leg] = dJointCreateHinge(world, nullptr);
      dJointAttach(r->closure[leg], r->shank[leg][0], r->shank[leg][1]);
      dJointSetHingeAnchor(r->closure[leg], tip[0].x(), tip[0].y(), 0.0);
      dJointSetHingeAxis(r->closure[leg], 0, 0, 1);
    }
    r->foot[leg] = dCreateSphere(nullptr, p.foot_radius);
    dGeomSetBody(r->foot[leg], r->shank[leg][0]);
    dGeomSetOffsetWorldPosition(r->foot[leg], tip[0].x(), tip[0].y(), 0.0);
  }
  const dReal* R = dBodyGetRotation(r->torso);
  r->pitch_last_raw = std::atan2(R[4], R[0]);
  r->pitch_unwrapped = pitch;
}

void destroyRobotGeoms(OdeRobot* r) {
  for (auto& g : r->foot)
    if (g) dGeomDestroy(g), g = nullptr;
  for (auto g : r->body_geoms) dGeomDestroy(g);
  r->body_geoms.clear();
}

void updateRobotAfterStep(OdeRobot* r, bool fixed_torso) {
  for (auto& e : r->joints) e.update();
  const dReal* R = dBodyGetRotation(r->torso);
  const double raw = std::atan2(R[4], R[0]);
  r->pitch_unwrapped += model::wrapAngle(raw - r->pitch_last_raw);
  r->pitch_last_raw = raw;
  if (!fixed_torso) {
    // Plane2D does not correct angular drift: keep the torso's rotation about z only.
    dMatrix3 Rn;
    dRFromAxisAndAngle(Rn, 0, 0, 1, raw);
    dBodySetRotation(r->torso, Rn);
    const dReal* w = dBodyGetAngularVel(r->torso);
    dBodySetAngularVel(r->torso, 0.0, 0.0, w[2]);
  }
}

void readRobotState(const OdeRobot& r, const model::RobotDescription& d, model::VectorQ* q, model::VectorQ* qd) {
  using namespace model;
  const dReal* p = dBodyGetPosition(r.torso);
  const dReal* v = dBodyGetLinearVel(r.torso);
  const double w = dBodyGetAngularVel(r.torso)[2];
  const double pitch = r.pitch_unwrapped;
  const Vector2d com_offset = rot(pitch, Vector2d(d.torso_com_m[0], d.torso_com_m[1]));
  const Vector2d base = Vector2d(p[0], p[1]) - com_offset;
  const Vector2d base_vel = Vector2d(v[0], v[1]) + cross(w, -com_offset);
  (*q)[kBaseX] = base.x();
  (*q)[kBaseZ] = base.y();
  (*q)[kBasePitch] = pitch;
  (*qd)[kBaseX] = base_vel.x();
  (*qd)[kBaseZ] = base_vel.y();
  (*qd)[kBasePitch] = w;
  for (std::size_t i = 0; i < r.joints.size(); ++i) {
    (*q)[static_cast<int>(i) + 3] = r.joints[i].position();
    (*qd)[static_cast<int>(i) + 3] = dJointGetHingeAngleRate(r.joints[i].joint);
  }
}

double closureError(const OdeRobot& r, int leg, const SimOptions& o) {
  dVector3 a, b;
  if (o.loop_closure == LoopClosureJoint::Ball) {
    dJointGetBallAnchor(r.closure[leg], a);
    dJointGetBallAnchor2(r.closure[leg], b);
  } else {
    dJointGetHingeAnchor(r.closure[leg], a);
    dJointGetHingeAnchor2(r.closure[leg], b);
  }
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

Eigen::Vector2d ankle(const OdeRobot& r, int leg, const SimOptions& o) {
  dVector3 a;
  if (o.loop_closure == LoopClosureJoint::Ball) dJointGetBallAnchor(r.closure[leg], a);
  else dJointGetHingeAnchor(r.closure[leg], a);
  return {a[0], a[1]};
}

}  // namespace mft::sim
