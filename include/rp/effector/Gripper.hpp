#pragma once
/// @file
/// The generic gripper interface (paper section 3.4): open, close, relax; simulated grasping.

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "rp/core/PhysicalObject.hpp"

namespace rp {

class WorkPiece;

/// Generic interface of a gripper (paper section 3.4): `open()`, `close()` and `relax()`.
///
/// Every gripper registers the interactive commands `Open`, `Close` and `Relax` (for the
/// Scene Viewer's pop-up menu and `rp-device NAME Close`), describes a control panel with its
/// state, and answers the message `read` with `{"state": "closed", "grasped": [...]}`.
///
/// In simulation mode no hardware is touched. The fingers close along the gripper's x axis; the
/// point midway between the fingertips is the tool point (`toolPoint`, in the gripper's frame,
/// default 100 mm along z). A gripper that closes holds:
/// - every WorkPiece whose fingers are around it: its centre within `graspTolerance` (default
///   10 mm) of the tool point and its width across the fingers (its extent along the gripper's x
///   axis) not more than the `opening` between the open fingers (default 80 mm);
/// - every other object of its `graspable` ones (rp.cfg, or addGraspable()) whose origin is within
///   `graspRange` of the gripper's origin.
///
/// A held object is attached to the gripper's frame where it is and moves with it until the
/// gripper opens (or relaxes) and releases it: a work piece then falls to its table
/// (WorkPiece::release()), other objects stay where they are. While the gripper holds work
/// pieces and is mounted on a DefaultManipulator's `endEffector` frame (directly or through other
/// objects mounted there, such as a tool changer), their mass is the arm's payload
/// (DefaultManipulator::setPayload(): the total mass at the pieces' common centre of mass); it
/// is set back to none when they are released. Positions are world poses, through each object's
/// chain of connections and mounting frames (PhysicalObject::getWorldTransform()).
///
/// rp.cfg settings (besides PhysicalObject's): `toolPoint X Y Z` [mm] (default 0 0 100),
/// `opening` [mm] (default 80), `graspTolerance` [mm] (default 10), `graspRange` [mm] (default
/// 50), `graspable NAME...` (objects other than work pieces the simulated gripper can pick up).
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

  /// Declares `toolPoint`, `opening`, `graspTolerance`, `graspRange` and `graspable`.
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
  /// Sets the tool point: midway between the fingertips, in the gripper's frame.
  /// @param[in] point  the point [m]
  /// @throws std::invalid_argument if not finite
  void setToolPoint(const Vector<3>& point);
  /// The tool point in the gripper's frame [m].
  Vector<3> getToolPoint() const;
  /// The world pose of the tool point: the gripper's world pose moved to the tool point [m].
  /// Real-time safe: no.
  Transform getToolTransform() const;
  /// Sets the distance between the open fingers: the widest work piece the gripper can hold.
  /// @param[in] meters  the opening [m], > 0
  /// @throws std::invalid_argument if not positive and finite
  void setOpening(double meters);
  /// The distance between the open fingers [m].
  double getOpening() const;
  /// Sets how far a work piece's centre may be from the tool point to be held.
  /// @param[in] meters  the tolerance [m], >= 0
  /// @throws std::invalid_argument if negative or not finite
  void setGraspTolerance(double meters);
  /// How far a work piece's centre may be from the tool point to be held [m].
  double getGraspTolerance() const;
  /// Whether the fingers are around `piece` (see the class comment), wherever the gripper's state.
  /// @param[in] piece  a work piece
  /// Real-time safe: no.
  bool fingersAround(const WorkPiece& piece) const;

  /// The objects currently held (simulation only). Real-time safe: no.
  std::vector<PhysicalObject*> getGraspedObjects() const;

  /// A palm and two fingers reaching to the tool point, the opening apart. Real-time safe: no.
  Model3D get3DModel() const override;
  /// Adds the state and the grasped objects to the default panel. Real-time safe: no.
  ControlPanel getControlPanel() const override;
  /// Publishes the state (index into the panel's `state` choices) and the number of objects held.
  /// @param[out] snapshot  receives the values
  /// @return true
  /// Real-time safe: no.
  bool getStateSnapshot(StateSnapshot& snapshot) const override;
  /// Answers `read` with the state as JSON. Real-time safe: no.
  bool handleMessage(const std::string& type, const std::string& payload, std::string& reply) override;

  /// The pose of an object in the world: its transform composed along its connections and
  /// mounting frames [m] (PhysicalObject::getWorldTransform()).
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
  void updatePayload();  // the held pieces' mass as the arm's payload

  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::atomic<State> state_{State::Unknown};
};

}  // namespace rp
