// Internal: the motion segments a QueueTrajectoryGenerator executes, and their evaluation.
#pragma once

#include <array>
#include <vector>

#include "rp/trajectory/SynchronizedJointMotion.hpp"

namespace rp::internal {

/// Coefficients c[0..5] of the quintic p(t) = sum c_m t^m on [0, D] with the given position,
/// velocity and acceleration at both ends.
void quinticCoefficients(double p0, double v0, double a0, double p1, double v1, double a1, double D, double c[6]);

// A joint path q(s), s in [0, 1], sampled at `intervals` + 1 uniform nodes with q, dq/ds and
// d2q/ds2, and interpolated by quintic Hermite pieces (continuous in q, q', q'').
struct JointPath {
  int joints = 0;
  int intervals = 0;
  std::vector<double> q, dq, ddq;  // node-major: node k, joint i at k * joints + i

  // q(s) and its first two derivatives with respect to s, into `out` (sized `joints`).
  void evaluate(double s, JointVector& q0, JointVector& q1, JointVector& q2) const;
};

enum class SegmentKind { Line, Dwell, Blend, Path };

// One queued motion. Local time runs from 0 to `duration`.
struct SegmentPlan {
  SegmentKind kind = SegmentKind::Dwell;
  SynchronizedJointMotion line;             // Line (a joint motion in any Synchronization)
  JointVector hold;                         // Dwell: the position held
  // Blend, either the two motions overlapped, q(t) = from(fromStart + t) + to(t) - from.end for
  // t in [0, duration] (`from` set), or a quintic per joint, q(t) = sum c_m t^m (`from` null,
  // `coefficients`). `from` ends at local time fromStart, `to` goes on from its entryTime.
  std::array<JointVector, 6> coefficients;
  const SegmentPlan* from = nullptr;
  const SegmentPlan* to = nullptr;
  double fromStart = 0;
  JerkLimitedProfile profile;               // Path: s(t)
  JointPath path;                           // Path: q(s)
  double length = 0;                        // Path: length of the Cartesian line [m]
  double duration = 0;                      // [s]
  // Blending: a blend into the next segment may begin from local time `exitTime` on (equal to
  // `duration` when this segment does not blend); a blend from the previous segment may last
  // until local time `entryTime` of this one (set to the blend's duration when it is planned).
  double exitTime = 0;
  double entryTime = 0;
  bool conditional = false;  // Blend: runs only if the segment before accepted it
  JointVector end;           // the position at `duration`

  // The setpoint at local time t (clamped). Real-time safe.
  void evaluate(double t, Setpoint& out) const;
  // The time at the path fraction s (Path: of the path parameter; Line: of the Euclidean
  // distance in joint space from the start, the last time the arm is that close to it), for planning.
  double timeAtFraction(double s) const;
};

}  // namespace rp::internal
