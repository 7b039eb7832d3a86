// Internal: blends by overlapping two queued motions (Blend.hpp).
#include "Blend.hpp"

#include <algorithm>
#include <cmath>

namespace rp::internal {

namespace {

constexpr double kSlack = 1 + 1e-12;  // rounding of states that are exactly at a limit

double polynomial(const double* c, int degree, double t) {
  double r = c[degree];
  for (int m = degree - 1; m >= 0; --m) r = r * t + c[m];
  return r;
}

// Real roots of a t^2 + b t + c in (0, D); returns how many were written.
int quadraticRootsIn(double a, double b, double c, double D, double roots[2]) {
  int count = 0;
  auto keep = [&](double r) {
    if (r > 0 && r < D) roots[count++] = r;
  };
  const double scale = std::max({std::abs(a), std::abs(b), std::abs(c)});
  if (scale == 0) return 0;
  if (std::abs(a) <= 1e-14 * scale) {
    if (b != 0) keep(-c / b);
    return count;
  }
  const double disc = b * b - 4 * a * c;
  if (disc < 0) return 0;
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  keep(q / a);
  if (q != 0) keep(c / q);
  return count;
}

// Roots in (0, D) of the cubic k, whose stationary points are `split` (sorted): bisection on
// each monotone piece.
int cubicRootsIn(const double k[4], double D, const double* split, int splits, double roots[3]) {
  double edges[4];
  int e = 0;
  edges[e++] = 0;
  for (int i = 0; i < splits; ++i) edges[e++] = split[i];
  edges[e++] = D;
  int count = 0;
  for (int i = 0; i + 1 < e; ++i) {
    double lo = edges[i], hi = edges[i + 1];
    double flo = polynomial(k, 3, lo);
    const double fhi = polynomial(k, 3, hi);
    if (flo == 0 || fhi == 0 || (flo < 0) == (fhi < 0)) continue;
    for (int it = 0; it < 200 && hi - lo > 1e-15 * D; ++it) {
      const double mid = 0.5 * (lo + hi);
      const double fm = polynomial(k, 3, mid);
      if ((fm < 0) == (flo < 0)) {
        lo = mid;
        flo = fm;
      } else {
        hi = mid;
      }
    }
    roots[count++] = 0.5 * (lo + hi);
  }
  return count;
}

}  // namespace

QuinticPeaks quinticPeaks(const double c[6], double D) {
  const double v[5] = {c[1], 2 * c[2], 3 * c[3], 4 * c[4], 5 * c[5]};  // first derivative
  const double a[4] = {2 * c[2], 6 * c[3], 12 * c[4], 20 * c[5]};      // second
  const double j[3] = {6 * c[3], 24 * c[4], 60 * c[5]};                // third
  QuinticPeaks peaks;
  // Jerk: a parabola, largest at an end or at its vertex.
  peaks.jerk = std::max(std::abs(polynomial(j, 2, 0)), std::abs(polynomial(j, 2, D)));
  if (j[2] != 0) {
    const double tv = -j[1] / (2 * j[2]);
    if (tv > 0 && tv < D) peaks.jerk = std::max(peaks.jerk, std::abs(polynomial(j, 2, tv)));
  }
  // Acceleration: ends and roots of the jerk.
  double jr[2];
  const int njr = quadraticRootsIn(j[2], j[1], j[0], D, jr);
  if (njr == 2 && jr[0] > jr[1]) std::swap(jr[0], jr[1]);
  peaks.acceleration = std::max(std::abs(polynomial(a, 3, 0)), std::abs(polynomial(a, 3, D)));
  for (int i = 0; i < njr; ++i) peaks.acceleration = std::max(peaks.acceleration, std::abs(polynomial(a, 3, jr[i])));
  // Velocity: ends and roots of the acceleration.
  double ar[3];
  const int nar = cubicRootsIn(a, D, jr, njr, ar);
  peaks.velocity = std::max(std::abs(polynomial(v, 4, 0)), std::abs(polynomial(v, 4, D)));
  for (int i = 0; i < nar; ++i) peaks.velocity = std::max(peaks.velocity, std::abs(polynomial(v, 4, ar[i])));
  return peaks;
}

namespace {

// Fills the quintic blend of duration D from state a to state b; true if it keeps the limits.
bool tryQuintic(const Setpoint& a, const Setpoint& b, double D, const JointVector& vmax, const JointVector& amax,
                const JointVector& jmax, SegmentPlan& blend) {
  bool ok = true;
  for (Eigen::Index i = 0; i < a.position.size(); ++i) {
    double c[6];
    quinticCoefficients(a.position(i), a.velocity(i), a.acceleration(i), b.position(i), b.velocity(i),
                        b.acceleration(i), D, c);
    for (int m = 0; m < 6; ++m) blend.coefficients[static_cast<std::size_t>(m)](i) = c[m];
    const QuinticPeaks p = quinticPeaks(c, D);
    if (p.velocity > vmax(i) * kSlack || p.acceleration > amax(i) * kSlack || p.jerk > jmax(i) * kSlack) ok = false;
  }
  return ok;
}

constexpr int kScan = 48;  // points of the scans below

// Scans `ok` at kScan evenly spaced points from `first` to `last` (either way round) and returns
// the first point where it holds, refined by bisection towards `before` (the scan's starting side)
// or the last point where it failed, to 1e-9 relative; -1 if it holds at no point.
template <typename Ok>
double firstFeasible(double before, double first, double last, Ok ok) {
  double bad = before, good = -1;
  for (int k = 0; k < kScan; ++k) {
    const double x = first + (last - first) * k / (kScan - 1);
    if (ok(x)) {
      good = x;
      break;
    }
    bad = x;
  }
  if (good < 0) return -1;
  for (int it = 0; it < 30 && std::abs(good - bad) > 1e-9 * good; ++it) {
    const double mid = 0.5 * (bad + good);
    if (ok(mid)) good = mid;
    else bad = mid;
  }
  return good;
}

// Exact check of two overlapping joint motions (see Blend.hpp), joint by joint: each joint's
// position is a cubic between the instants where its jerk changes in either motion.
bool linesKeepLimits(const SegmentPlan& from, const SegmentPlan& to, double overlap, const JointVector& vmax,
                     const JointVector& amax, const JointVector& jmax) {
  const SynchronizedJointMotion& mf = from.line;
  const SynchronizedJointMotion& mt = to.line;
  const double shift = from.duration - overlap;  // from's local time at the overlap's start
  const Eigen::Index n = vmax.size();
  for (Eigen::Index i = 0; i < n; ++i) {
    const int joint = static_cast<int>(i);
    double cuts[16];
    int count = 0;
    cuts[count++] = 0;
    double b[6];
    int nb = mf.getJointBreakpoints(joint, b);
    for (int k = 0; k < nb; ++k) {
      if (b[k] - shift > 0 && b[k] - shift < overlap) cuts[count++] = b[k] - shift;
    }
    // A joint that arrives early (Synchronization::None) holds: its arrival is a breakpoint too.
    const double arrival = mf.getJointDuration(joint) - shift;
    if (arrival > 0 && arrival < overlap) cuts[count++] = arrival;
    nb = mt.getJointBreakpoints(joint, b);
    for (int k = 0; k < nb; ++k) {
      if (b[k] > 0 && b[k] < overlap) cuts[count++] = b[k];
    }
    cuts[count++] = overlap;
    for (int k = 1; k < count; ++k) {  // insertion sort of at most 15 values
      for (int m = k; m > 0 && cuts[m - 1] > cuts[m]; --m) std::swap(cuts[m - 1], cuts[m]);
    }
    auto state = [&](double u, double& v, double& a) {
      const ProfileState x = mf.evaluateJoint(joint, shift + u), y = mt.evaluateJoint(joint, u);
      v = x.velocity + y.velocity;
      a = x.acceleration + y.acceleration;
    };
    for (int c = 0; c + 1 < count; ++c) {
      const double u0 = cuts[c], u1 = cuts[c + 1];
      if (u1 <= u0) continue;
      double v0, a0, v1, a1;
      state(u0, v0, a0);
      state(u1, v1, a1);
      if (std::abs(v0) > vmax(i) * kSlack || std::abs(v1) > vmax(i) * kSlack) return false;
      if (std::abs(a0) > amax(i) * kSlack || std::abs(a1) > amax(i) * kSlack) return false;
      // The jerk is constant on the piece: the sum of both profiles' phases at its middle, exactly
      // (a finite difference with a 1e-6 margin once let a blend's jerk exceed the limit by 1e-7).
      const double um = 0.5 * (u0 + u1);
      if (std::abs(mf.jointJerk(joint, shift + um) + mt.jointJerk(joint, um)) > jmax(i) * kSlack) return false;
      if ((a0 < 0) != (a1 < 0) && a0 != a1) {
        const double us = u0 + a0 / (a0 - a1) * (u1 - u0);  // acceleration zero: velocity peak
        double vs, as;
        state(us, vs, as);
        if (std::abs(vs) > vmax(i) * kSlack) return false;
      }
    }
  }
  return true;
}

// Sampled check for pairs with a Cartesian path (see Blend.hpp).
bool sampledKeepLimits(const SegmentPlan& from, const SegmentPlan& to, double overlap, const JointVector& vmax,
                       const JointVector& amax, const JointVector& jmax) {
  SegmentPlan blend;
  blend.kind = SegmentKind::Blend;
  blend.from = &from;
  blend.to = &to;
  blend.fromStart = from.duration - overlap;
  blend.duration = overlap;
  const Eigen::Index n = vmax.size();
  Setpoint x, prev;
  x.position = x.velocity = x.acceleration = JointVector(n);
  prev = x;
  constexpr int kSamples = 2000;
  constexpr double kMargin = 0.98;
  const double dt = overlap / kSamples;
  for (int k = 0; k <= kSamples; ++k) {
    blend.evaluate(k * dt, x);
    for (Eigen::Index i = 0; i < n; ++i) {
      if (std::abs(x.velocity(i)) > kMargin * vmax(i) || std::abs(x.acceleration(i)) > kMargin * amax(i)) return false;
      if (k > 0 && std::abs(x.acceleration(i) - prev.acceleration(i)) > kMargin * jmax(i) * dt) return false;
    }
    prev = x;
  }
  return true;
}

}  // namespace

bool planBlend(const SegmentPlan& from, const SegmentPlan& to, const JointVector& vmax, const JointVector& amax,
               const JointVector& jmax, SegmentPlan& blend, double& entry) {
  const Eigen::Index n = vmax.size();
  const double stopping = (from.duration - from.exitTime) + to.entryTime;  // through the via point at rest
  constexpr double kShortest = 1e-3;
  if (!(stopping >= kShortest)) return false;
  blend = SegmentPlan();
  blend.kind = SegmentKind::Blend;
  blend.conditional = true;
  blend.end = to.end;  // not used for holding: a blend is always followed by `to`
  // First choice: overlap the motions as long as the radius and the limits allow.
  const double longest = std::min(from.duration - from.exitTime, to.entryTime);
  const bool lines = from.kind == SegmentKind::Line && to.kind == SegmentKind::Line;
  auto overlapOk = [&](double overlap) {
    return lines ? linesKeepLimits(from, to, overlap, vmax, amax, jmax)
                 : sampledKeepLimits(from, to, overlap, vmax, amax, jmax);
  };
  // The longest overlap: scanned from `longest` down, then bisected up.
  const double overlap =
      firstFeasible(longest, longest, longest / kScan, [&](double o) { return o >= kShortest && overlapOk(o); });
  if (overlap > 0) {
    blend.from = &from;
    blend.to = &to;
    blend.fromStart = from.duration - overlap;
    blend.duration = blend.exitTime = overlap;
    entry = overlap;
    return true;
  }
  // Otherwise a quintic from the exit point to the entry point.
  Setpoint a, b;
  a.position = a.velocity = a.acceleration = JointVector(n);
  b.position = b.velocity = b.acceleration = JointVector(n);
  from.evaluate(from.exitTime, a);
  to.evaluate(to.entryTime, b);
  for (auto& c : blend.coefficients) c = JointVector(n);
  constexpr double kLongestQuintic = 3;  // times stopping (Blend.hpp)
  const double longestQuintic = kLongestQuintic * stopping;  // the shortest: scanned up, bisected down
  const double D = firstFeasible(0, longestQuintic / kScan, longestQuintic,
                                 [&](double d) { return tryQuintic(a, b, d, vmax, amax, jmax, blend); });
  if (D < 0 || !tryQuintic(a, b, D, vmax, amax, jmax, blend)) return false;
  blend.fromStart = from.exitTime;
  blend.duration = blend.exitTime = D;
  entry = to.entryTime;
  return true;
}

}  // namespace rp::internal
