#pragma once
/// @file
/// The interface of trajectory generators (paper section 3.3, Figure 8).

#include <mutex>
#include <string>
#include <vector>

#include "rp/core/PhysicalObject.hpp"
#include "rp/trajectory/Setpoint.hpp"

namespace rp {

class Manipulator;

/// Any object that produces a continuous stream of setpoints for manipulators.
///
/// A manipulator connected with Manipulator::setTrajectoryGenerator() calls
/// getCurrentSetpoint() from its servo thread every cycle. One generator may drive several
/// manipulators (paper Figure 23): each calls it with its own clock time, and on a shared clock
/// they all see the same setpoints. getCurrentSetpoint() must be real-time safe and may be called
/// from several servo threads at once.
///
/// A subclass whose objects may be destroyed while a system shutdown runs (a fault, Ctrl-C: the
/// shutdown's thread calls startShutdown() and isShutdownComplete() on every object) calls
/// withdrawObject() first in its destructor, as RoboticObject says; the shutdown then keeps off it.
class TrajectoryGenerator : public FunctionalObject {
 public:
  /// Creates a generator.
  /// @param[in] name  object name; empty for an automatic name
  explicit TrajectoryGenerator(const std::string& name = "") : FunctionalObject(name) {}
  /// Disconnects from every manipulator it drives (each then holds its position); returns once no
  /// servo cycle uses the generator.
  ~TrajectoryGenerator() override;

  /// The setpoint at servo-clock time `time`.
  /// @param[in]     time      the calling servo loop's clock time [s]
  /// @param[in,out] setpoint  on entry the manipulator's hold setpoint (its sizes fixed); on a
  ///                          true return the generator's setpoint
  /// @return true if the generator produced a setpoint, false if the manipulator should hold
  /// Real-time safe: must be (no allocation, locking or blocking).
  virtual bool getCurrentSetpoint(double time, Setpoint& setpoint) {
    (void)time;
    (void)setpoint;
    return false;
  }

  /// Called (in the caller's thread) when `manipulator` connects to this generator.
  /// @param[in] manipulator  the manipulator that will call getCurrentSetpoint()
  /// @throws std::invalid_argument if the generator cannot drive it (e.g. wrong number of joints)
  /// Real-time safe: no.
  virtual void attach(Manipulator& manipulator) { (void)manipulator; }
  /// Called (in the caller's thread) when `manipulator` disconnects.
  /// @param[in] manipulator  the manipulator that no longer calls getCurrentSetpoint()
  /// Real-time safe: no.
  virtual void detach(Manipulator& manipulator) { (void)manipulator; }

  /// The manipulators connected to this generator. Real-time safe: no.
  std::vector<Manipulator*> getManipulators() const;

 protected:
  /// Disconnects from every manipulator and returns once no servo cycle runs this generator.
  /// A derived class whose getCurrentSetpoint() may run while it is destroyed must call this
  /// first thing in its destructor (the base destructor calls it too, but by then the derived
  /// part is gone). Real-time safe: no.
  void releaseFromManipulators();

 private:
  friend class Manipulator;
  mutable std::mutex manipulatorsMutex_;
  std::vector<Manipulator*> manipulators_;
};

}  // namespace rp
