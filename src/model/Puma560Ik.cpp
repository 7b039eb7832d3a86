// Closed-form inverse kinematics of the Puma 560 (rp/model/Puma560Model.hpp).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "ChainInternal.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/Puma560Model.hpp"

namespace rp {

namespace {

constexpr double kPi = std::numbers::pi;

double wrap(double a) {
  a = std::remainder(a, 2 * kPi);  // (-pi, pi]
  return a <= -kPi ? a + 2 * kPi : a;
}

}  // namespace

const char* Puma560IkSolution::branchName() const {
  static const char* const names[8] = {"left-down-noflip", "left-down-flip", "left-up-noflip", "left-up-flip",
                                        "right-down-noflip", "right-down-flip", "right-up-noflip", "right-up-flip"};
  return names[(rightShoulder ? 4 : 0) + (elbowUp ? 2 : 0) + (wristFlipped ? 1 : 0)];
}

IkStatus Puma560Model::inverseKinematicsAll(const Transform& pose, std::array<Puma560IkSolution, 8>& solutions) const {
  // The wanted pose of link frame 6 in the base frame.
  const Transform T6 = rigidInverse(getBaseTransform()) * pose * rigidInverse(getToolTransform());
  const double d1 = getLink(0).d, a2 = getLink(1).a, d3 = getLink(2).d, a3 = getLink(2).a, d4 = getLink(3).d;
  // The wrist centre (origin of frames 4-6).
  const double px = T6(0, 3), py = T6(1, 3), pz = T6(2, 3) - d1;
  const double r2 = px * px + py * py - d3 * d3;
  if (r2 < 0) return IkStatus::Unreachable;
  const double rho = std::hypot(a3, d4), phi = std::atan2(d4, a3);
  int k = 0;
  for (int shoulder = 0; shoulder < 2; ++shoulder) {
    const double X = shoulder == 1 ? std::sqrt(r2) : -std::sqrt(r2);
    // px + i py = (X - i d3) (cos q1 + i sin q1)
    const double q1 = wrap(std::atan2(py, px) - std::atan2(-d3, X));
    const double Y = pz;
    const double K = (X * X + Y * Y - a2 * a2 - a3 * a3 - d4 * d4) / (2 * a2);
    if (std::abs(K) > rho * (1 + 1e-12)) return IkStatus::Unreachable;
    const double beta = std::acos(std::clamp(K / rho, -1.0, 1.0));
    for (int elbow = 0; elbow < 2; ++elbow) {
      const double q3 = wrap((elbow == 1 ? beta : -beta) - phi);
      const double u = a2 + a3 * std::cos(q3) - d4 * std::sin(q3), v = a3 * std::sin(q3) + d4 * std::cos(q3);
      const double q2 = wrap(std::atan2(Y, X) - std::atan2(v, u));
      // Wrist: R36 = R03^T R06 = Rz(q4) Ry(-q5) Rz(q6).
      JointVector q(6);
      q << q1, q2, q3, 0, 0, 0;
      // R03 = rotation of A1 A2 A3 (frame 3 in the base frame).
      Eigen::Matrix3d R03 = Eigen::Matrix3d::Identity();
      for (int i = 0; i < 3; ++i) {
        Eigen::Matrix<double, 3, 4> A;
        internal::linkMatrix(*this, i, q(i), A);
        R03 = R03 * A.leftCols<3>();
      }
      Transform R36 = Transform::unit();
      R36.topLeftCorner<3, 3>() = R03.transpose() * T6.topLeftCorner<3, 3>();
      const Vector<3> e = transformToEuler(R36);  // (phi, theta, psi), theta in [0, pi]
      for (int flip = 0; flip < 2; ++flip) {
        Puma560IkSolution& s = solutions[static_cast<std::size_t>(k++)];
        s.q = q;
        if (flip == 0) {
          s.q(3) = wrap(e(0));
          s.q(4) = -e(1);
          s.q(5) = wrap(e(2));
        } else {
          s.q(3) = wrap(e(0) + kPi);
          s.q(4) = e(1);
          s.q(5) = wrap(e(2) + kPi);
        }
        s.rightShoulder = shoulder == 1;
        s.elbowUp = elbow == 1;
        s.wristFlipped = flip == 1;
        s.withinLimits = isWithinLimits(s.q);
      }
    }
  }
  return IkStatus::Solved;
}

Puma560IkSolution Puma560Model::branchOf(const JointVector& q) const {
  // The inverse of inverseKinematicsAll()'s choices: X = +-sqrt(r2) picks the shoulder,
  // q3 + phi = +-beta (beta in [0, pi]) the elbow and q5 = -+theta (theta in [0, pi]) the wrist.
  const double a2 = getLink(1).a, a3 = getLink(2).a, d4 = getLink(3).d;
  const double c3 = std::cos(q(2)), s3 = std::sin(q(2));
  const double u = a2 + a3 * c3 - d4 * s3, v = a3 * s3 + d4 * c3;
  Puma560IkSolution s;
  s.q = q;
  s.rightShoulder = u * std::cos(q(1)) - v * std::sin(q(1)) >= 0;
  s.elbowUp = std::sin(q(2) + std::atan2(d4, a3)) >= 0;
  s.wristFlipped = wrap(q(4)) > 0;
  s.withinLimits = isWithinLimits(q);
  return s;
}

IkStatus Puma560Model::inverseKinematicsClosest(const Transform& pose, const JointVector& current,
                                                JointVector& q) const {
  std::array<Puma560IkSolution, 8> all;
  const IkStatus status = inverseKinematicsAll(pose, all);
  if (status != IkStatus::Solved) return status;
  double best = INFINITY;
  for (const Puma560IkSolution& s : all) {
    if (!s.withinLimits) continue;
    double d = 0;
    for (int i = 0; i < 6; ++i) {
      const double diff = wrap(s.q(i) - current(i));
      d += diff * diff;
    }
    if (d < best) {
      best = d;
      q = s.q;
    }
  }
  return std::isfinite(best) ? IkStatus::Solved : IkStatus::NotConverged;
}

}  // namespace rp
