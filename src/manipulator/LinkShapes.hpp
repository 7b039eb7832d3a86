#pragma once
// The generic drawing of an arm's links from its kinematic parameters (DefaultManipulator's 3D
// model when the class gives none of its own).

#include "rp/core/PhysicalObject.hpp"
#include "rp/model/ManipulatorModel.hpp"

namespace rp::internal {

/// Adds the links of `model` to `m` as the kinematics place them: for each link a cylinder along
/// each of its offsets (along the joint axis by `d`, then along the common normal by `a`, for a
/// DH arm; to the next joint's origin for an arm given by placements), a motor housing on each
/// joint axis, a flange at the last link. Radii shrink along the chain from a size set by the
/// arm's reach, so a Puma 560 and a WAM look like themselves. Link `i` (from 1) is drawn in frame
/// `link<i>`; the first joint's housing in `base`. Sets `m.linksDrawn`.
/// @param[in]  model  the arm's model (without mimic joints)
/// @param[out] m      the object's 3D model, frames base, link1..linkN, endEffector
void addLinkShapes(const ManipulatorModel& model, Model3D& m);

}  // namespace rp::internal
