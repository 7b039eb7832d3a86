// Internal: blends between two queued motions.
#pragma once

#include "Segment.hpp"

namespace rp::internal {

// Plans a blend from `from` to `to` by overlapping them: the next motion starts `overlap`
// seconds before the first ends, and the two displacements add up while both run. Both motions
// start and end at rest with zero acceleration, so the sum is continuous in position, velocity
// and acceleration at either end of the overlap, and it saves exactly `overlap` seconds.
// The overlap is the longest (found by a scan, then bisection) that
// - begins no earlier than from.exitTime and ends no later than to.entryTime (the blend radius),
// - keeps every joint within its velocity, acceleration and jerk limits. For two joint motions
//   (any Synchronization) this is checked exactly, joint by joint: between the instants where
//   the joint's jerk changes in either motion, its position is a cubic, so the velocity peaks at a piece's ends or where the
//   (linear) acceleration crosses zero, the acceleration at the ends, and the jerk is constant.
//   With a Cartesian path in the pair, it is checked at 2,000 samples against 98 % of the limits.
// If no overlap of at least a millisecond keeps the limits (two motions that each drive some
// joint at its limit rarely can overlap), the blend is a quintic per joint from `from` at its
// exitTime to `to` at its entryTime, matching position, velocity and acceleration at both ends,
// with the shortest duration found (a scan, then bisection) that keeps every joint within its
// limits, checked exactly from the polynomial's stationary points, and at most three times as
// long as stopping at the via point would take (so the arm passes the via point without stopping
// even when that costs a little time; the shortest such quintic is usually shorter than
// stopping). Returns false if neither exists: the motions then meet at rest.
// On success `blend` is a Blend segment: an overlap's `from` and `to` point at the arguments
// (re-point them when the plans move); blend.fromStart is where `from` ends and to.entryTime
// must be set to `entry`.
bool planBlend(const SegmentPlan& from, const SegmentPlan& to, const JointVector& vmax, const JointVector& amax,
               const JointVector& jmax, SegmentPlan& blend, double& entry);

struct QuinticPeaks {
  double velocity = 0, acceleration = 0, jerk = 0;
};
// The largest |p'|, |p''| and |p'''| over [0, D] of the quintic with coefficients c (exact: at
// the ends and the stationary points, from the roots of the next derivative).
QuinticPeaks quinticPeaks(const double c[6], double D);

}  // namespace rp::internal
