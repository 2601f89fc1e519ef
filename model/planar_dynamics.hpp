#pragma once
// Planar floating-base rigid-body dynamics of the biped (RBDL style: a model is plain data plus free
// functions). Planar spatial algebra with 3-vectors (angular, x, z). The floating base is the chain
// prismatic-x, prismatic-z, revolute-pitch (massless intermediate bodies), so qd = d/dt q exactly and the
// tree has 11 one-degree-of-freedom joints. Each leg is a tree (two thigh-shank chains from the torso);
// the loop closure at the foot is the holonomic constraint J_h (rear shank end - fore shank end = 0).
//
// Body frames: a link's origin is its proximal joint and the link lies along its local -z axis, so a link at
// absolute CCW angle a points along (sin a, -cos a). The torso frame is the base frame (origin on the hip axis).
#include <Eigen/Core>
#include <array>
#include <vector>

#include "model/coordinates.hpp"
#include "model/robot_description.hpp"

namespace mft::model {

enum class JointType { PrismaticX, PrismaticZ, Revolute };

struct PlanarBody {
  int parent = -1;                  // index of the parent body, -1 = world
  JointType joint = JointType::Revolute;
  Eigen::Vector2d joint_offset{0, 0};  // joint position in the parent body frame
  double mass = 0.0;
  Eigen::Vector2d com{0, 0};        // in the body frame
  double inertia = 0.0;             // about the CoM
};

// Body indices in the tree: body i is moved by joint (generalized coordinate) i.
struct PlanarModel {
  std::vector<PlanarBody> bodies;   // kNq bodies; bodies 0 and 1 are massless base carriages
  double gravity = 9.81;
  double shank_length = 0.0;
  // The foot of each leg is the distal end of its rear shank (the contact point), and the closure compares
  // it with the distal end of the fore shank.
  int rearShankBody(int leg) const { return kneeRearIndex(leg); }
  int foreShankBody(int leg) const { return kneeForeIndex(leg); }
  Eigen::Vector2d shankTip() const { return {0.0, -shank_length}; }
};

PlanarModel buildBipedModel(const RobotDescription& d);

// World-frame kinematics of one body frame (origin = its proximal joint). bias_acceleration is the origin's
// acceleration at qdd = 0 (velocity-product terms only; the angular one is zero in the plane).
struct BodyKinematics {
  double angle = 0.0;   // absolute CCW angle of the body frame
  double omega = 0.0;   // absolute angular velocity
  Eigen::Vector2d origin{0, 0}, velocity{0, 0}, bias_acceleration{0, 0};
};

// Everything one control tick needs, preallocated: updateModel fills it without allocating.
struct ModelData {
  MatrixQ M = MatrixQ::Zero();       // mass matrix
  VectorQ h = VectorQ::Zero();       // bias forces: Coriolis, centrifugal and gravity (M qdd + h = S_a' tau + ...)
  MatrixCQ Jc = MatrixCQ::Zero();    // foot contact Jacobian [right x, right z, left x, left z]
  VectorC Jc_dot_qd = VectorC::Zero();
  MatrixHQ Jh = MatrixHQ::Zero();    // loop closure Jacobian (rear tip - fore tip) [right x, z, left x, z]
  VectorH Jh_dot_qd = VectorH::Zero();
  VectorC foot_pos = VectorC::Zero();   // world [x, z] of the right foot, then the left
  VectorC foot_vel = VectorC::Zero();
  VectorH closure_error = VectorH::Zero();  // rear tip - fore tip, should be ~0
  Eigen::Vector2d com{0, 0}, com_vel{0, 0};
  Eigen::Matrix<double, 2, kNq> Jcom = Eigen::Matrix<double, 2, kNq>::Zero();
  Eigen::Vector2d Jcom_dot_qd{0, 0};
  // Workspace of the recursive algorithms (sized by kNq, never reallocated).
  std::array<Eigen::Matrix3d, kNq> X_up{};          // parent-to-body planar transforms
  std::array<Eigen::Vector3d, kNq> v{}, a{}, f{};   // body velocities, bias accelerations, forces
  std::array<Eigen::Matrix3d, kNq> Ic{};            // composite inertias
  std::array<Eigen::Vector3d, kNq> S{};             // joint motion subspaces
  std::array<Eigen::Matrix3d, kNq> X_base{};        // world-to-body transforms
  // Added with the implementation (backward compatible): the state of the last updateModel call, the
  // world-frame body kinematics it computed and the total mass.
  VectorQ q = VectorQ::Zero(), qd = VectorQ::Zero();
  std::array<BodyKinematics, kNq> body{};
  double total_mass = 0.0;
};

// Fills every field of ModelData at (q, qd): the full per-tick model update. Allocation-free.
// The model must be a tree in topological order (parent < index) with kNq bodies, as buildBipedModel makes
// it; otherwise these functions throw std::invalid_argument.
void updateModel(const PlanarModel& model, const VectorQ& q, const VectorQ& qd, ModelData* data);

// Pieces of updateModel, usable on their own.
void massMatrix(const PlanarModel& model, const VectorQ& q, ModelData* data);              // CRBA -> data->M
void biasForces(const PlanarModel& model, const VectorQ& q, const VectorQ& qd, ModelData* data);  // RNEA qdd = 0 -> data->h
// World position, Jacobian and Jdot*qd of a point fixed in a body (body frame coordinates).
Eigen::Vector2d pointPosition(const PlanarModel& model, const VectorQ& q, int body, const Eigen::Vector2d& point);
void pointJacobian(const PlanarModel& model, const VectorQ& q, int body, const Eigen::Vector2d& point,
                   Eigen::Matrix<double, 2, kNq>* J);
Eigen::Vector2d pointJdotQd(const PlanarModel& model, const VectorQ& q, const VectorQ& qd, int body,
                            const Eigen::Vector2d& point);
// World (x, z, angle) of a body frame.
Eigen::Vector3d bodyPose(const PlanarModel& model, const VectorQ& q, int body);

// Energies (for tests and the simulator's checks).
double kineticEnergy(const ModelData& data, const VectorQ& qd);
double potentialEnergy(const PlanarModel& model, const VectorQ& q);

// Paper (6): constrained forward dynamics with the loop closure. Given actuated torques and contact forces,
// returns qdd and the closure forces f_h with  M qdd - Jh' f_h = S_a' tau + Jc' f_c - h,  Jh qdd = -Jdot_h qd.
void constrainedForwardDynamics(const ModelData& data, const VectorA& tau, const VectorC& f_c, VectorQ* qdd,
                                VectorH* f_h);

// Paper (7)-(9) helpers. Lambda_h = (Jh M^-1 Jh')^-1, N_h = I - M^-1 Jh' Lambda_h Jh.
struct ClosureProjection {
  Eigen::Matrix<double, kNh, kNh> Lambda_h;
  MatrixQ N_h;
  MatrixQ Minv;
};
void closureProjection(const ModelData& data, ClosureProjection* out);

// Paper (7), the closure-projected equations of motion (f_h eliminated with N_h and Lambda_h):
//   M qdd + N_h' H + J_h' Lambda_h Jdot_h qd - N_h' S_a' tau_a = N_h' J_c' f_c,
// for the rows a selection S picks: S_f (the floating base) gives (8), S_a (the actuated joints) gives (9).
// Each matrix holds the selected rows of the factor it names; the products with qdd, H, Lambda_h Jdot_h qd,
// tau_a and f_c are the caller's, so that every caller keeps its own evaluation order. Allocation-free.
template <int R>
struct ProjectedDynamicsRows {
  Eigen::Matrix<double, R, kNq> M;    // S M
  Eigen::Matrix<double, R, kNq> NhT;  // S N_h' (rows of N_h' are columns of N_h)
  Eigen::Matrix<double, R, kNh> JhT;  // S J_h'
};
template <int R>
void projectedDynamicsRows(const ModelData& data, const ClosureProjection& proj, const std::array<int, R>& rows,
                           ProjectedDynamicsRows<R>* out) {
  for (int i = 0; i < R; ++i) {
    const int j = rows[i];
    out->M.row(i) = data.M.row(j);
    out->NhT.row(i) = proj.N_h.col(j).transpose();
    out->JhT.row(i) = data.Jh.col(j).transpose();
  }
}
// The floating-base coordinates [x, z, pitch]: the selection S_f of (8).
constexpr std::array<int, 3> kBaseIndex = {kBaseX, kBaseZ, kBasePitch};

// Paper (9) as an affine map of the QP's unknowns (qdd, f_c): the one place the actuated torque is computed.
// The WBC bounds tau with these matrices and decodes its command from them, so the torque the QP limits and
// the torque the robot receives are the same numbers.
//   tau_a = tau_qdd qdd + tau_fc f_c + tau_0,  K = (S_a N_h' S_a')^-1,
//   tau_qdd = K S_a M,  tau_fc = -K S_a N_h' J_c',  tau_0 = K S_a (N_h' h + J_h' Lambda_h Jdot_h qd).
struct ActuatedTorqueMap {
  Eigen::Matrix<double, kNa, kNq> tau_qdd;
  Eigen::Matrix<double, kNa, kNc> tau_fc;
  VectorA tau_0;
};
// Needs data from updateModel and proj from closureProjection at the same state. Allocation-free. Returns false
// if the result is not finite (S_a N_h' S_a' singular, e.g. at a leg singularity).
bool actuatedTorqueMap(const ModelData& data, const ClosureProjection& proj, ActuatedTorqueMap* out);
// The map evaluated at (qdd, f_c).
VectorA actuatedTorque(const ActuatedTorqueMap& map, const VectorQ& qdd, const VectorC& f_c);

// Paper (9) in one call: actuatedTorqueMap, then actuatedTorque. The velocity terms come from data (h and
// Jh_dot_qd of the last updateModel call), so qd must be the velocity data was updated with.
VectorA inverseDynamicsActuated(const ModelData& data, const ClosureProjection& proj, const VectorQ& qdd,
                                const VectorQ& qd, const VectorC& f_c);

// A configuration with both loops closed exactly: base at (x, z, pitch), each foot at the given offset from the
// hip axis in the base frame (x forward, z up; e.g. (0, -0.40) is straight below). Throws std::invalid_argument
// if a foot is out of reach. Optionally fills qd consistent with the closure (zero here: a standing pose).
VectorQ closedLoopConfiguration(const RobotDescription& d, const Eigen::Vector3d& base_pose,
                                const Eigen::Vector2d& right_foot_in_base, const Eigen::Vector2d& left_foot_in_base);

}  // namespace mft::model
