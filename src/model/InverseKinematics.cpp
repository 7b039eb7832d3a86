// Damped least-squares inverse kinematics (rp/model/InverseKinematics.hpp).
#include "rp/model/InverseKinematics.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>

#include "rp/model/Kinematics.hpp"

namespace rp {

namespace {

// Pose error (position, rotation vector) from the current pose to the target, world frame.
Eigen::Matrix<double, 6, 1> poseError(const Transform& current, const Transform& target) {
  Eigen::Matrix<double, 6, 1> e;
  e.head<3>() = target.topRightCorner<3, 1>() - current.topRightCorner<3, 1>();
  const Eigen::Matrix3d dR = target.topLeftCorner<3, 3>() * current.topLeftCorner<3, 3>().transpose();
  const Eigen::AngleAxisd aa(dR);
  e.tail<3>() = aa.axis() * aa.angle();
  return e;
}

bool converged(const Eigen::Matrix<double, 6, 1>& e, const IkOptions& o) {
  return e.head<3>().norm() <= o.positionTolerance && (o.positionOnly || e.tail<3>().norm() <= o.orientationTolerance);
}

}  // namespace

IkStatus inverseKinematics(const ManipulatorModel& model, ManipulatorData& data, const Transform& target,
                           const JointVector& seed, JointVector& q, const IkOptions& options) {
  const int n = model.getNumberOfJoints();
  std::mt19937_64 rng(options.randomSeed);
  JointVector best = seed, trial(n), step(n);
  double bestError = INFINITY;
  for (int attempt = 0; attempt < options.maxAttempts; ++attempt) {
    if (attempt == 0) {
      for (int i = 0; i < n; ++i) trial(i) = std::clamp(seed(i), model.getPositionMin()(i), model.getPositionMax()(i));
    } else {
      for (int i = 0; i < n; ++i) {
        std::uniform_real_distribution<double> d(model.getPositionMin()(i), model.getPositionMax()(i));
        trial(i) = d(rng);
      }
    }
    double lambda = 1e-2;
    Eigen::Matrix<double, 6, 1> e = poseError(forwardKinematics(model, data, trial), target);
    if (options.positionOnly) e.tail<3>().setZero();
    double err = e.norm();
    for (int it = 0; it < options.maxIterations && !converged(e, options); ++it) {
      const Jacobian& J = jacobian(model, data, trial);
      // dq = J^T (J J^T + lambda^2 I)^-1 e  (6 x 6 solve, no allocation)
      Eigen::Matrix<double, 6, 6> A = J * J.transpose();
      if (options.positionOnly) {
        A.bottomRows<3>().setZero();
        A.rightCols<3>().setZero();
        A.bottomRightCorner<3, 3>().setIdentity();
      }
      A.diagonal().array() += lambda * lambda;
      const Eigen::Matrix<double, 6, 1> y = A.ldlt().solve(e);
      step = J.transpose() * y;
      JointVector candidate = trial + step;
      for (int i = 0; i < n; ++i)
        candidate(i) = std::clamp(candidate(i), model.getPositionMin()(i), model.getPositionMax()(i));
      Eigen::Matrix<double, 6, 1> ec = poseError(forwardKinematics(model, data, candidate), target);
      if (options.positionOnly) ec.tail<3>().setZero();
      if (ec.norm() < err) {
        trial = candidate;
        e = ec;
        err = ec.norm();
        lambda = std::max(lambda * 0.5, 1e-6);
      } else {
        lambda = std::min(lambda * 4.0, 1e3);
      }
    }
    if (err < bestError) {
      bestError = err;
      best = trial;
    }
    if (converged(e, options)) {
      q = trial;
      return IkStatus::Solved;
    }
  }
  q = best;
  return IkStatus::NotConverged;
}

}  // namespace rp
