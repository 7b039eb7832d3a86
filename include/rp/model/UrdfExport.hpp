#pragma once
/// @file
/// Writes a manipulator model as URDF, so that other tools (ROS, MoveIt, Drake, browsers with
/// urdf-loader) can load the built-in arms.

#include <string>

#include "rp/model/ManipulatorModel.hpp"

namespace rp {

/// The URDF text of `model`: links `base_link`, `link1`..`linkN` and `tool`, revolute joints
/// `joint1`..`jointN` with the model's limits (effort = torque limit, velocity limit), inertias
/// at each link's centre of mass, and fixed joints for the base and tool transforms.
///
/// Frames: URDF link k is the DH frame k-1 turned by joint k about its z axis; joint k+1 sits at
/// \f$T_z(d_k) T_x(a_k) R_x(\alpha_k)\f$ in it, so forward kinematics of the URDF equals the
/// model's for every joint vector (tested with urdfdom).
/// @param[in] model  the manipulator
/// @return the URDF document
/// Real-time safe: no.
std::string toUrdf(const ManipulatorModel& model);

}  // namespace rp
