// Rest-to-rest joint motion synchronised in time, in phase, or not (rp/trajectory/SynchronizedJointMotion.hpp).
#include "rp/trajectory/SynchronizedJointMotion.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "rp/trajectory/JointLineSegment.hpp"

namespace rp {

SynchronizedJointMotion::SynchronizedJointMotion(const JointVector& start, const JointVector& target,
                                                 const JointVector& vmax, const JointVector& amax,
                                                 const JointVector& jmax, Synchronization mode)
    : mode_(mode), start_(start), target_(target), delta_(target - start) {
  const Eigen::Index n = start.size();
  if (target.size() != n || vmax.size() != n || amax.size() != n || jmax.size() != n) {
    throw std::invalid_argument("SynchronizedJointMotion: start, target and the limits must have the same size");
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(vmax(i) > 0 && amax(i) > 0 && jmax(i) > 0)) {
      throw std::invalid_argument("SynchronizedJointMotion: the limits of joint " + std::to_string(i + 1) +
                                  " must be positive");
    }
    if (!std::isfinite(delta_(i))) {
      throw std::invalid_argument("SynchronizedJointMotion: the motion of joint " + std::to_string(i + 1) +
                                  " is not finite");
    }
  }
  if (mode == Synchronization::Phase) {
    line_ = JointLineSegment(start, target, vmax, amax, jmax).getProfile();
    duration_ = line_.getDuration();
    return;
  }
  // Each joint's minimum time; Time then stretches every joint to the slowest one's.
  double longest = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    profiles_[static_cast<std::size_t>(i)] = JerkLimitedProfile(std::abs(delta_(i)), vmax(i), amax(i), jmax(i));
    longest = std::max(longest, profiles_[static_cast<std::size_t>(i)].getDuration());
  }
  duration_ = longest;
  if (mode == Synchronization::Time) {
    for (Eigen::Index i = 0; i < n; ++i) {
      JerkLimitedProfile& p = profiles_[static_cast<std::size_t>(i)];
      if (delta_(i) != 0 && p.getDuration() < longest) {
        p = JerkLimitedProfile::withDuration(std::abs(delta_(i)), longest, vmax(i), amax(i), jmax(i));
      }
    }
  }
}

double SynchronizedJointMotion::getJointDuration(int joint) const {
  if (delta_(joint) == 0) return 0;
  if (mode_ != Synchronization::None) return duration_;
  return profiles_[static_cast<std::size_t>(joint)].getDuration();
}

ProfileState SynchronizedJointMotion::evaluateJoint(int joint, double t) const {
  const double d = delta_(joint);
  ProfileState s;
  if (mode_ == Synchronization::Phase) {
    if (t >= duration_) return ProfileState{d, 0, 0};
    s = line_.evaluate(t);
    s.position *= d;
    s.velocity *= d;
    s.acceleration *= d;
    return s;
  }
  if (t >= getJointDuration(joint)) return ProfileState{d, 0, 0};  // arrived, at rest
  s = profiles_[static_cast<std::size_t>(joint)].evaluate(t);
  if (d < 0) {
    s.position = -s.position;
    s.velocity = -s.velocity;
    s.acceleration = -s.acceleration;
  }
  return s;
}

void SynchronizedJointMotion::evaluate(double t, Setpoint& setpoint) const {
  if (mode_ == Synchronization::Phase) {
    const ProfileState s = line_.evaluate(t);
    if (t >= duration_) {
      setpoint.position = target_;
      setpoint.velocity.setZero();
      setpoint.acceleration.setZero();
      return;
    }
    setpoint.position = start_ + delta_ * s.position;
    setpoint.velocity = delta_ * s.velocity;
    setpoint.acceleration = delta_ * s.acceleration;
    return;
  }
  for (Eigen::Index i = 0; i < delta_.size(); ++i) {
    const ProfileState s = evaluateJoint(static_cast<int>(i), t);
    setpoint.position(i) = t >= getJointDuration(static_cast<int>(i)) ? target_(i) : start_(i) + s.position;
    setpoint.velocity(i) = s.velocity;
    setpoint.acceleration(i) = s.acceleration;
  }
}

double SynchronizedJointMotion::jointJerk(int joint, double t) const {
  const double d = delta_(joint);
  if (mode_ == Synchronization::Phase) return d * line_.jerkAt(t);
  if (t >= getJointDuration(joint)) return 0;
  const double j = profiles_[static_cast<std::size_t>(joint)].jerkAt(t);
  return d < 0 ? -j : j;
}

int SynchronizedJointMotion::getJointBreakpoints(int joint, double times[6]) const {
  if (delta_(joint) == 0) return 0;
  if (mode_ == Synchronization::Phase) return line_.getBreakpoints(times);
  return profiles_[static_cast<std::size_t>(joint)].getBreakpoints(times);
}

double SynchronizedJointMotion::distanceFrom(const JointVector& point, double t) const {
  double sum = 0;
  for (Eigen::Index i = 0; i < delta_.size(); ++i) {
    const double x = start_(i) + evaluateJoint(static_cast<int>(i), t).position - point(i);
    sum += x * x;
  }
  return std::sqrt(sum);
}

double SynchronizedJointMotion::timeWithinOfTarget(double radius) const {
  const JointVector target = start_ + delta_;
  double lo = 0, hi = duration_;
  if (distanceFrom(target, lo) <= radius) return 0;
  for (int i = 0; i < 200 && hi - lo > 1e-12; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (distanceFrom(target, mid) <= radius) hi = mid;
    else lo = mid;
  }
  return hi;
}

double SynchronizedJointMotion::timeWithinOfStart(double radius) const {
  double lo = 0, hi = duration_;
  if (distanceFrom(start_, hi) <= radius) return duration_;
  for (int i = 0; i < 200 && hi - lo > 1e-12; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (distanceFrom(start_, mid) <= radius) lo = mid;
    else hi = mid;
  }
  return lo;
}

}  // namespace rp
