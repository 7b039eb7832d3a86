#pragma once
/// @file
/// The generic queue of motion segments (paper section 3.3).

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>

#include "rp/trajectory/JerkLimitedProfile.hpp"
#include "rp/trajectory/TrajectoryGenerator.hpp"

namespace rp {

/// A trajectory generator that executes a queue of segments (motions to target points and
/// dwells) in order, filled from the user's thread.
///
/// Segments are planned when they are queued, in the caller's thread; the servo threads only
/// evaluate them (no allocation, no lock). The queue holds at most kCapacity segments; queueing
/// into a full queue waits in the caller's thread until the robot has used one up.
///
/// Time: the first segment queued while the generator is idle starts in the first servo cycle
/// that sees it; every later segment starts exactly when the one before it ends.
///
/// When the generator is destroyed while connected manipulators still run, the destructor waits
/// until the queue is done, so a program that queues its motions and returns (paper Figures 21
/// and 23) still sees them executed.
class QueueTrajectoryGenerator : public TrajectoryGenerator {
 public:
  /// Largest number of queued segments.
  static constexpr int kCapacity = 64;

  /// Creates an empty generator.
  /// @param[in] name  object name; empty for an automatic name
  explicit QueueTrajectoryGenerator(const std::string& name = "");
  /// Waits until the queue is done (see the class description), then disconnects.
  ~QueueTrajectoryGenerator() override;

  bool getCurrentSetpoint(double time, Setpoint& setpoint) override;
  void attach(Manipulator& manipulator) override;

  /// Queues a dwell of `seconds` at the last target, and waits until the robot has come to rest
  /// there and the dwell is over: the synchronisation point of a program (paper Figure 21:
  /// `tragen.moveTo(...); tragen.stop(1); gripper.close();`).
  /// @param[in] seconds  dwell time [s], >= 0
  /// Real-time safe: no (waits).
  void stop(double seconds);
  /// Whether every queued segment has been executed. Real-time safe: yes.
  bool isDone() const;
  /// Number of segments not yet finished. Real-time safe: yes.
  int getSegmentsLeft() const;
  /// Waits until isDone(), a system shutdown, or `timeoutSeconds` (negative: no limit).
  /// @return true if the queue is done
  /// Real-time safe: no.
  bool waitUntilDone(double timeoutSeconds = -1) const;
  /// Plans the motions queued from now on with `fraction` (0, 1] of the model's velocity,
  /// acceleration and jerk limits (default 0.8): the servo control's tracking error needs the
  /// margin, because the manipulator's safety checks stop the system at the full limits.
  /// @param[in] fraction  share of the limits
  /// @throws std::invalid_argument outside (0, 1]
  void setSpeedFraction(double fraction);
  /// The share of the model's limits used for planning.
  double getSpeedFraction() const { return speedFraction_; }
  /// The target the last queued segment ends at (n x 1) [rad].
  /// @throws std::logic_error if no manipulator is connected
  JointVector getLastTarget() const;

 protected:
  /// Queues a synchronised straight-line joint motion from the last target to `target` under
  /// the connected manipulator's velocity, acceleration and jerk limits.
  /// @param[in] target  joint positions (n x 1) [rad]
  /// @throws std::invalid_argument if `target` has the wrong size or lies outside the joint limits
  void queueJointMotion(const JointVector& target);
  /// Queues a dwell of `seconds` at the last target.
  /// @param[in] seconds  dwell time [s]
  void queueDwell(double seconds);
  /// The manipulator whose model and position plan the motions (the first connected).
  /// @throws std::logic_error if none is connected
  Manipulator& getPlanningManipulator() const;

 private:
  struct Segment {
    JointVector start, delta;    // q(s) = start + delta * s, s in [0, 1]
    JerkLimitedProfile profile;  // s(t); zero length for a dwell
    double duration = 0;         // [s]
    std::atomic<double> startTime{0};
    std::atomic<int> state{0};  // 0 waiting, 1 being started, 2 started
  };
  void push(const JointVector& start, const JointVector& delta, const JerkLimitedProfile& profile, double duration);
  double startOf(Segment& segment, double time);

  std::array<Segment, kCapacity> ring_;
  std::atomic<std::uint64_t> head_{0}, tail_{0};  // segments [head, tail) are not finished
  mutable std::mutex producerMutex_;
  JointVector lastTarget_;  // the producer's: where the last queued segment ends
  bool haveTarget_ = false;
  double speedFraction_ = 0.8;
};

}  // namespace rp
