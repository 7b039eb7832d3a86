#pragma once
/// @file
/// The generic gripper interface (paper section 3.4): open, close, relax.

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "rp/core/PhysicalObject.hpp"

namespace rp {

/// Generic interface of a gripper (paper section 3.4): `open()`, `close()` and `relax()`.
///
/// Every gripper registers the interactive commands `Open`, `Close` and `Relax` (for the
/// Scene Viewer's pop-up menu and `rp-device NAME Close`), describes a control panel with its
/// state, and answers the message `read` with `{"state": "closed", "grasped": [...]}`.
///
/// In simulation mode no hardware is touched. A gripper that closes within `graspRange` of one of
/// its `graspable` objects (rp.cfg, or addGraspable()) attaches that object to itself: the object
/// moves with the gripper until the gripper opens (or relaxes) and releases it where it is.
/// Positions are compared through each object's chain of connections (mounting frames other than
/// `base` are taken as the mount's base).
///
/// rp.cfg settings (besides PhysicalObject's): `graspRange` [mm] (default 50),
/// `graspable NAME...` (objects the simulated gripper can pick up).
///
/// A hardware failure leaves the state unchanged, sets the object's error status (code 1, the
/// driver's message; see getErrorStatus()) and makes the command return false.
class Gripper : public PhysicalObject {
 public:
  /// What the gripper was last told to do.
  enum class State {
    Unknown,  ///< no command yet
    Open,     ///< opened
    Closed,   ///< closed
    Relaxed   ///< relaxed (no force, no power to the actuators)
  };

  /// Creates the gripper and registers its commands.
  /// @param[in] name  object name (rp.cfg section); empty for an automatic name
  /// @throws ConfigError if a setting is invalid
  /// Real-time safe: no.
  explicit Gripper(const std::string& name = "");
  ~Gripper() override;

  /// Declares `graspRange` and `graspable`.
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);

  /// Opens the gripper (and releases a grasped object in simulation).
  /// @return true on success; false on a hardware failure (see getErrorStatus())
  /// Real-time safe: no.
  virtual bool open();
  /// Closes the gripper (and grasps a graspable object in range, in simulation).
  /// @return true on success; false on a hardware failure
  /// Real-time safe: no.
  virtual bool close();
  /// Relaxes the gripper: no force either way (and releases a grasped object in simulation).
  /// @return true on success; false on a hardware failure
  /// Real-time safe: no.
  virtual bool relax();

  /// The state after the last successful command. Real-time safe: yes.
  State getState() const noexcept { return state_.load(); }
  /// The name of a state: `unknown`, `open`, `closed` or `relaxed`.
  /// @param[in] state  a state
  static const char* stateName(State state) noexcept;

  /// Adds an object the simulated gripper may grasp.
  /// @param[in] object  the object (must outlive the gripper or be removed first)
  /// Real-time safe: no.
  void addGraspable(PhysicalObject& object);
  /// Removes an object from the graspable ones (releasing it if held).
  /// @param[in] object  the object
  void removeGraspable(PhysicalObject& object);
  /// Sets how close a graspable object must be to be grasped.
  /// @param[in] meters  distance between the gripper's and the object's origins [m]
  void setGraspRange(double meters);
  /// The objects currently held (simulation only). Real-time safe: no.
  std::vector<PhysicalObject*> getGraspedObjects() const;

  /// Adds the state and the grasped objects to the default panel. Real-time safe: no.
  ControlPanel getControlPanel() const override;
  /// Publishes the state (index into the panel's `state` choices) and the number of objects held.
  /// @param[out] snapshot  receives the values
  /// @return true
  /// Real-time safe: no.
  bool getStateSnapshot(StateSnapshot& snapshot) const override;
  /// Answers `read` with the state as JSON. Real-time safe: no.
  bool handleMessage(const std::string& type, const std::string& payload, std::string& reply) override;

  /// The pose of an object in the world: its transform composed along its connections [m].
  /// @param[in] object  any physical object
  /// Real-time safe: no.
  static Transform worldTransform(const PhysicalObject& object);

 protected:
  /// Drives the hardware to open. @return true on success; on failure, set the error first.
  virtual bool hardwareOpen() = 0;
  /// Drives the hardware to close. @return true on success; on failure, set the error first.
  virtual bool hardwareClose() = 0;
  /// Drives the hardware to relax. @return true on success; on failure, set the error first.
  virtual bool hardwareRelax() = 0;

 private:
  void graspInSimulation();
  void releaseInSimulation();

  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::atomic<State> state_{State::Unknown};
};

}  // namespace rp
