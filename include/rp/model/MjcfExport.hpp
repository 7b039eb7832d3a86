#pragma once
/// @file
/// Writes a manipulator model as MJCF, MuJoCo's model format, with its drive train (armature,
/// damping, friction loss) and joint ranges.

#include <string>

#include "rp/model/ManipulatorModel.hpp"

namespace rp {

/// Options of exportMjcf().
struct MjcfOptions {
  double timestep = 0.001;           ///< MuJoCo's time step [s] (`<option timestep>`), > 0
  std::string integrator = "Euler";  ///< MuJoCo's integrator: `Euler` (semi-implicit, implicit damping), `RK4` or `implicit`
};

/// The MJCF text of `model`, which MuJoCo (2.2 and later) loads: a static body `base_link` at the
/// base transform, then one body per joint named as the model's links (getLinkName(): a loaded
/// URDF's own names, `link1`..`linkN` for the built-in arms), each with a hinge (revolute) or slide
/// (prismatic) joint about its z axis named as the model's joint (getJointName(): the URDF's,
/// `joint1`..`jointN` for the built-in arms), a site `tool` at the end-effector, a torque motor
/// `motor1`..`motorN` per joint (control range = the torque limit) and a keyframe `home` at the
/// model's home position (`base_link_2`, `tool_2`, ... where the model has a link or joint of
/// that name). Gravity is the model's.
///
/// The bodies are the frames URDF link k of toUrdf() uses (the joint frame after the joint's
/// motion), so forward kinematics equals the model's. Each joint carries its range (`limited`),
/// the reflected motor inertia \f$G^2 J_m\f$ as `armature`, viscous friction \f$B G^2\f$ as
/// `damping` and Coulomb friction \f$|G| T_c\f$ as `frictionloss`, which MuJoCo applies as a
/// stick-and-slip constraint. MuJoCo's friction loss has one value for both directions: for
/// two-sided friction (the Puma's \f$T_c^+ \ne -T_c^-\f$) the mean of the two magnitudes is
/// written and a comment in the file gives both. Velocity, acceleration and jerk limits have no
/// MJCF counterpart and are left out. The inertial data are those of physicalModel() (the
/// corrections are listed in a comment), written in principal axes (`diaginertia`, `quat`), so that
/// MuJoCo's mass matrix and bias forces equal massMatrix() (with motor inertia) and
/// \f$C(q,\dot q)\dot q + g(q)\f$ of physicalModel(model) (tested to 1e-9 relative).
/// @param[in] model    the manipulator (standard or modified DH, revolute and prismatic joints)
/// @param[in] options  time step and integrator
/// @return the MJCF document
/// @throws std::invalid_argument for a model without mass (kinematics only: MuJoCo needs the
///         inertial data of every moving body), a time step that is not a positive finite
///         number, or an unknown integrator
/// Real-time safe: no.
std::string exportMjcf(const ManipulatorModel& model, const MjcfOptions& options = MjcfOptions());

}  // namespace rp
