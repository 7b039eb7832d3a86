// Transformation functions of the math library (rp/math/Transform.hpp).
#include "rp/math/Transform.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <numbers>

namespace rp {

namespace {

Transform fromRotation(const Eigen::Matrix3d& R) {
  Transform t = Transform::unit();
  t.topLeftCorner<3, 3>() = R;
  return t;
}

// Rotations within this distance of a gimbal-lock pose are treated as exactly singular.
constexpr double kSingularTolerance = 1e-12;

}  // namespace

Transform translation(double x, double y, double z) {
  Transform t = Transform::unit();
  t(0, 3) = x;
  t(1, 3) = y;
  t(2, 3) = z;
  return t;
}

Transform translation(const Vector<3>& p) { return translation(p(0), p(1), p(2)); }

Transform xRotation(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Transform t = Transform::unit();
  t(1, 1) = c;
  t(1, 2) = -s;
  t(2, 1) = s;
  t(2, 2) = c;
  return t;
}

Transform yRotation(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Transform t = Transform::unit();
  t(0, 0) = c;
  t(0, 2) = s;
  t(2, 0) = -s;
  t(2, 2) = c;
  return t;
}

Transform zRotation(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Transform t = Transform::unit();
  t(0, 0) = c;
  t(0, 1) = -s;
  t(1, 0) = s;
  t(1, 1) = c;
  return t;
}

Transform rotation(const Vector<3>& axis, double angle) {
  const double n = axis.norm();
  if (!(n > 0) || !std::isfinite(n)) {
    throw MathException("rotation: the axis must have a finite, non-zero length");
  }
  return fromRotation(Eigen::AngleAxisd(angle, axis / n).toRotationMatrix());
}

Transform eulerToTransform(double phi, double theta, double psi) {
  return Transform(zRotation(phi) * yRotation(theta) * zRotation(psi));
}

Vector<3> transformToEuler(const Transform& t) {
  // R = Rz(phi) Ry(theta) Rz(psi): R(2,2) = cos(theta), R(0,2) = cos(phi) sin(theta),
  // R(1,2) = sin(phi) sin(theta), R(2,0) = -sin(theta) cos(psi), R(2,1) = sin(theta) sin(psi).
  const double sinTheta = std::hypot(t(0, 2), t(1, 2));
  Vector<3> e;
  if (sinTheta > kSingularTolerance) {
    e(0) = std::atan2(t(1, 2), t(0, 2));
    e(1) = std::atan2(sinTheta, t(2, 2));
    e(2) = std::atan2(t(2, 1), -t(2, 0));
  } else if (t(2, 2) > 0) {
    // theta = 0: R = Rz(phi + psi); choose phi = 0.
    e(0) = 0;
    e(1) = 0;
    e(2) = std::atan2(t(1, 0), t(0, 0));
  } else {
    // theta = pi: R = Rz(phi) Ry(pi) Rz(psi), R(0,0) = -cos(psi - phi), R(0,1) = sin(psi - phi); phi = 0.
    e(0) = 0;
    e(1) = std::numbers::pi;
    e(2) = std::atan2(t(0, 1), -t(0, 0));
  }
  return e;
}

Transform rpyToTransform(double r, double p, double y) {
  return Transform(zRotation(y) * yRotation(p) * xRotation(r));
}

Vector<3> transformToRPY(const Transform& t) {
  // R = Rz(y) Ry(p) Rx(r): R(2,0) = -sin(p), R(2,1) = cos(p) sin(r), R(2,2) = cos(p) cos(r),
  // R(1,0) = sin(y) cos(p), R(0,0) = cos(y) cos(p).
  const double cosP = std::hypot(t(0, 0), t(1, 0));
  Vector<3> a;
  if (cosP > kSingularTolerance) {
    a(0) = std::atan2(t(2, 1), t(2, 2));
    a(1) = std::atan2(-t(2, 0), cosP);
    a(2) = std::atan2(t(1, 0), t(0, 0));
  } else if (t(2, 0) < 0) {
    // p = +pi/2: R(0,1) = sin(r - y), R(1,1) = cos(r - y); choose r = 0.
    a(0) = 0;
    a(1) = std::numbers::pi / 2;
    a(2) = std::atan2(-t(0, 1), t(1, 1));
  } else {
    // p = -pi/2: R(0,1) = -sin(r + y), R(1,1) = cos(r + y); choose r = 0.
    a(0) = 0;
    a(1) = -std::numbers::pi / 2;
    a(2) = std::atan2(-t(0, 1), t(1, 1));
  }
  return a;
}

Vector<3> getPosition(const Transform& t) { return Vector<3>(t.topRightCorner<3, 1>()); }

Matrix<3, 3> getRotation(const Transform& t) { return Matrix<3, 3>(t.topLeftCorner<3, 3>()); }

Transform makeTransform(const Matrix<3, 3>& R, const Vector<3>& p) {
  Transform t = Transform::unit();
  t.topLeftCorner<3, 3>() = R;
  t.topRightCorner<3, 1>() = p;
  return t;
}

Transform rigidInverse(const Transform& t) {
  Transform inv = Transform::unit();
  inv.topLeftCorner<3, 3>() = t.topLeftCorner<3, 3>().transpose();
  inv.topRightCorner<3, 1>() = -(t.topLeftCorner<3, 3>().transpose() * t.topRightCorner<3, 1>());
  return inv;
}

std::string rigidTransformError(const Transform& pose, double tolerance) {
  if (!pose.allFinite()) return "has an element that is not a finite number";
  if (pose(3, 0) != 0 || pose(3, 1) != 0 || pose(3, 2) != 0 || pose(3, 3) != 1) return "has a last row other than 0 0 0 1";
  const Eigen::Matrix3d R = pose.topLeftCorner<3, 3>();
  const double deviation = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(deviation <= tolerance)) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "has a rotation block that is not orthonormal (R^T R differs from I by %.3g; at most %.3g)", deviation,
                  tolerance);
    return buf;
  }
  if (R.determinant() <= 0) return "has a rotation block that is a reflection (determinant -1), not a rotation";
  return {};
}

}  // namespace rp
