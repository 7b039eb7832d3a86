#pragma once
/// @file
/// The generic queue of motion segments (paper section 3.3).

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>

#include "rp/math/Transform.hpp"
#include "rp/trajectory/CartesianLimits.hpp"
#include "rp/trajectory/JerkLimitedProfile.hpp"
#include "rp/trajectory/Synchronization.hpp"
#include "rp/trajectory/TrajectoryGenerator.hpp"

namespace rp {

/// @cond INTERNAL
namespace internal {
struct SegmentPlan;
}
/// @endcond

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
/// Blending: with a blend radius (setJointBlendRadius(), setCartesianBlendRadius(); on by default,
/// kDefaultJointBlendRadius and kDefaultCartesianBlendRadius; 0 stops at every target), a
/// motion does not stop at the target before the next one. Once the arm comes within the radius
/// of that via point, it leaves the first motion and joins the next one where that is the radius
/// away from the via point, along a quintic in joint space that matches position, velocity and
/// acceleration at both ends, with the shortest duration that keeps every joint within its
/// velocity, acceleration and jerk limits (checked exactly, from the polynomial's stationary
/// points). The radius is capped at half of each motion. A blend needs the next motion queued
/// before the arm reaches the radius; if it comes later (or no blend keeps the limits), the arm
/// stops at the via point as without blending. Dwells never blend.
///
/// When the generator is destroyed while connected manipulators still run, the destructor waits
/// until the queue is done, so a program that queues its motions and returns (paper Figures 21
/// and 23) still sees them executed.
class QueueTrajectoryGenerator : public TrajectoryGenerator {
 public:
  /// Largest number of queued segments.
  static constexpr int kCapacity = 64;
  /// The joint blend radius of a new generator: 0.1 rad (5.7 degrees) from a via point.
  static constexpr double kDefaultJointBlendRadius = 0.1;
  /// The Cartesian blend radius of a new generator: 0.02 m from a via point.
  static constexpr double kDefaultCartesianBlendRadius = 0.02;

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
  /// Number of segments not yet finished (a blend counts as one). Real-time safe: yes.
  int getSegmentsLeft() const;
  /// Waits until isDone(), a system shutdown, or `timeoutSeconds` (negative: no limit).
  /// @return true if the queue is done
  /// Real-time safe: no.
  bool waitUntilDone(double timeoutSeconds = -1) const;
  /// Plans the motions queued from now on with `fraction` (0, 1] of the velocity, acceleration
  /// and jerk limits (default 0.8): the servo control's tracking error needs the margin, because
  /// the manipulator's safety checks stop the system at the model's limits.
  /// @param[in] fraction  share of the limits
  /// @throws std::invalid_argument outside (0, 1]
  void setSpeedFraction(double fraction);
  /// The share of the limits used for planning.
  double getSpeedFraction() const { return speedFraction_; }
  /// Replaces the model's joint limits for the motions queued from now on (the speed fraction
  /// still applies).
  /// @param[in] velocity      per joint [rad/s], > 0
  /// @param[in] acceleration  per joint [rad/s^2], > 0
  /// @param[in] jerk          per joint [rad/s^3], > 0
  /// @throws std::invalid_argument for a limit that is not positive or sizes that differ
  void setJointLimits(const JointVector& velocity, const JointVector& acceleration, const JointVector& jerk);
  /// Returns to the model's joint limits.
  void clearJointLimits();
  /// Sets the limits of straight-line Cartesian motion queued from now on (moveTo()).
  /// @throws std::invalid_argument for a limit that is not positive
  void setCartesianLimits(const CartesianLimits& limits);
  /// The limits of straight-line Cartesian motion.
  CartesianLimits getCartesianLimits() const;
  /// Sets the blend radius of joint motions queued from now on: the Euclidean distance in joint
  /// space [rad] from a via point at which the arm leaves one motion for the next (default
  /// kDefaultJointBlendRadius). 0 stops at every target.
  /// @throws std::invalid_argument for a negative radius
  void setJointBlendRadius(double radians);
  /// The blend radius of joint motions [rad].
  double getJointBlendRadius() const;
  /// Sets the blend radius of Cartesian motions queued from now on: the distance along the line
  /// [m] from a via point at which the arm leaves one motion for the next (default
  /// kDefaultCartesianBlendRadius). 0 stops at every target.
  /// @throws std::invalid_argument for a negative radius
  void setCartesianBlendRadius(double metres);
  /// The blend radius of Cartesian motions [m].
  double getCartesianBlendRadius() const;
  /// Sets how the joints of joint motions queued from now on are synchronised (see
  /// Synchronization and SynchronizedJointMotion): Synchronization::Time (the default) ends all
  /// joints together at the shortest common duration, each on its own jerk-limited profile;
  /// Synchronization::Phase keeps the straight line in joint space (up to about 10 % longer with
  /// limits that differ per joint); Synchronization::None moves each joint on its own minimum
  /// time. Cartesian motions (moveTo()) are not affected.
  /// @param[in] mode  the synchronisation mode
  /// @throws std::invalid_argument for a value that is no Synchronization
  void setSynchronization(Synchronization mode);
  /// How the joints of joint motions are synchronised.
  Synchronization getSynchronization() const;
  /// The target the last queued segment ends at (n x 1) [rad].
  /// @throws std::logic_error if no manipulator is connected
  JointVector getLastTarget() const;
  /// Number of blends planned so far (a blend that came too late to be used still counts).
  int getBlendCount() const;

 protected:
  /// Queues a joint motion from the last target to `target` under the joint velocity,
  /// acceleration and jerk limits, its joints synchronised as setSynchronization() says (see
  /// SynchronizedJointMotion).
  /// @param[in] target  joint positions (n x 1) [rad]
  /// @throws std::invalid_argument if `target` has the wrong size or lies outside the joint limits
  void queueJointMotion(const JointVector& target);
  /// Queues a straight-line motion of the end-effector from the last target's pose to `pose`
  /// (world frame, metres): the position along the line, the orientation by the shortest-arc
  /// rotation about a fixed axis, the joints found by inverse kinematics that follows the arm's
  /// configuration (IK branch) from the start. The line is turned into a joint path when queued
  /// (its end-effector stays within 1e-7 m of the line), timed under the Cartesian limits and the
  /// joint limits.
  /// @param[in] pose  end-effector pose wanted [m]
  /// @throws std::invalid_argument if the arm has fewer than six joints, or the line leaves the
  ///         workspace or the joint limits, or passes through a singularity
  void queueCartesianMotion(const Transform& pose);
  /// Queues a dwell of `seconds` at the last target.
  /// @param[in] seconds  dwell time [s]
  void queueDwell(double seconds);
  /// The manipulator whose model and position plan the motions (the first connected).
  /// @throws std::logic_error if none is connected
  Manipulator& getPlanningManipulator() const;

 private:
  struct Slot;
  struct Limits;
  Limits planningLimits(const ManipulatorModel& model) const;
  void pushPlanned(internal::SegmentPlan&& plan);
  void waitForRoom(int slots);
  void publish(std::uint64_t index, internal::SegmentPlan&& plan);
  double startOf(Slot& slot, double time, double offset);
  void setRadius(double& radius, double value, const char* what, const char* unit);

  std::unique_ptr<std::array<Slot, kCapacity>> ring_;
  std::atomic<std::uint64_t> head_{0}, tail_{0};  // segments [head, tail) are not finished
  mutable std::mutex producerMutex_;
  JointVector lastTarget_;  // the producer's: where the last queued segment ends
  bool haveTarget_ = false;
  std::uint64_t lastMotion_ = 0;  // index + 1 of the last queued motion that may blend (0: none)
  int blends_ = 0;
  double speedFraction_ = 0.8;
  double jointBlendRadius_ = kDefaultJointBlendRadius, cartesianBlendRadius_ = kDefaultCartesianBlendRadius;
  Synchronization synchronization_ = Synchronization::Time;
  CartesianLimits cartesianLimits_;
  JointVector userVelocity_, userAcceleration_, userJerk_;  // empty: the model's
};

}  // namespace rp
