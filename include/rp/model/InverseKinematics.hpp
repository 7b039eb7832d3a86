#pragma once
/// @file
/// Numeric inverse kinematics for any serial chain.

#include <cstdint>
#include <string>

#include "rp/math/Transform.hpp"
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
  int maxAttempts = 100;               ///< the seed first, then random restarts within the limits
  std::uint64_t randomSeed = 1;        ///< seed of the restarts (deterministic)
  /// Time budget [s]: when > 0, random restarts within the joint limits continue until a solution
  /// is found or this much (steady-clock) time is spent, and `maxAttempts` is ignored; 0: no time
  /// limit, `maxAttempts` attempts.
  double timeBudget = 0;
  /// An attempt that has not reduced its error by half within this many iterations is abandoned
  /// for a restart (stagnation, typically against a joint limit); 0: never. The last attempt
  /// (with `maxAttempts` = 1, the only one) always runs its `maxIterations`.
  int stallIterations = 12;
};

/// Solves \f$FK(q) = T\f$ by damped least squares (Levenberg-Marquardt) on the geometric
/// Jacobian, keeping every joint inside its limits, starting from `seed` and then from random
/// configurations within the limits (until `maxAttempts` or the `timeBudget` is spent).
///
/// Each iteration takes the step \f$\Delta q = J^T (J J^T + \lambda I)^{-1} e\f$ (a 6 x 6, or
/// 3 x 3 position-only, fixed-size solve) on the pose error \f$e\f$ (position, rotation vector,
/// world frame), clamps to the limits and keeps it only if it lowers the error; the damping
/// \f$\lambda = \mu (\tfrac12 |e|^2 + 10^{-9})\f$ follows the error (Sugihara 2011) with \f$\mu\f$
/// lowered after a success and raised after a failure. Stagnating attempts restart early.
/// @param[in]  model    the manipulator
/// @param[out] data     scratch
/// @param[in]  target   the end-effector pose wanted, in the world [m]
/// @param[in]  seed     first guess (n x 1) [rad], e.g. the current joint positions
/// @param[out] q        the solution (n x 1) [rad] (the best attempt if not solved)
/// @param[in]  options  tolerances and budget
/// @return Solved or NotConverged
/// @throws std::invalid_argument if `seed` does not have one value per joint, or if `target` is
///         not a rigid transform (see rigidTransformError(); a rotation block of zeros or 2 I
///         used to be "solved")
/// Real-time safe: yes (no allocation), but its run time depends on the pose (bound it with
/// `timeBudget`).
IkStatus inverseKinematics(const ManipulatorModel& model, ManipulatorData& data, const Transform& target,
                           const JointVector& seed, JointVector& q, const IkOptions& options = IkOptions());

}  // namespace rp
