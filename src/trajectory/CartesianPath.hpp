// Internal: straight-line Cartesian motion turned into a joint path at planning time.
#pragma once

#include <string>

#include "Segment.hpp"
#include "rp/math/Transform.hpp"
#include "rp/trajectory/CartesianLimits.hpp"

namespace rp::internal {

// Plans the end-effector's straight line from FK(qStart) to `goal` (position along the line,
// orientation by the shortest-arc rotation about one fixed axis) as a Path segment: inverse
// kinematics at nodes along the line, each from the previous node (so the arm keeps its
// configuration), joint derivatives dq/ds = J^+ dx/ds (plus the null-space drift of redundant
// arms), nodes added until the interpolated path stays within 1e-7 m of the line. The time
// profile s(t) is a jerk-limited S-curve under the Cartesian limits and under joint limits
// derived from the path's largest joint derivatives. Throws std::invalid_argument (message
// starting with `who`) when the line leaves the workspace or the joint limits, or passes a
// singularity. Returns a segment of zero duration for no motion.
// Whether the arm's Jacobian at q has lost rank (smallest singular value below 1e-4 of the
// largest, or fewer than six): no straight line can start there.
bool isSingular(const ManipulatorModel& model, const JointVector& q);

SegmentPlan planCartesianLine(const ManipulatorModel& model, const JointVector& qStart, const Transform& goal,
                              const CartesianLimits& limits, const JointVector& vmax, const JointVector& amax,
                              const JointVector& jmax, const std::string& who);

}  // namespace rp::internal
