// Tests of the transformation functions: rotations against their textbook element formulas and
// Rodrigues' formula, orthonormality, and Euler/RPY round trips on dense grids with the singular cases.
#include "rp/math/Transform.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace rp {
namespace {

constexpr double kPi = std::numbers::pi;

void expectRigid(const Transform& t, double tol = 1e-14) {
  const Eigen::Matrix3d R = t.topLeftCorner<3, 3>();
  EXPECT_TRUE((R * R.transpose()).isIdentity(tol)) << t;
  EXPECT_NEAR(R.determinant(), 1.0, tol);
  EXPECT_EQ(t(3, 0), 0.0);
  EXPECT_EQ(t(3, 1), 0.0);
  EXPECT_EQ(t(3, 2), 0.0);
  EXPECT_EQ(t(3, 3), 1.0);
}

double maxRotationDifference(const Transform& a, const Transform& b) {
  return (a.topLeftCorner<3, 3>() - b.topLeftCorner<3, 3>()).cwiseAbs().maxCoeff();
}

// Rodrigues' formula written out element by element (an independent reference).
Eigen::Matrix3d rodrigues(Eigen::Vector3d k, double a) {
  k.normalize();
  const double c = std::cos(a), s = std::sin(a), v = 1 - c;
  Eigen::Matrix3d R;
  R << k.x() * k.x() * v + c, k.x() * k.y() * v - k.z() * s, k.x() * k.z() * v + k.y() * s,  //
      k.y() * k.x() * v + k.z() * s, k.y() * k.y() * v + c, k.y() * k.z() * v - k.x() * s,   //
      k.z() * k.x() * v - k.y() * s, k.z() * k.y() * v + k.x() * s, k.z() * k.z() * v + c;
  return R;
}

TEST(Transform, ElementaryRotationsMatchTextbookElements) {
  for (double a = -2 * kPi; a <= 2 * kPi; a += 0.1) {
    const double c = std::cos(a), s = std::sin(a);
    const Transform x = xRotation(a), y = yRotation(a), z = zRotation(a);
    expectRigid(x);
    expectRigid(y);
    expectRigid(z);
    EXPECT_DOUBLE_EQ(x(1, 2), -s);
    EXPECT_DOUBLE_EQ(x(2, 1), s);
    EXPECT_DOUBLE_EQ(y(0, 2), s);
    EXPECT_DOUBLE_EQ(y(2, 0), -s);
    EXPECT_DOUBLE_EQ(z(0, 1), -s);
    EXPECT_DOUBLE_EQ(z(1, 0), s);
    EXPECT_DOUBLE_EQ(z(0, 0), c);
    // A quarter turn about z takes x to y.
  }
  const Vector<3> p = transformPoint(zRotation(kPi / 2), Vector<3>{{1}, {0}, {0}});
  EXPECT_NEAR(p(0), 0.0, 1e-16);
  EXPECT_NEAR(p(1), 1.0, 1e-16);
}

TEST(Transform, RotationAboutArbitraryAxisMatchesRodrigues) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> ang(-kPi, kPi);
  for (int i = 0; i < 1000; ++i) {
    Vector<3> axis{{n(rng)}, {n(rng)}, {n(rng)}};
    const double a = ang(rng);
    const Transform t = rotation(axis, a);
    expectRigid(t);
    const Eigen::Matrix3d R = t.topLeftCorner<3, 3>();
    EXPECT_TRUE(R.isApprox(rodrigues(axis, a), 1e-13));
  }
  EXPECT_TRUE(rotation(Vector<3>{{2}, {0}, {0}}, 0.3).isApprox(xRotation(0.3), 1e-15));
  EXPECT_THROW(rotation(Vector<3>(), 1.0), MathException);
}

TEST(Transform, TranslationAndFigure21Syntax) {
  Transform down = xRotation(M_PI);  // end-effector pointing down
  Transform target = translation(0, 0.5, 0) * down;
  expectRigid(target);
  Vector<4> p = target.getColumn(4);
  EXPECT_EQ(p, (Vector<4>{{0}, {0.5}, {0}, {1}}));
  EXPECT_NEAR(target(2, 2), -1.0, 1e-15) << "the tool z axis points down";
  const Vector<3> moved = transformPoint(translation(Vector<3>{{1}, {2}, {3}}), Vector<3>{{1}, {1}, {1}});
  EXPECT_EQ(moved, (Vector<3>{{2}, {3}, {4}}));
  EXPECT_EQ(getPosition(target), (Vector<3>{{0}, {0.5}, {0}}));
}

TEST(Transform, RigidInverseAgreesWithGeneralInverse) {
  const Transform t = translation(0.3, -1, 2) * rpyToTransform(0.1, -0.7, 2.5);
  EXPECT_TRUE(rigidInverse(t).isApprox(t.inverse(), 1e-14));
  EXPECT_TRUE((t * rigidInverse(t)).isIdentity(1e-14));
  EXPECT_TRUE(makeTransform(getRotation(t), getPosition(t)).isApprox(t, 0.0));
}

TEST(Transform, EulerZYZRoundTripOnDenseGridIncludingSingularities) {
  int count = 0;
  for (double phi = -kPi; phi <= kPi + 1e-9; phi += kPi / 12) {
    for (double theta = 0; theta <= kPi + 1e-9; theta += kPi / 12) {
      for (double psi = -kPi; psi <= kPi + 1e-9; psi += kPi / 12) {
        const Transform t = eulerToTransform(phi, theta, psi);
        expectRigid(t);
        // Against the product of elementary rotations.
        EXPECT_LT(maxRotationDifference(t, Transform(zRotation(phi) * yRotation(theta) * zRotation(psi))), 1e-15);
        const Vector<3> e = transformToEuler(t);
        EXPECT_GE(e(1), 0.0);
        EXPECT_LE(e(1), kPi);
        EXPECT_LT(maxRotationDifference(eulerToTransform(e(0), e(1), e(2)), t), 1e-12)
            << "phi=" << phi << " theta=" << theta << " psi=" << psi;
        ++count;
      }
    }
  }
  EXPECT_EQ(count, 25 * 13 * 25);
  // The documented choice at the singularities: phi = 0.
  Vector<3> e0 = transformToEuler(eulerToTransform(0.4, 0.0, 0.5));
  EXPECT_DOUBLE_EQ(e0(0), 0.0);
  EXPECT_NEAR(e0(2), 0.9, 1e-15);
  Vector<3> epi = transformToEuler(eulerToTransform(0.4, kPi, 0.5));
  EXPECT_DOUBLE_EQ(epi(0), 0.0);
  EXPECT_NEAR(epi(1), kPi, 1e-15);
  EXPECT_NEAR(epi(2), 0.1, 1e-12);
}

TEST(Transform, EulerAnglesInsideTheirRangesComeBackUnchanged) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> a(-kPi + 1e-6, kPi), b(1e-3, kPi - 1e-3);
  for (int i = 0; i < 10000; ++i) {
    const double phi = a(rng), theta = b(rng), psi = a(rng);
    const Vector<3> e = transformToEuler(eulerToTransform(phi, theta, psi));
    EXPECT_NEAR(e(0), phi, 1e-9);
    EXPECT_NEAR(e(1), theta, 1e-9);
    EXPECT_NEAR(e(2), psi, 1e-9);
  }
}

TEST(Transform, RollPitchYawRoundTripOnDenseGridIncludingSingularities) {
  for (double r = -kPi; r <= kPi + 1e-9; r += kPi / 12) {
    for (double p = -kPi / 2; p <= kPi / 2 + 1e-9; p += kPi / 24) {
      for (double y = -kPi; y <= kPi + 1e-9; y += kPi / 12) {
        const Transform t = rpyToTransform(r, p, y);
        expectRigid(t);
        EXPECT_LT(maxRotationDifference(t, Transform(zRotation(y) * yRotation(p) * xRotation(r))), 1e-15);
        const Vector<3> a = transformToRPY(t);
        EXPECT_GE(a(1), -kPi / 2);
        EXPECT_LE(a(1), kPi / 2);
        EXPECT_LT(maxRotationDifference(rpyToTransform(a(0), a(1), a(2)), t), 1e-12)
            << "r=" << r << " p=" << p << " y=" << y;
      }
    }
  }
  // Gimbal lock: roll is reported as zero and the yaw carries the rest.
  const Vector<3> up = transformToRPY(rpyToTransform(0.3, kPi / 2, 0.2));
  EXPECT_DOUBLE_EQ(up(0), 0.0);
  EXPECT_NEAR(up(2), 0.2 - 0.3, 1e-12);
  const Vector<3> down = transformToRPY(rpyToTransform(0.3, -kPi / 2, 0.2));
  EXPECT_DOUBLE_EQ(down(0), 0.0);
  EXPECT_NEAR(down(2), 0.2 + 0.3, 1e-12);
}

TEST(Transform, RandomRotationMatricesSurviveBothConversions) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> n(0, 1);
  for (int i = 0; i < 10000; ++i) {
    Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
    q.normalize();
    Transform t = Transform::unit();
    t.topLeftCorner<3, 3>() = q.toRotationMatrix();
    const Vector<3> e = transformToEuler(t), a = transformToRPY(t);
    EXPECT_LT(maxRotationDifference(eulerToTransform(e(0), e(1), e(2)), t), 1e-12);
    EXPECT_LT(maxRotationDifference(rpyToTransform(a(0), a(1), a(2)), t), 1e-12);
  }
}

}  // namespace
}  // namespace rp
