#pragma once
/// @file
/// The time-optimal jerk-limited (S-curve) rest-to-rest motion along one coordinate.

namespace rp {

/// Position, velocity and acceleration of a profile at one instant.
struct ProfileState {
  double position = 0;      ///< [units]
  double velocity = 0;      ///< [units/s]
  double acceleration = 0;  ///< [units/s^2]
};

/// The minimum-time rest-to-rest motion over a distance under velocity, acceleration and jerk
/// limits: the classic seven-phase S-curve (jerk +j, 0, -j, cruise, -j, 0, +j), symmetric in
/// acceleration and deceleration.
///
/// Three cases, all closed form: the velocity limit is reached (a cruise phase), or not; and in
/// each the acceleration limit is reached (a constant-acceleration phase), or not. With
/// \f$T_j\f$ the jerk phase, \f$T_a\f$ the whole acceleration phase and \f$T_v\f$ the cruise:
/// - reaching \f$v\f$: \f$T_j = a/j, T_a = T_j + v/a\f$ if \f$v j \ge a^2\f$, else
///   \f$T_j = \sqrt{v/j}, T_a = 2T_j\f$; then \f$T_v = D/v - T_a\f$ if positive;
/// - otherwise, if \f$D \ge 2a^3/j^2\f$: \f$T_j = a/j\f$,
///   \f$T_a = (T_j + \sqrt{T_j^2 + 4D/a})/2\f$, \f$T_v = 0\f$;
/// - otherwise \f$T_j = (D/2j)^{1/3}\f$, \f$T_a = 2T_j\f$, \f$T_v = 0\f$.
/// The duration is \f$2T_a + T_v\f$ (Biagiotti & Melchiorri, *Trajectory Planning for Automatic
/// Machines and Robots*, section 3.4, for the rest-to-rest case).
class JerkLimitedProfile {
 public:
  /// A profile of zero length.
  JerkLimitedProfile() = default;
  /// Plans the motion over `distance` (>= 0) under the limits (all > 0).
  /// @param[in] distance  length of the motion [units]
  /// @param[in] vmax      velocity limit [units/s]
  /// @param[in] amax      acceleration limit [units/s^2]
  /// @param[in] jmax      jerk limit [units/s^3]
  /// @throws std::invalid_argument for a negative distance or non-positive limits
  JerkLimitedProfile(double distance, double vmax, double amax, double jmax);
  /// Plans the rest-to-rest motion over `distance` that takes exactly `duration`, for time
  /// synchronisation of several joints (Synchronization::Time).
  ///
  /// From rest to rest every duration at or above the minimum is reachable: the minimum-time
  /// profile slowed down by \f$s = T / T_{min} \ge 1\f$, which is the minimum-time profile under
  /// the limits \f$v/s, a/s^2, j/s^3\f$ (the same case of the three, every phase \f$s\f$ times as
  /// long). Its peak velocity, acceleration and jerk are the minimum-time profile's divided by
  /// \f$s, s^2, s^3\f$: the joints that wait for the slowest one move as gently as they can in
  /// the common time, rather than rushing at their limits and then cruising slowly, which also
  /// leaves room to overlap two motions at a blend.
  /// @param[in] distance  length of the motion [units], >= 0
  /// @param[in] duration  duration wanted [s], >= the minimum-time profile's (a duration below it
  ///                      by at most 1e-9 relative is taken as the minimum)
  /// @param[in] vmax      velocity limit [units/s], > 0
  /// @param[in] amax      acceleration limit [units/s^2], > 0
  /// @param[in] jmax      jerk limit [units/s^3], > 0
  /// @return the profile; getDuration() equals `duration` (for a zero distance, 0: it stays at rest)
  /// @throws std::invalid_argument for a duration shorter than the minimum, or bad limits
  /// Real-time safe: yes, except for the exception (no allocation on success).
  static JerkLimitedProfile withDuration(double distance, double duration, double vmax, double amax, double jmax);

  /// Duration of the motion [s]. Real-time safe: yes.
  double getDuration() const { return 2 * ta_ + tv_; }
  /// Peak velocity reached [units/s].
  double getPeakVelocity() const { return vp_; }
  /// Peak acceleration reached [units/s^2].
  double getPeakAcceleration() const { return ap_; }
  /// The state at time `t` (clamped to [0, duration]). Real-time safe: yes.
  ProfileState evaluate(double t) const;
  /// The jerk at time `t` [units/s^3]: +j, 0 or -j by phase (at a switching instant, the phase
  /// that begins there; 0 outside (0, duration)). Real-time safe: yes.
  double jerkAt(double t) const;
  /// The time at which the motion has covered `position` (clamped to [0, distance]); the
  /// position grows strictly while the motion lasts, so the answer is unique.
  /// @param[in] position  distance covered [units]
  /// @return time [s] in [0, duration], to within 1e-12 s
  /// Real-time safe: yes (bisection, at most 200 evaluations).
  double timeAtPosition(double position) const;
  /// The instants inside (0, duration) where the jerk changes (at most six), in increasing order;
  /// between two of them the position is a cubic in time.
  /// @param[out] times  receives the instants [s]
  /// @return how many were written
  /// Real-time safe: yes.
  int getBreakpoints(double times[6]) const;

 private:
  ProfileState accelerationPhase(double t) const;  // 0 <= t <= ta_
  double distance_ = 0, jerk_ = 0;
  double tj_ = 0, ta_ = 0, tv_ = 0;  // jerk, acceleration and cruise phase durations [s]
  double ap_ = 0, vp_ = 0;           // peak acceleration and velocity
};

}  // namespace rp
