// A joint trajectory through timed points (rp/trajectory/TimedJointTrajectory.hpp).
#include "rp/trajectory/TimedJointTrajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "../core/ShortNumber.hpp"
#include "Segment.hpp"

namespace rp {

namespace {

// The velocity at a point between two others (times strictly increasing): Fritsch and Butland's
// weighted harmonic mean of the slopes on either side, 0 where the slopes differ in sign (or one
// is 0), so that the cubic through it stays between its neighbours.
double monotoneVelocity(double t0, double p0, double t1, double p1, double t2, double p2) {
  const double h0 = t1 - t0, h1 = t2 - t1;
  if (!(h0 > 0) || !(h1 > 0)) return 0;
  const double s0 = (p1 - p0) / h0, s1 = (p2 - p1) / h1;
  if (s0 * s1 <= 0) return 0;
  const double w0 = 2 * h1 + h0, w1 = h1 + 2 * h0;
  return (w0 + w1) / (w0 / s0 + w1 / s1);
}

std::string at(std::size_t point, const char* field) { return "point " + std::to_string(point) + " " + field; }

}  // namespace

TimedJointTrajectory::TimedJointTrajectory(std::vector<TimedJointPoint> points) : points_(std::move(points)) {
  if (points_.empty()) throw std::invalid_argument("a trajectory needs at least one point");
  if (points_.size() > static_cast<std::size_t>(kMaxPoints))
    throw std::invalid_argument("a trajectory of " + std::to_string(points_.size()) + " points, more than " +
                                std::to_string(kMaxPoints));
  const TimedJointPoint& first = points_.front();
  joints_ = static_cast<int>(first.position.size());
  if (joints_ < 1) throw std::invalid_argument(at(0, "positions: none"));
  const bool velocities = first.velocity.size() != 0, accelerations = first.acceleration.size() != 0;
  interpolation_ = accelerations ? Interpolation::QuinticHermite
                   : velocities  ? Interpolation::CubicHermite
                                 : Interpolation::Cubic;
  if (accelerations && !velocities) throw std::invalid_argument(at(0, "accelerations without velocities"));
  double previous = -1;
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const TimedJointPoint& p = points_[k];
    if (p.position.size() != joints_)
      throw std::invalid_argument(at(k, "positions: ") + std::to_string(p.position.size()) + " values, not " +
                                  std::to_string(joints_));
    if (p.velocity.size() != (velocities ? joints_ : 0))
      throw std::invalid_argument(at(k, "velocities: ") + std::to_string(p.velocity.size()) + " values, not " +
                                  std::to_string(velocities ? joints_ : 0) + " as point 0");
    if (p.acceleration.size() != (accelerations ? joints_ : 0))
      throw std::invalid_argument(at(k, "accelerations: ") + std::to_string(p.acceleration.size()) + " values, not " +
                                  std::to_string(accelerations ? joints_ : 0) + " as point 0");
    if (!p.position.allFinite()) throw std::invalid_argument(at(k, "positions: a value that is not finite"));
    if (!p.velocity.allFinite()) throw std::invalid_argument(at(k, "velocities: a value that is not finite"));
    if (!p.acceleration.allFinite()) throw std::invalid_argument(at(k, "accelerations: a value that is not finite"));
    if (!std::isfinite(p.time) || p.time < 0) throw std::invalid_argument(at(k, "time: negative or not finite"));
    if (!(p.time > previous))
      throw std::invalid_argument(at(k, "time: ") + internal::shortNumber(p.time) + " s, not after the point before (" +
                                  internal::shortNumber(previous) + " s)");
    previous = p.time;
  }
  const TimedJointPoint& last = points_.back();
  if ((velocities && !last.velocity.isZero(0)) || (accelerations && !last.acceleration.isZero(0)))
    throw std::invalid_argument(at(points_.size() - 1, "velocities/accelerations: not 0 at the last point"));

  const std::size_t n = points_.size();
  times_.resize(n);
  velocities_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    times_[k] = points_[k].time;
    velocities_[k] = velocities ? points_[k].velocity : JointVector(JointVector::Zero(joints_));
  }
  if (!velocities) {  // inner points; the first is estimated in start(), the last stays at rest
    for (std::size_t k = 1; k + 1 < n; ++k)
      for (int i = 0; i < joints_; ++i)
        velocities_[k](i) = monotoneVelocity(times_[k - 1], points_[k - 1].position(i), times_[k], points_[k].position(i),
                                             times_[k + 1], points_[k + 1].position(i));
  }
  coefficients_.resize(n * static_cast<std::size_t>(joints_));
  const JointVector zero = JointVector::Zero(joints_);
  for (std::size_t k = 1; k < n; ++k)
    computePiece(static_cast<int>(k), points_[k - 1].position, velocities_[k - 1],
                 accelerations ? points_[k - 1].acceleration : zero);
  start_.position = first.position;
  start_.velocity = zero;
  start_.acceleration = zero;
  start(start_);
}

void TimedJointTrajectory::piecePolynomial(int piece, int joint, double duration, double p0, double v0, double a0,
                                           double p1, double v1, double a1) noexcept {
  Coefficients& c = coefficients_[static_cast<std::size_t>(piece) * static_cast<std::size_t>(joints_) +
                                  static_cast<std::size_t>(joint)];
  c.fill(0);
  if (!(duration > 0)) {  // a piece of no time: at its end at once
    c[0] = p1;
    return;
  }
  if (interpolation_ == Interpolation::QuinticHermite) {
    internal::quinticCoefficients(p0, v0, a0, p1, v1, a1, duration, c.data());
    return;
  }
  // Cubic Hermite: p(u) = p0 + v0 u + c2 u^2 + c3 u^3 with p(D) = p1, p'(D) = v1.
  const double d = p1 - p0;
  c[0] = p0;
  c[1] = v0;
  c[2] = (3 * d / duration - 2 * v0 - v1) / duration;
  c[3] = (-2 * d / duration + v0 + v1) / (duration * duration);
}

void TimedJointTrajectory::computePiece(int piece, const JointVector& p0, const JointVector& v0, const JointVector& a0) {
  const auto k = static_cast<std::size_t>(piece);
  const double duration = times_[k] - pieceStart(piece);
  const bool quintic = interpolation_ == Interpolation::QuinticHermite;
  for (int i = 0; i < joints_; ++i)
    piecePolynomial(piece, i, duration, p0(i), v0(i), a0(i), points_[k].position(i), velocities_[k](i),
                    quintic ? points_[k].acceleration(i) : 0.0);
}

void TimedJointTrajectory::start(const Setpoint& state) noexcept {
  start_.position = state.position;
  start_.velocity = state.velocity;
  start_.acceleration = state.acceleration;
  if (interpolation_ == Interpolation::Cubic && points_.size() > 1) {
    // The first point's velocity from the start position (time 0) and the second point; with the
    // first point at time 0 it is the velocity the motion starts with.
    for (int i = 0; i < joints_; ++i)
      velocities_[0](i) = times_[0] > 0 ? monotoneVelocity(0, state.position(i), times_[0], points_[0].position(i),
                                                           times_[1], points_[1].position(i))
                                        : state.velocity(i);
    const JointVector zero = JointVector::Zero(joints_);
    computePiece(1, points_[0].position, velocities_[0], zero);
  }
  computePiece(0, state.position, state.velocity, state.acceleration);
}

void TimedJointTrajectory::evaluate(double t, Setpoint& out) const noexcept {
  out.position.resize(joints_);
  out.velocity.resize(joints_);
  out.acceleration.resize(joints_);
  if (t >= times_.back()) {
    out.position = points_.back().position;
    out.velocity.setZero();
    out.acceleration.setZero();
    return;
  }
  // The piece that ends at the first point at or after t.
  const auto piece = static_cast<std::size_t>(std::lower_bound(times_.begin(), times_.end(), t) - times_.begin());
  const double u = std::max(0.0, t - pieceStart(static_cast<int>(piece)));
  const Coefficients* c = &coefficients_[piece * static_cast<std::size_t>(joints_)];
  for (int i = 0; i < joints_; ++i) {
    const Coefficients& k = c[i];
    out.position(i) = k[0] + u * (k[1] + u * (k[2] + u * (k[3] + u * (k[4] + u * k[5]))));
    out.velocity(i) = k[1] + u * (2 * k[2] + u * (3 * k[3] + u * (4 * k[4] + u * 5 * k[5])));
    out.acceleration(i) = 2 * k[2] + u * (6 * k[3] + u * (12 * k[4] + u * 20 * k[5]));
  }
}

TrajectoryLimitViolation TimedJointTrajectory::findLimitViolation(const JointVector& min, const JointVector& max,
                                                                  const JointVector& vmax, int samples) const {
  TrajectoryLimitViolation v;
  Setpoint s;
  const int steps = std::max(1, samples + 1);
  for (std::size_t k = 0; k < points_.size() && !v.found; ++k) {
    const double t0 = pieceStart(static_cast<int>(k)), t1 = times_[k];
    for (int j = 0; j <= steps && !v.found; ++j) {
      // At its start, inside and at its end (evaluate() gives the end of piece k at t1).
      const double t = j == steps ? t1 : t0 + (t1 - t0) * j / steps;
      evaluate(t, s);
      for (int i = 0; i < joints_; ++i) {
        const double p = s.position(i), w = s.velocity(i);
        const double slack = 1e-9 * std::max(1.0, std::abs(p));
        if (p < min(i) - slack || p > max(i) + slack) {
          v = {true, static_cast<int>(k), i, false, t, p, p < min(i) ? min(i) : max(i)};
          break;
        }
        if (std::abs(w) > vmax(i) * (1 + 1e-9)) {
          v = {true, static_cast<int>(k), i, true, t, w, vmax(i)};
          break;
        }
      }
    }
  }
  return v;
}

}  // namespace rp
