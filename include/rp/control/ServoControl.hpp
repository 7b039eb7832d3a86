#pragma once
/// @file
/// The interface of servo controls (paper section 3.3, Figures 8 and 22).

#include <string>

#include "rp/core/PhysicalObject.hpp"

namespace rp {

class Manipulator;

/// Base class of servo control algorithms: computes a manipulator's control output (joint
/// torques) once per servo cycle.
///
/// A manipulator calls calculate() from its servo thread every cycle after reading the joints
/// and evaluating the trajectory generator. calculate() reads the manipulator through
/// `d_manipulator` (getJointPosition(), getJointVelocity(), getSetpoint(), the model) and writes
/// its result with `d_manipulator->setControlOutput(torque)`. If it writes nothing, the output of
/// that cycle is zero; with gravity compensation on, the manipulator adds the gravity torque to
/// whatever the servo control outputs.
///
/// Servo controls can be switched at any time with Manipulator::setServoControl(); the switch
/// takes effect between two cycles, and activate() is then called in the servo thread.
/// calculate() and activate() must not allocate, lock or block.
///
/// Example (paper Figure 22): a class with `void calculate() override` that computes a
/// virtual-wall force and calls `d_manipulator->setControlOutput(torque)`.
///
/// A subclass whose objects may be destroyed while a system shutdown runs (a fault, Ctrl-C: the
/// shutdown's thread calls startShutdown() and isShutdownComplete() on every object) calls
/// withdrawObject() first in its destructor, as RoboticObject says; the shutdown then keeps off it.
class ServoControl : public FunctionalObject {
 public:
  /// Creates a servo control not yet attached to a manipulator.
  /// @param[in] name  object name; empty for an automatic name
  explicit ServoControl(const std::string& name = "") : FunctionalObject(name) {}
  /// Detaches from the manipulator: if it is the manipulator's servo control, the manipulator
  /// switches back to its default control first and this returns once no servo cycle uses it.
  ~ServoControl() override;

  /// Computes the control output of the current cycle. Derived classes implement it; the default
  /// outputs nothing (zero torque, plus gravity if compensation is on).
  /// @pre attached to a manipulator (`d_manipulator` set)
  /// Real-time safe: must be.
  virtual void calculate() {}

  /// Called in the servo thread in the first cycle this control is active (after a switch or at
  /// start): reset integrators here for a bumpless transfer. The default does nothing.
  /// Real-time safe: must be.
  virtual void activate() {}

  /// Attaches the control to `manipulator` (Manipulator::setServoControl() calls it, in the
  /// caller's thread): size buffers and register parameters here. The default sets
  /// `d_manipulator`.
  /// @param[in] manipulator  the manipulator the control will drive
  /// Real-time safe: no.
  virtual void attach(Manipulator& manipulator) { d_manipulator = &manipulator; }

  /// The manipulator the control drives, or nullptr.
  Manipulator* getManipulator() const { return d_manipulator; }

 protected:
  /// Stops the manipulator from using this control (it switches back to its default control)
  /// and returns once no servo cycle runs it. A derived class should call this first thing in
  /// its destructor (the base destructor calls it too, but by then the derived part is gone).
  /// Real-time safe: no.
  void releaseFromManipulator();

  /// The manipulator this control drives (the paper's name, as Figure 22 uses it).
  Manipulator* d_manipulator = nullptr;

 private:
  friend class Manipulator;  // clears d_manipulator when the manipulator goes first
};

}  // namespace rp
