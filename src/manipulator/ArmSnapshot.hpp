// One servo cycle's joint state out of a DefaultManipulator's state snapshot, for the readers
// that must not mix cycles: the Scene Viewer's state frames (the poses drawn and the values sent)
// and the ROS 2 bridge's joint_states (positions, velocities and efforts of one cycle). The
// layout is DefaultManipulator::getStateSnapshot()'s, and is defined here only.
#pragma once

#include "rp/core/RoboticObject.hpp"
#include "rp/manipulator/DefaultManipulator.hpp"

namespace rp::internal {

/// Values in a DefaultManipulator's snapshot of n joints: q, qd, tau (n each), then power (0 or
/// 1), the servo cycles missed and the cycles at a torque limit.
constexpr int armSnapshotSize(int n) { return 3 * n + 3; }

/// The joint state of one servo cycle.
struct ArmCycleState {
  JointVector q, qd, tau;  ///< [rad or m], [rad/s or m/s], [N m or N]
  bool power = false;      ///< arm power was on
};

/// Copies the joint state out of `snap`, read from `arm` with n joints. False (and `out`
/// untouched) when `arm` is not a DefaultManipulator or `snap` not its snapshot: the caller then
/// reads the arm's getters.
inline bool armCycleState(const Manipulator& arm, const StateSnapshot& snap, int n, ArmCycleState& out) {
  if (snap.size != armSnapshotSize(n) || dynamic_cast<const DefaultManipulator*>(&arm) == nullptr) return false;
  out.q.resize(n);
  out.qd.resize(n);
  out.tau.resize(n);
  for (int i = 0; i < n; ++i) {
    out.q(i) = snap.values[i];
    out.qd(i) = snap.values[n + i];
    out.tau(i) = snap.values[2 * n + i];
  }
  out.power = snap.values[3 * n] != 0;
  return true;
}

}  // namespace rp::internal
