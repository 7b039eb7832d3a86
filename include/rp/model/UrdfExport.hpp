#pragma once
/// @file
/// Writes a manipulator model as URDF, so that other tools (ROS, MoveIt, Drake, browsers with
/// urdf-loader) can load the built-in arms.

#include <string>

#include "rp/model/ManipulatorModel.hpp"

namespace rp {

/// The URDF text of `model`: links `world`, `base_link`, one per joint named as the model's
/// links (getLinkName(): a loaded URDF's own names, `link1`..`linkN` for the built-in arms) and
/// `tool`; revolute or prismatic joints named as the model's joints (getJointName(): the URDF's,
/// `joint1`..`jointN` for the built-in arms) with the model's limits (effort = torque limit,
/// velocity limit), inertias at each link's centre of mass, and fixed joints `base` and `tool` for
/// the base and tool transforms. A URDF loaded and exported so keeps its joint names (and those
/// of the links the joints move); the frames the export adds are renamed `world_2`, `tool_2`, ...
/// where the model has a link or joint of that name. What is not kept: the root and tip link
/// names (the export's `base_link` and `tool`), links fixed to the chain (their mass is in the link
/// they hang on) and, where a joint's axis is not z, the orientation of its link's frame: link
/// frame k is the model's, turned so that its z axis is the joint axis (see loadUrdf()).
///
/// Dynamics: the inertial data are those of physicalModel() (MuJoCo and Drake refuse a massless link
/// with inertia and inertias that break the triangle inequality, as the Puma 560's published ones
/// do; the corrections are listed in a comment), each written in its principal axes so that no
/// reader has to diagonalise it. `<dynamics damping>` is the viscous friction \f$B G^2\f$ and
/// `friction` the Coulomb friction \f$|G| T_c\f$; URDF has one value for both directions, so for
/// two-sided friction the mean of the two magnitudes is written and a comment at the joint gives
/// both. URDF has no field for the motor inertia: a joint with motor inertia or a gear ratio other
/// than 1 gets a `<transmission>` whose actuator carries `mechanicalReduction` (\f$G\f$) and
/// Drake's `drake:rotor_inertia` (\f$J_m\f$) and `drake:gear_ratio` (\f$|G|\f$), which Drake turns
/// into the reflected inertia \f$G^2 J_m\f$; urdfdom, MuJoCo and loadUrdf() ignore it (exportMjcf()
/// carries it as armature). MuJoCo loads the result (tested for the Puma 560 and WAM with its mass
/// matrix and bias forces against the model's).
///
/// Frames: with each link transform split as \f$A_k = P_k\,J(q_k)\,Q_k\f$ (standard DH:
/// \f$P_k = R_z(\mathrm{offset}_k) T_z(d_k)\f$, \f$Q_k = T_x(a_k) R_x(\alpha_k)\f$; modified DH:
/// \f$P_k = R_x(\alpha_k) T_x(a_k) R_z(\mathrm{offset}_k) T_z(d_k)\f$, \f$Q_k = 1\f$), URDF link k is
/// the frame after joint k's motion \f$J\f$ (about or along z) and joint k sits at
/// \f$Q_{k-1} P_k\f$ in link k-1, so forward kinematics of the URDF equals the model's for every
/// joint vector (tested with urdfdom).
/// @param[in] model  the manipulator
/// @return the URDF document
/// Real-time safe: no.
std::string toUrdf(const ManipulatorModel& model);

}  // namespace rp
