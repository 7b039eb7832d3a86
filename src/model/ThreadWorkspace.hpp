#pragma once
// A ManipulatorData of the calling thread, for the servo cycle's algorithms whose results are used
// right away (the simulation's forward dynamics, the control law's gravity torque).
//
// Why: an executor steps hundreds of arms in one thread, each arm once a period. With a
// ManipulatorData per arm, every arm-cycle writes its frames, mass matrix and scratch into memory
// that has left the caches since the arm's last cycle (about 20 KB an arm, several MB for hundreds
// of arms). One workspace per thread stays in the level-1 and level-2 caches from one arm to the
// next, as Pinocchio keeps one Data per thread and not per robot (docs/realtime.md, "What one
// arm-cycle costs").
//
// Contract: whatever a caller computes in it is valid only until the thread's next use of the
// workspace (by any arm); nothing may be kept in it across calls. The algorithms write every
// quantity they read back, so a workspace last used for another model of the same number of
// joints needs nothing reset.
#include "rp/model/ManipulatorData.hpp"

namespace rp::internal {

/// This thread's workspace set up for `model`: its n is the model's. Null for a model with mimic
/// joints (their data holds the full chain's, which the caller's own data keeps). The storage is
/// part of the thread's thread-local block, so no call allocates; when the number of joints
/// differs from the last caller's, the workspace is made again in place (about 3 KB written).
/// Real-time safe: yes.
ManipulatorData* threadWorkspace(const ManipulatorModel& model) noexcept;

/// `model`'s thread workspace if it has one, otherwise `own`.
inline ManipulatorData& workspaceOr(const ManipulatorModel& model, ManipulatorData& own) noexcept {
  ManipulatorData* w = threadWorkspace(model);
  return w != nullptr ? *w : own;
}

}  // namespace rp::internal
