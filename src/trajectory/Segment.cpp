// Internal: evaluation of queued motion segments (Segment.hpp).
#include "Segment.hpp"

#include <algorithm>
#include <cmath>

namespace rp::internal {

void quinticCoefficients(double p0, double v0, double a0, double p1, double v1, double a1, double D, double c[6]) {
  const double d = p1 - p0, D2 = D * D, D3 = D2 * D;
  c[0] = p0;
  c[1] = v0;
  c[2] = 0.5 * a0;
  c[3] = (20 * d - (8 * v1 + 12 * v0) * D - (3 * a0 - a1) * D2) / (2 * D3);
  c[4] = (-30 * d + (14 * v1 + 16 * v0) * D + (3 * a0 - 2 * a1) * D2) / (2 * D3 * D);
  c[5] = (12 * d - 6 * (v1 + v0) * D + (a1 - a0) * D2) / (2 * D3 * D2);
}

void JointPath::evaluate(double s, JointVector& q0, JointVector& q1, JointVector& q2) const {
  const double x = std::clamp(s, 0.0, 1.0) * intervals;
  const int k = std::min(static_cast<int>(x), intervals - 1);
  const double u = x - k, h = 1.0 / intervals;
  const std::size_t a = static_cast<std::size_t>(k) * static_cast<std::size_t>(joints);
  const std::size_t b = a + static_cast<std::size_t>(joints);
  for (int i = 0; i < joints; ++i) {
    double c[6];
    quinticCoefficients(q[a + i], dq[a + i] * h, ddq[a + i] * h * h, q[b + i], dq[b + i] * h, ddq[b + i] * h * h, 1.0, c);
    q0(i) = c[0] + u * (c[1] + u * (c[2] + u * (c[3] + u * (c[4] + u * c[5]))));
    q1(i) = (c[1] + u * (2 * c[2] + u * (3 * c[3] + u * (4 * c[4] + u * 5 * c[5])))) / h;
    q2(i) = (2 * c[2] + u * (6 * c[3] + u * (12 * c[4] + u * 20 * c[5]))) / (h * h);
  }
}

void SegmentPlan::evaluate(double t, Setpoint& out) const {
  switch (kind) {
    case SegmentKind::Line:
      line.evaluate(t, out);
      return;
    case SegmentKind::Dwell:
      out.position = hold;
      out.velocity.setZero();
      out.acceleration.setZero();
      return;
    case SegmentKind::Blend: {
      const double u = std::clamp(t, 0.0, duration);
      if (from == nullptr) {
        for (Eigen::Index i = 0; i < out.position.size(); ++i) {
          double c[6];
          for (int m = 0; m < 6; ++m) c[m] = coefficients[static_cast<std::size_t>(m)](i);
          out.position(i) = c[0] + u * (c[1] + u * (c[2] + u * (c[3] + u * (c[4] + u * c[5]))));
          out.velocity(i) = c[1] + u * (2 * c[2] + u * (3 * c[3] + u * (4 * c[4] + u * 5 * c[5])));
          out.acceleration(i) = 2 * c[2] + u * (6 * c[3] + u * (12 * c[4] + u * 20 * c[5]));
        }
        return;
      }
      Setpoint second;
      second.position = second.velocity = second.acceleration = JointVector(out.position.size());
      from->evaluate(fromStart + u, out);
      to->evaluate(u, second);
      out.position += second.position - from->end;
      out.velocity += second.velocity;
      out.acceleration += second.acceleration;
      return;
    }
    case SegmentKind::Path: {
      const ProfileState s = profile.evaluate(t);
      // out.velocity and out.acceleration first receive dq/ds and d2q/ds2.
      path.evaluate(s.position, out.position, out.velocity, out.acceleration);
      out.acceleration = out.acceleration * (s.velocity * s.velocity) + out.velocity * s.acceleration;
      out.velocity *= s.velocity;
      return;
    }
  }
}

double SegmentPlan::timeAtFraction(double s) const {
  if (kind == SegmentKind::Line) return line.timeWithinOfStart(s * line.getDelta().norm());
  if (kind == SegmentKind::Path) return profile.timeAtPosition(s);
  return s * duration;
}

}  // namespace rp::internal
