#pragma once
/// @file
/// Results and scratch space of the kinematics and dynamics algorithms for one thread.

#include <array>
#include <memory>

#include <Eigen/Cholesky>

#include "rp/model/ManipulatorModel.hpp"

namespace rp {

/// Everything the algorithms compute for a ManipulatorModel, and their scratch space.
///
/// Made from a model, which fixes every size; each thread (servo, planner, viewer) has its own.
/// No algorithm allocates: all storage is inside this object.
struct ManipulatorData {
  /// Creates data sized for `model` (n = number of joints).
  /// @param[in] model  the model the data belongs to
  explicit ManipulatorData(const ManipulatorModel& model);

  int n;  ///< number of joints

  /// Pose of link frame i (i = 0..n-1, the frame at the distal end of link i+1) in the world,
  /// from the last forwardKinematics() [m].
  std::array<Transform, kMaxJoints> linkTransforms;
  /// Pose of the end-effector (tool) in the world, from the last forwardKinematics() [m].
  Transform endEffector;

  Jacobian jacobian;       ///< (6 x n) from the last jacobian call
  JointVector tau;         ///< (n x 1) result of inverseDynamics() [N m]
  JointVector qdd;         ///< (n x 1) result of forwardDynamics() [rad/s^2]
  JointMatrix massMatrix;  ///< (n x n) from the last massMatrix(), massMatrixAndBias() or forwardDynamics() [kg m^2]
  JointVector bias;        ///< (n x 1) h(q, qd) of the last massMatrixAndBias() or forwardDynamics() [N m]

  /// For a model with mimic joints: the data of its full chain (ManipulatorModel::getChain()),
  /// where the algorithms compute before mapping back; its `linkTransforms` include the links
  /// the mimic joints move (for drawing). Null for a model without mimic joints.
  std::unique_ptr<ManipulatorData> chain;

  /// @cond INTERNAL
  // The scratch the servo cycle's algorithms (kinematics, gravity, the composite-rigid-body
  // forward dynamics) use comes first, what the others use last: with hundreds of arms in one
  // cycle, the pages and cache lines each arm touches are the cost (docs/realtime.md).
  // Scratch of the recursive Newton-Euler algorithm, per link, in link coordinates.
  std::array<Matrix<3, 3>, kMaxJoints> R;       // rotation of A_i
  std::array<Vector<3>, kMaxJoints> pstar;      // origin of frame i from frame i-1, in frame i
  std::array<Vector<3>, kMaxJoints> w, wd, vd;  // angular velocity, acceleration, linear acceleration
  std::array<Vector<3>, kMaxJoints> F, N;       // inertial force and moment at the centre of mass
  JointVector scratchTau;
  // Scratch of forwardDynamics() and massMatrix(), per link, in world coordinates at the world
  // origin: the mass moment m c and the rotational inertia about the origin (the spatial forces
  // of the velocity products go into biasForce), and (also of the articulated-body algorithm,
  // at the link frame's origin in link coordinates) spatial vectors as (angular; linear).
  std::array<Vector<3>, kMaxJoints> massMoment;
  std::array<Matrix<3, 3>, kMaxJoints> originInertia;
  std::array<Eigen::Matrix<double, 6, 1>, kMaxJoints> biasForce, motionSubspace, inertiaTimesS;
  JointMatrix ldl;  // massMatrix = L D L^T: L strictly below the diagonal (unit diagonal), D on it
  // Scratch of the articulated-body algorithm and of the Newton-Euler mass matrix.
  std::array<Eigen::Matrix<double, 6, 6>, kMaxJoints> articulatedInertia;
  std::array<Eigen::Matrix<double, 6, 1>, kMaxJoints> biasAcceleration;
  JointVector abaD, abaU, zero, unitColumn;
  // With mimic joints: the chain's joint values, speeds, accelerations and torques.
  JointVector chainQ, chainQd, chainQdd, chainTau;
  /// @endcond
};

}  // namespace rp
