// Time-optimal jerk-limited rest-to-rest profile (rp/trajectory/JerkLimitedProfile.hpp).
#include "rp/trajectory/JerkLimitedProfile.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "../core/ShortNumber.hpp"

namespace rp {

JerkLimitedProfile::JerkLimitedProfile(double distance, double vmax, double amax, double jmax)
    : distance_(distance), jerk_(jmax) {
  if (!(distance >= 0) || !std::isfinite(distance)) {
    throw std::invalid_argument("JerkLimitedProfile: distance must be finite and >= 0, got " + internal::shortNumber(distance));
  }
  if (!(vmax > 0) || !(amax > 0) || !(jmax > 0)) {
    throw std::invalid_argument("JerkLimitedProfile: velocity, acceleration and jerk limits must be positive");
  }
  if (distance == 0) return;
  const double D = distance, v = vmax, a = amax, j = jmax;
  // Case 1: the velocity limit is reached.
  double tj, ta;
  if (v * j >= a * a) {
    tj = a / j;
    ta = tj + v / a;
  } else {
    tj = std::sqrt(v / j);
    ta = 2 * tj;
  }
  double tv = D / v - ta;
  if (tv < 0) {
    tv = 0;
    if (D >= 2 * a * a * a / (j * j)) {
      // Case 2: the acceleration limit is reached, the velocity limit is not.
      tj = a / j;
      ta = 0.5 * (tj + std::sqrt(tj * tj + 4 * D / a));
    } else {
      // Case 3: neither limit is reached.
      tj = std::cbrt(D / (2 * j));
      ta = 2 * tj;
    }
  }
  tj_ = tj;
  ta_ = ta;
  tv_ = tv;
  ap_ = j * tj;
  vp_ = ap_ * (ta - tj);
}

JerkLimitedProfile JerkLimitedProfile::withDuration(double distance, double duration, double vmax, double amax,
                                                    double jmax) {
  JerkLimitedProfile p(distance, vmax, amax, jmax);
  if (distance == 0) return p;
  const double shortest = p.getDuration();
  if (!(duration >= shortest * (1 - 1e-9)) || !std::isfinite(duration)) {
    throw std::invalid_argument("JerkLimitedProfile: a duration of " + internal::shortNumber(duration) +
                                " s is shorter than the minimum " + internal::shortNumber(shortest) + " s");
  }
  if (duration <= shortest) return p;
  // The minimum-time profile slowed down by s = duration / shortest: the limits v / s, a / s^2,
  // j / s^3 give the same case and every phase s times as long (see the header).
  const double s = duration / shortest;
  const double js = jmax / (s * s * s);
  if (!(js > 0) || !(amax / (s * s) > 0)) {
    // A distance so short against the duration that s^3 overflows: the profile that reaches
    // neither limit (the minimum-time case of such a distance), four jerk phases of T / 4 each
    // with the jerk that covers the distance, D = 2 j tj^3.
    const double tj = 0.25 * duration;
    p.tj_ = tj;
    p.ta_ = 2 * tj;
    p.tv_ = 0;
    p.jerk_ = distance / (2 * tj * tj * tj);
    p.ap_ = p.jerk_ * tj;
    p.vp_ = p.ap_ * tj;
    return p;
  }
  p = JerkLimitedProfile(distance, vmax / s, amax / (s * s), js);
  // Rounding may leave the end an ulp after `duration`: the end exactly at it or before.
  if (p.tv_ > 0) p.tv_ = std::max(0.0, duration - 2 * p.ta_);
  for (int i = 0; i < 64 && 2 * p.ta_ + p.tv_ > duration; ++i) {
    if (p.tv_ > 0) p.tv_ = std::nextafter(p.tv_, 0.0);
    else p.ta_ = std::nextafter(p.ta_, 0.0);
  }
  return p;
}

// The acceleration phase from rest: jerk +j for tj, constant acceleration, jerk -j for tj.
ProfileState JerkLimitedProfile::accelerationPhase(double t) const {
  const double j = jerk_, tj = tj_, ta = ta_, ap = ap_;
  ProfileState s;
  if (t <= tj) {
    s.acceleration = j * t;
    s.velocity = 0.5 * j * t * t;
    s.position = j * t * t * t / 6;
  } else if (t <= ta - tj) {
    const double u = t - tj;
    const double v1 = 0.5 * j * tj * tj, p1 = j * tj * tj * tj / 6;
    s.acceleration = ap;
    s.velocity = v1 + ap * u;
    s.position = p1 + v1 * u + 0.5 * ap * u * u;
  } else {
    // Mirror of the start: reaching vp with zero acceleration at ta.
    const double r = ta - t;  // time left in the phase
    const double halfDistance = 0.5 * vp_ * ta;
    s.acceleration = j * r;
    s.velocity = vp_ - 0.5 * j * r * r;
    s.position = halfDistance - vp_ * r + j * r * r * r / 6;
  }
  return s;
}

ProfileState JerkLimitedProfile::evaluate(double t) const {
  const double T = getDuration();
  if (distance_ == 0) return ProfileState{};
  if (t >= T) return ProfileState{distance_, 0, 0};  // exactly at rest at the end
  t = std::max(t, 0.0);
  if (t <= ta_) return accelerationPhase(t);
  if (t <= ta_ + tv_) {
    ProfileState s;
    s.velocity = vp_;
    s.position = 0.5 * vp_ * ta_ + vp_ * (t - ta_);
    return s;
  }
  // Deceleration: the acceleration phase played backwards from the end.
  const ProfileState m = accelerationPhase(T - t);
  ProfileState s;
  s.position = distance_ - m.position;
  s.velocity = m.velocity;
  s.acceleration = -m.acceleration;
  return s;
}

double JerkLimitedProfile::jerkAt(double t) const {
  const double T = getDuration();
  if (distance_ == 0 || !(t >= 0) || t >= T) return 0;
  if (t < tj_) return jerk_;
  if (t < ta_ - tj_) return 0;
  if (t < ta_) return -jerk_;
  if (t < T - ta_) return 0;
  if (t < T - ta_ + tj_) return -jerk_;
  if (t < T - tj_) return 0;
  return jerk_;
}

double JerkLimitedProfile::timeAtPosition(double position) const {
  if (distance_ == 0 || position <= 0) return 0;
  if (position >= distance_) return getDuration();
  double lo = 0, hi = getDuration();
  for (int i = 0; i < 200 && hi - lo > 1e-12; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (evaluate(mid).position < position) lo = mid;
    else hi = mid;
  }
  return 0.5 * (lo + hi);
}

int JerkLimitedProfile::getBreakpoints(double times[6]) const {
  if (distance_ == 0) return 0;
  const double T = getDuration();
  const double all[6] = {tj_, ta_ - tj_, ta_, ta_ + tv_, T - ta_ + tj_, T - tj_};
  int count = 0;
  double last = 0;
  for (double t : all) {
    if (t > last && t < T) times[count++] = last = t;
  }
  return count;
}

}  // namespace rp
