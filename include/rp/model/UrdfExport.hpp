#pragma once
/// @file
/// Writes a manipulator model as URDF, so that other tools (ROS, MoveIt, Drake, browsers with
/// urdf-loader) can load the built-in arms.

#include <string>

#include "rp/model/ManipulatorModel.hpp"

namespace rp {

/// The URDF text of `model`: links `base_link`, `link1`..`linkN` and `tool`, revolute or
/// prismatic joints `joint1`..`jointN` with the model's limits (effort = torque limit, velocity limit), inertias
/// at each link's centre of mass, and fixed joints for the base and tool transforms.
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
