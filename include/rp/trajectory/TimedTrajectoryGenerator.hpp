#pragma once
/// @file
/// A trajectory generator that executes timed joint trajectories (TimedJointTrajectory) handed
/// over from any thread, each replacing the one before, continuous with the motion.

#include <cstdint>
#include <memory>
#include <string>

#include "rp/trajectory/TimedJointTrajectory.hpp"
#include "rp/trajectory/TrajectoryGenerator.hpp"

namespace rp {

/// Executes the TimedJointTrajectory objects given to execute(), one at a time, on one
/// manipulator: the Ros2Bridge's `<object>/joint_trajectory` (trajectory_msgs/JointTrajectory)
/// runs through it, and a program may use it in the same way.
///
/// A trajectory replaces the one being executed (as a new goal does in ros2_control's
/// joint_trajectory_controller): it starts `delay` seconds after the servo thread first sees it,
/// from the setpoint of that cycle (position, velocity and acceleration of the motion under way,
/// or of the hold), so the motion stays continuous in position and velocity. After its last point
/// the arm holds there until the next one.
///
/// Threads: execute() prepares nothing in the servo thread; it hands the trajectory over through
/// an atomic pointer. The servo thread takes it (one atomic exchange), computes its first piece
/// from the current setpoint (start(): a few multiplications per joint) and evaluates it, without
/// a lock or an allocation; trajectories it no longer uses are freed later by execute() (or the
/// destructor) in the caller's thread, never in the servo thread.
class TimedTrajectoryGenerator : public TrajectoryGenerator {
 public:
  /// Creates a generator with nothing to execute (a connected manipulator holds).
  /// @param[in] name  object name; empty for an automatic name
  explicit TimedTrajectoryGenerator(const std::string& name = "");
  /// Disconnects (the manipulator holds its setpoint) and frees the trajectories.
  ~TimedTrajectoryGenerator() override;

  /// The setpoint of the trajectory under way, or false (hold) before the first.
  /// Real-time safe: yes.
  bool getCurrentSetpoint(double time, Setpoint& setpoint) override;
  /// Refuses a second manipulator and one whose number of joints differs from the trajectories'.
  /// @throws std::invalid_argument if another manipulator is connected
  void attach(Manipulator& manipulator) override;

  /// Hands `trajectory` over: the servo thread starts it `delay` seconds after it first sees it,
  /// replacing the one under way (a trajectory handed over before and not yet started is dropped).
  /// @param[in] trajectory  the trajectory (its number of joints the manipulator's)
  /// @param[in] delay       [s], >= 0
  /// @throws std::invalid_argument for a null trajectory or a negative or non-finite delay
  /// Real-time safe: no (frees trajectories the servo thread has finished with).
  void execute(std::unique_ptr<TimedJointTrajectory> trajectory, double delay = 0);
  /// Whether the last trajectory handed over has reached its last point (true before the first).
  /// Real-time safe: yes.
  bool isDone() const noexcept;
  /// Number of trajectories the servo thread has started. Real-time safe: yes.
  std::uint64_t getStartedCount() const noexcept;
  /// The setpoint the generator gave in its last cycle (or the hold it was given).
  /// @param[out] position  joint positions (n x 1)
  /// @param[out] velocity  joint velocities (n x 1)
  /// @return false if the servo thread has not called it yet (or a read raced a write: try again)
  /// Real-time safe: yes.
  bool getLastSetpoint(JointVector& position, JointVector& velocity) const noexcept;
  /// Number of trajectories held (handed over and not yet freed), for tests. Real-time safe: no.
  std::size_t getHeldCount() const;

 private:
  struct Shared;
  std::unique_ptr<Shared> shared_;
};

}  // namespace rp
