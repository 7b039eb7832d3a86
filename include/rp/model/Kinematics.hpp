#pragma once
/// @file
/// Forward kinematics and geometric Jacobians over a model and a data object.

#include "rp/model/ManipulatorData.hpp"

namespace rp {

/// The frame a Jacobian or wrench is expressed in.
enum class ReferenceFrame {
  Base,         ///< the world frame (the paper's base coordinates)
  EndEffector,  ///< the end-effector (tool) frame
};

/// Forward kinematics: the pose of every link frame and of the end-effector in the world.
/// @param[in]  model  the manipulator
/// @param[out] data   receives `linkTransforms` and `endEffector`
/// @param[in]  q      joint angles (n x 1) [rad]
/// @return `data.endEffector` [m]
/// Real-time safe: yes.
const Transform& forwardKinematics(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q);

/// The geometric Jacobian at the end-effector: \f$(v, \omega) = J \dot q\f$ with rows
/// vx vy vz wx wy wz, the linear velocity of the end-effector's origin and the angular velocity.
/// @param[in]  model  the manipulator
/// @param[out] data   receives `jacobian` (6 x n) and the forward kinematics of `q`
/// @param[in]  q      joint angles (n x 1) [rad]
/// @param[in]  frame  Base: both vectors in world coordinates; EndEffector: in tool coordinates
/// @return `data.jacobian`
/// Real-time safe: yes.
const Jacobian& jacobian(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                         ReferenceFrame frame = ReferenceFrame::Base);

/// Joint torques that make the end-effector exert `wrench` on its environment:
/// \f$\tau = J^T F\f$ (the paper's Figure 22 uses it for a force).
/// @param[in]  model   the manipulator
/// @param[out] data    scratch (receives the Jacobian of `q`)
/// @param[in]  q       joint angles (n x 1) [rad]
/// @param[in]  wrench  force [N] and moment [N m] (6 x 1), or a force only (3 x 1), in `frame`
/// @param[out] tau     joint torques (n x 1) [N m]
/// @param[in]  frame   frame `wrench` is expressed in
/// @throws MathException if `wrench` has neither 3 nor 6 elements or `tau` cannot hold n values
/// Real-time safe: yes.
void endEffectorForceToJointTorque(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                                   const Eigen::Ref<const Eigen::VectorXd>& wrench, Eigen::Ref<Eigen::VectorXd> tau,
                                   ReferenceFrame frame = ReferenceFrame::Base);

}  // namespace rp
