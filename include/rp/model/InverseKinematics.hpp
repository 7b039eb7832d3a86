#pragma once
/// @file
/// Numeric inverse kinematics for any serial chain.

#include <cstdint>

#include "rp/model/ManipulatorData.hpp"

namespace rp {

/// Outcome of an inverse kinematics solve.
enum class IkStatus {
  Solved,         ///< the pose is reached within the tolerance, inside the joint limits
  NotConverged,   ///< no solution found within the iteration budget (unreachable or too hard)
  Unreachable,    ///< the pose is out of the arm's reach (closed-form solvers know it)
};

/// Settings of the numeric inverse kinematics.
struct IkOptions {
  double positionTolerance = 1e-6;     ///< largest position error accepted [m]
  double orientationTolerance = 1e-6;  ///< largest orientation error accepted [rad]
  bool positionOnly = false;           ///< ignore the orientation
  int maxIterations = 200;             ///< iterations per attempt
  int maxAttempts = 20;                ///< the seed first, then random restarts within the limits
  std::uint64_t randomSeed = 1;        ///< seed of the restarts (deterministic)
};

/// Solves \f$FK(q) = T\f$ by damped least squares (Levenberg-Marquardt) on the geometric
/// Jacobian, keeping every joint inside its limits, starting from `seed` and then from random
/// configurations within the limits.
/// @param[in]  model    the manipulator
/// @param[out] data     scratch
/// @param[in]  target   the end-effector pose wanted, in the world [m]
/// @param[in]  seed     first guess (n x 1) [rad], e.g. the current joint positions
/// @param[out] q        the solution (n x 1) [rad] (the best attempt if not solved)
/// @param[in]  options  tolerances and budget
/// @return Solved or NotConverged
/// Real-time safe: yes (no allocation), but its run time depends on the pose.
IkStatus inverseKinematics(const ManipulatorModel& model, ManipulatorData& data, const Transform& target,
                           const JointVector& seed, JointVector& q, const IkOptions& options = IkOptions());

}  // namespace rp
