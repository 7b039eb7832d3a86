// Damped least-squares inverse kinematics (rp/model/InverseKinematics.hpp).
#include "rp/model/InverseKinematics.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>

#include "ChainInternal.hpp"
#include "rp/model/Kinematics.hpp"

namespace rp {

namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;

// Pose error (position, rotation vector) from the current pose to the target, world frame.
void poseError(const Transform& current, const Transform& target, bool positionOnly, Vector6& e) {
  e.head<3>() = target.topRightCorner<3, 1>() - current.topRightCorner<3, 1>();
  if (positionOnly) {
    e.tail<3>().setZero();
    return;
  }
  const Eigen::Matrix3d dR = target.topLeftCorner<3, 3>() * current.topLeftCorner<3, 3>().transpose();
  const Eigen::AngleAxisd aa(dR);
  e.tail<3>() = aa.axis() * aa.angle();
}

bool converged(const Vector6& e, const IkOptions& o) {
  return e.head<3>().squaredNorm() <= o.positionTolerance * o.positionTolerance &&
         (o.positionOnly || e.tail<3>().squaredNorm() <= o.orientationTolerance * o.orientationTolerance);
}

// The damped step dq = J^T (J J^T + lambda I)^-1 e into `step`.
void dampedStep(const Jacobian& J, const Vector6& e, double lambda, bool positionOnly, JointVector& step) {
  if (positionOnly) {
    const auto Jp = J.topRows<3>();
    Eigen::Matrix3d A;
    A.noalias() = Jp * Jp.transpose();
    A.diagonal().array() += lambda;
    const Eigen::Vector3d y = A.llt().solve(e.head<3>());
    step.noalias() = Jp.transpose() * y;
  } else {
    Eigen::Matrix<double, 6, 6> A;
    A.noalias() = J * J.transpose();
    A.diagonal().array() += lambda;
    const Vector6 y = A.llt().solve(e);
    step.noalias() = J.transpose() * y;
  }
}

}  // namespace

IkStatus inverseKinematics(const ManipulatorModel& model, ManipulatorData& data, const Transform& target,
                           const JointVector& seed, JointVector& q, const IkOptions& options) {
  const int n = model.getNumberOfJoints();
  if (seed.size() != n) {
    throw std::invalid_argument("inverseKinematics: the seed has " + std::to_string(seed.size()) + " values for a " +
                                std::to_string(n) + "-joint manipulator");
  }
  if (const std::string problem = rigidTransformError(target); !problem.empty())
    throw std::invalid_argument("inverseKinematics: the target pose " + problem);
  using Clock = std::chrono::steady_clock;
  const bool timed = options.timeBudget > 0;
  const Clock::time_point deadline =
      timed ? Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options.timeBudget))
            : Clock::time_point();
  const JointVector& qmin = model.getPositionMin();
  const JointVector& qmax = model.getPositionMax();
  std::mt19937_64 rng(options.randomSeed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  JointVector best = seed, trial(n), candidate(n), step(n);
  double bestError = INFINITY;
  Vector6 e, ec;
  for (int attempt = 0; timed || attempt < options.maxAttempts; ++attempt) {
    if (attempt == 0) {
      for (int i = 0; i < n; ++i) trial(i) = std::clamp(seed(i), qmin(i), qmax(i));
    } else {
      if (timed && Clock::now() >= deadline) break;
      for (int i = 0; i < n; ++i) trial(i) = qmin(i) + unit(rng) * (qmax(i) - qmin(i));
    }
    poseError(forwardKinematics(model, data, trial), target, options.positionOnly, e);
    double err = e.squaredNorm();
    bool solved = converged(e, options);
    if (!solved) internal::jacobianFromKinematics(model, data);
    double mu = 1.0;
    // Abandoning a stagnating attempt pays only if another attempt follows.
    const bool mayRestart = options.stallIterations > 0 && (timed || attempt + 1 < options.maxAttempts);
    double checkpointError = err;
    int checkpoint = 0;
    for (int it = 0; it < options.maxIterations && !solved; ++it) {
      dampedStep(data.jacobian, e, mu * (0.5 * err + 1e-9), options.positionOnly, step);
      for (int i = 0; i < n; ++i) candidate(i) = std::clamp(trial(i) + step(i), qmin(i), qmax(i));
      poseError(forwardKinematics(model, data, candidate), target, options.positionOnly, ec);
      const double errc = ec.squaredNorm();
      if (errc < err) {
        trial = candidate;
        e = ec;
        err = errc;
        mu = std::max(mu * 0.5, 1e-3);
        solved = converged(e, options);
        if (!solved) internal::jacobianFromKinematics(model, data);
      } else {
        mu = std::min(mu * 4.0, 1e6);
      }
      // Stagnation: the (squared) error must fall to a quarter within stallIterations.
      if (mayRestart && it - checkpoint >= options.stallIterations) {
        if (err > 0.25 * checkpointError) break;
        checkpoint = it;
        checkpointError = err;
      }
      if (timed && (it & 15) == 15 && Clock::now() >= deadline) break;
    }
    if (err < bestError) {
      bestError = err;
      best = trial;
    }
    if (solved) {
      q = trial;
      return IkStatus::Solved;
    }
  }
  q = best;
  return IkStatus::NotConverged;
}

}  // namespace rp
