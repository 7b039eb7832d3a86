// Frames and friction as the URDF and MJCF exports write them (ExportFrames.hpp).
#include "ExportFrames.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <cstdio>

namespace rp::internal {

JointFrames jointFrames(const ManipulatorModel& model, int k) {
  const LinkParameters& l = model.getLink(k);
  if (model.getConvention() == DHConvention::Standard) {
    return {Transform(zRotation(l.offset) * translation(0, 0, l.d)), Transform(translation(l.a, 0, 0) * xRotation(l.alpha))};
  }
  // Modified DH and Placement: the fixed part precedes the motion (getPlacement()).
  return {model.getPlacement(k), Transform::unit()};
}

JointFriction jointFriction(const LinkParameters& l) {
  JointFriction f;
  f.positive = std::abs(l.gearRatio) * l.coulombFrictionPositive;
  f.negative = -std::abs(l.gearRatio) * l.coulombFrictionNegative;
  f.symmetric = 0.5 * (f.positive + f.negative);
  return f;
}

PrincipalInertia principalInertia(const Matrix<3, 3>& inertia) {
  const Eigen::Matrix3d I = inertia;
  if (I(0, 1) == 0 && I(0, 2) == 0 && I(1, 2) == 0 && I(1, 0) == 0 && I(2, 0) == 0 && I(2, 1) == 0) {
    return {Eigen::Matrix3d::Identity(), I.diagonal()};
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(I);
  Eigen::Matrix3d axes = eig.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) = -axes.col(2);
  return {axes, eig.eigenvalues()};
}

std::string exact(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

std::string xmlEscape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string brief(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

std::string correctionLines(const PhysicalModel& physical, const std::string& indent) {
  std::string text;
  for (const ModelCorrection& c : physical.corrections) text += indent + "- " + c.description + "\n";
  return text;
}

}  // namespace rp::internal
