#pragma once
/// @file
/// A rest-to-rest joint motion whose joints are synchronised in time, in phase, or not at all.

#include <array>

#include "rp/model/ManipulatorModel.hpp"
#include "rp/trajectory/JerkLimitedProfile.hpp"
#include "rp/trajectory/Setpoint.hpp"
#include "rp/trajectory/Synchronization.hpp"

namespace rp {

/// The motion of all joints from rest at `start` to rest at `target` under per-joint velocity,
/// acceleration and jerk limits, every joint on a jerk-limited (S-curve) profile:
/// - Synchronization::Time: every joint takes exactly the shortest common duration \f$T\f$.
///   From rest to rest a joint can take any duration at or above its own minimum (see
///   JerkLimitedProfile::withDuration()), so \f$T\f$ is the slowest joint's minimum and no
///   synchronised motion is shorter;
/// - Synchronization::Phase: one profile of the path parameter along the straight line in joint
///   space (see JointLineSegment);
/// - Synchronization::None: each joint on its own minimum-time profile, holding at its target
///   once there; the duration is the slowest joint's.
///
/// Planning and evaluation allocate nothing (at most kMaxJoints joints).
class SynchronizedJointMotion {
 public:
  /// An empty motion (zero joints, zero duration).
  SynchronizedJointMotion() = default;
  /// Plans the motion.
  /// @param[in] start   joint positions at the start (n x 1) [rad]
  /// @param[in] target  joint positions at the end (n x 1) [rad]
  /// @param[in] vmax    velocity limits (n x 1) [rad/s], > 0
  /// @param[in] amax    acceleration limits (n x 1) [rad/s^2], > 0
  /// @param[in] jmax    jerk limits (n x 1) [rad/s^3], > 0
  /// @param[in] mode    how the joints are synchronised
  /// @throws std::invalid_argument on sizes that differ, limits that are not positive, or a
  ///         displacement that is not finite
  /// Real-time safe: yes (no allocation, except for the exception).
  SynchronizedJointMotion(const JointVector& start, const JointVector& target, const JointVector& vmax,
                          const JointVector& amax, const JointVector& jmax,
                          Synchronization mode = Synchronization::Time);

  /// Duration of the motion [s] (0 when start equals target): when the last joint arrives.
  double getDuration() const { return duration_; }
  /// How the joints are synchronised.
  Synchronization getSynchronization() const { return mode_; }
  /// The joint positions at the start (n x 1) [rad].
  const JointVector& getStart() const { return start_; }
  /// The joint displacement, target - start (n x 1) [rad].
  const JointVector& getDelta() const { return delta_; }
  /// The time joint `joint` arrives at its target [s] (the whole duration unless the mode is None;
  /// 0 for a joint that does not move).
  /// @param[in] joint  index, 0 <= joint < n
  double getJointDuration(int joint) const;
  /// The setpoint at time `t` after the start (clamped to [0, duration]); a joint that has
  /// arrived is exactly at its target, at rest.
  /// @param[in]  t         time since the start [s]
  /// @param[out] setpoint  position, velocity and acceleration (each already sized n)
  /// Real-time safe: yes.
  void evaluate(double t, Setpoint& setpoint) const;
  /// One joint's displacement from its start, velocity and acceleration at time `t` (clamped).
  /// @param[in] joint  index, 0 <= joint < n
  /// @param[in] t      time since the start [s]
  /// Real-time safe: yes.
  ProfileState evaluateJoint(int joint, double t) const;
  /// One joint's jerk at time `t` [rad/s^3] (see JerkLimitedProfile::jerkAt()).
  /// @param[in] joint  index, 0 <= joint < n
  /// @param[in] t      time since the start [s]
  double jointJerk(int joint, double t) const;
  /// The instants inside (0, duration) where joint `joint`'s jerk changes (at most six), in
  /// increasing order; between two of them its position is a cubic in time.
  /// @param[in]  joint  index, 0 <= joint < n
  /// @param[out] times  receives the instants [s]
  /// @return how many were written
  int getJointBreakpoints(int joint, double times[6]) const;
  /// The first time at which the arm is within `radius` (Euclidean, in joint space) of the target.
  /// Every joint moves monotonically towards its target, so the distance falls monotonically.
  /// @param[in] radius  [rad], >= 0
  /// @return time [s] in [0, duration], to within 1e-12 s
  double timeWithinOfTarget(double radius) const;
  /// The last time at which the arm is within `radius` (Euclidean, in joint space) of the start.
  /// @param[in] radius  [rad], >= 0
  /// @return time [s] in [0, duration], to within 1e-12 s
  double timeWithinOfStart(double radius) const;

 private:
  double distanceFrom(const JointVector& point, double t) const;
  Synchronization mode_ = Synchronization::Time;
  JointVector start_, target_, delta_;
  double duration_ = 0;
  JerkLimitedProfile line_;                                 // Phase: the path parameter, distance 1
  std::array<JerkLimitedProfile, kMaxJoints> profiles_{};   // Time and None: |delta_i| per joint
};

}  // namespace rp
