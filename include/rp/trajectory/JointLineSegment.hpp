#pragma once
/// @file
/// A synchronised straight-line joint motion from rest to rest.

#include "rp/model/ManipulatorModel.hpp"
#include "rp/trajectory/JerkLimitedProfile.hpp"
#include "rp/trajectory/Setpoint.hpp"

namespace rp {

/// The time-optimal rest-to-rest motion of all joints along the straight line from `start` to
/// `target` in joint space, every joint starting and finishing together.
///
/// One path parameter \f$s \in [0, 1]\f$ follows a JerkLimitedProfile, \f$q(t) = q_0 + \Delta
/// s(t)\f$; its limits are the tightest of the joints' limits divided by their distances,
/// \f$v_s = \min_i v_i / |\Delta_i|\f$ (likewise for acceleration and jerk), so at least one joint
/// reaches each of its limits and none exceeds any. Since the joints move in proportion, no
/// synchronised straight-line motion is faster.
class JointLineSegment {
 public:
  /// An empty segment (zero joints, zero duration).
  JointLineSegment() = default;
  /// Plans the motion.
  /// @param[in] start   joint positions at the start (n x 1) [rad]
  /// @param[in] target  joint positions at the end (n x 1) [rad]
  /// @param[in] vmax    velocity limits (n x 1) [rad/s], > 0
  /// @param[in] amax    acceleration limits (n x 1) [rad/s^2], > 0
  /// @param[in] jmax    jerk limits (n x 1) [rad/s^3], > 0
  /// @throws std::invalid_argument on sizes that differ or limits that are not positive
  /// Real-time safe: yes (no allocation).
  JointLineSegment(const JointVector& start, const JointVector& target, const JointVector& vmax,
                   const JointVector& amax, const JointVector& jmax);

  /// Duration of the motion [s] (0 when start equals target).
  double getDuration() const { return profile_.getDuration(); }
  /// The joint positions at the start (n x 1) [rad].
  const JointVector& getStart() const { return start_; }
  /// The joint displacement, target - start (n x 1) [rad].
  const JointVector& getDelta() const { return delta_; }
  /// The profile of the path parameter s (distance 1; 0 for no motion).
  const JerkLimitedProfile& getProfile() const { return profile_; }
  /// The setpoint at time `t` after the start (clamped to [0, duration]).
  /// @param[in]  t         time since the start [s]
  /// @param[out] setpoint  position, velocity and acceleration (each already sized n)
  /// Real-time safe: yes.
  void evaluate(double t, Setpoint& setpoint) const;

 private:
  JointVector start_, delta_;
  JerkLimitedProfile profile_;
};

}  // namespace rp
