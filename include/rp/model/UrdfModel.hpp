#pragma once
/// @file
/// Loading a manipulator model from a URDF file (liburdfdom), for any serial arm.

#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "rp/model/ManipulatorModel.hpp"

namespace rp {

/// Error loading a URDF file; the message starts with the file name.
class UrdfError : public std::runtime_error {
 public:
  /// Creates the error.
  /// @param[in] message  `FILE: what is wrong`
  explicit UrdfError(const std::string& message) : std::runtime_error(message) {}
};

/// Error in a value the caller gave in UrdfOptions (not in the file), such as a joint of
/// UrdfOptions::offChainPositions the description has no such (moving, off-chain) joint of: what()
/// starts with the file name, and option() and problem() let a caller say where the value came
/// from (an rp.cfg setting, a command-line option).
class UrdfOptionError : public UrdfError {
 public:
  /// Creates the error.
  /// @param[in] fileName  the URDF file
  /// @param[in] option    the option at fault, e.g. `offChainPositions`
  /// @param[in] problem   what is wrong with it, naming the joint
  UrdfOptionError(const std::string& fileName, const std::string& option, const std::string& problem)
      : UrdfError(fileName + ": UrdfOptions::" + option + ": " + problem), option_(option), problem_(problem) {}
  /// The option at fault, e.g. `offChainPositions`.
  const std::string& option() const noexcept { return option_; }
  /// What is wrong, without the file name and option, e.g. `there is no joint 'x' (...)`.
  const std::string& problem() const noexcept { return problem_; }

 private:
  std::string option_, problem_;
};

/// Options of loadUrdf().
struct UrdfOptions {
  /// Last link of the chain. Empty: from the root, follow the one child joint below which
  /// something moves (a branch of fixed frames only, such as `tool0` or a camera, is no branch)
  /// to the last moving link. Where everything that moves further on is a gripper (joints or
  /// links named grip..., finger, jaw or claw), the arm ends there and the gripper is lumped
  /// (see `notes`); where two or more other moving chains branch off, the load is refused with
  /// the leaf links below as candidate tips.
  std::string tip;
  bool requireDynamics = false;  ///< refuse links without inertial data (simulation needs them)
  /// Receives what the loader decided on its own that a user should know (which moving links off
  /// the chain it lumped, at which joint values); may be null.
  std::vector<std::string>* notes = nullptr;
  /// Values of moving joints off the chain (fingers, a jaw) at which the links they move are
  /// lumped into the chain link they hang on, by joint name [rad or m; deg or mm with
  /// offChainInDegreesAndMillimetres]. A joint not named here is at zero (within its limits); a
  /// mimic joint follows its master (multiplier and offset) unless it is named itself. Each name
  /// must be a revolute, continuous or prismatic joint off the chain that moves links lumped into
  /// the arm, and each value finite and within the joint's limits (UrdfOptionError otherwise).
  std::map<std::string, double> offChainPositions;
  /// Whether offChainPositions are in rp.cfg's units: degrees for revolute and continuous joints,
  /// millimetres for prismatic ones (UrdfManipulator's `offChainPositions` setting).
  bool offChainInDegreesAndMillimetres = false;
  /// The joints' velocity limits are the `<limit velocity>` of the file times this (a positive,
  /// finite number; UrdfOptionError otherwise): a client that plans for an arm it does not drive
  /// itself (RemoteManipulator) keeps a reserve for the arm's own controller. Velocities the file
  /// does not give (no `<limit>`, or `velocity="0"`) keep the ManipulatorModel default, unscaled.
  double velocityLimitScale = 1.0;
};

/// Loads the serial chain from the URDF root link to a tip link as a ManipulatorModel.
///
/// Revolute, continuous and prismatic joints become the model's joints (mimic joints on the chain
/// follow their master and are no joints of the model: ManipulatorModel::getChain() and
/// getCoupling()), fixed joints are merged
/// into the links around them (their inertias combined about the common centre of mass), links
/// moved by joints off the chain (fingers, a jaw) are lumped into the chain link they hang on at
/// a stated configuration (UrdfOptions::offChainPositions; zero by default; mimic joints follow
/// their master) and named in a note, and the
/// chain is kept as the file says it (DHConvention::Placement): each joint's fixed placement, then
/// its motion about or along its axis, as in KDL and Pinocchio, so that any chain loads exactly,
/// whatever its axes (nearly parallel, nearly intersecting, with float noise such as
/// `axis xyz="0 -1 -4.37114e-08"`). Model link frame i is the child link of joint i turned so that
/// its z axis is the joint's axis (unturned when the axis is z); the base transform is the unit
/// transform (the URDF root frame is the model's base) and the tool transform places the tip
/// link in the last link frame, so forward kinematics equals the URDF's for every joint vector
/// and joint values keep the URDF's zero and sign (a prismatic joint's value in metres along its
/// axis). Joint and link names are the URDF's. Limits come from `<limit>` (continuous joints get
/// +-2 pi; an effort or velocity of 0, or none, the ManipulatorModel defaults 100 N m and 3 rad/s);
/// `<dynamics damping friction>` become viscous and Coulomb friction. Before returning, the
/// model's forward kinematics is compared with the description's at the zero configuration and
/// at four others spread over the joint ranges.
/// @param[in] fileName  path of the URDF file
/// @param[in] options   tip link and whether dynamics are required
/// @return the model, named after the robot
/// @throws UrdfError naming the file for: a missing or unreadable file, malformed XML (`FILE:LINE:COLUMN: ...`)
///         or URDF (urdfdom's own errors, naming the joint or link), a floating or planar joint in the chain,
///         an unknown tip, a branching robot without a tip, no movable joint; and naming the joint or link: a
///         number that is not finite or beyond the bounds of docs/models.md, a negative `<limit>` effort or
///         velocity or a lower limit above the upper on the chain, an inertia that is not positive semi-definite,
///         a mimic joint naming a missing joint (or mimics in a circle) or on the chain following one off it, and
///         (with requireDynamics) a moving link without inertial data; UrdfOptionError (a UrdfError) for a bad
///         UrdfOptions::offChainPositions entry
/// Real-time safe: no.
std::unique_ptr<ManipulatorModel> loadUrdf(const std::string& fileName, const UrdfOptions& options = UrdfOptions());

/// The same as loadUrdf() for a URDF document given as text (a `robot_description` received over
/// the network, a string built in a program): the same checks and the same errors, in which
/// `sourceName` stands where loadUrdf() names the file (`<string>:LINE:COLUMN: ...`).
/// @param[in] text        the URDF document
/// @param[in] options     as loadUrdf()'s
/// @param[in] sourceName  what error messages call the document
/// @throws UrdfError as loadUrdf() (except for reading a file)
/// Real-time safe: no.
std::unique_ptr<ManipulatorModel> loadUrdfString(const std::string& text, const UrdfOptions& options = UrdfOptions(),
                                                 const std::string& sourceName = "<string>");

}  // namespace rp
