// Synchronised straight-line joint motion (rp/trajectory/JointLineSegment.hpp).
#include "rp/trajectory/JointLineSegment.hpp"

#include <cmath>
#include <stdexcept>

namespace rp {

JointLineSegment::JointLineSegment(const JointVector& start, const JointVector& target, const JointVector& vmax,
                                   const JointVector& amax, const JointVector& jmax)
    : start_(start), delta_(target - start) {
  const Eigen::Index n = start.size();
  if (target.size() != n || vmax.size() != n || amax.size() != n || jmax.size() != n) {
    throw std::invalid_argument("JointLineSegment: start, target and the limits must have the same size");
  }
  double vs = INFINITY, as = INFINITY, js = INFINITY;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(vmax(i) > 0 && amax(i) > 0 && jmax(i) > 0)) {
      throw std::invalid_argument("JointLineSegment: the limits of joint " + std::to_string(i + 1) + " must be positive");
    }
    const double d = std::abs(delta_(i));
    if (d == 0) continue;
    vs = std::min(vs, vmax(i) / d);
    as = std::min(as, amax(i) / d);
    js = std::min(js, jmax(i) / d);
  }
  if (std::isfinite(vs)) profile_ = JerkLimitedProfile(1.0, vs, as, js);
}

void JointLineSegment::evaluate(double t, Setpoint& setpoint) const {
  const ProfileState s = profile_.evaluate(t);
  setpoint.position = start_ + delta_ * s.position;
  setpoint.velocity = delta_ * s.velocity;
  setpoint.acceleration = delta_ * s.acceleration;
}

}  // namespace rp
