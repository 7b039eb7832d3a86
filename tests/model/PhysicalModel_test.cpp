// physicalModel(): the inertial data the exports write. Non-physical inertias become physical by
// adding inertia only (a rod along the joint axis when that suffices, keeping the moment about the
// axis), massless and point-mass links get the floors, and physical models come back unchanged.
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "rp/model/PhysicalModel.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/model/WAMModel.hpp"

namespace rp {
namespace {

Matrix<3, 3> diagonal(double xx, double yy, double zz) {
  Matrix<3, 3> m;
  m(0, 0) = xx;
  m(1, 1) = yy;
  m(2, 2) = zz;
  return m;
}

double smallestEigenvalue(const Eigen::Matrix3d& m) {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(m).eigenvalues().minCoeff();
}

TEST(PhysicalModel, TriangleInequality) {
  EXPECT_TRUE(isPhysicalInertia(diagonal(1, 1, 1)));
  EXPECT_TRUE(isPhysicalInertia(diagonal(1, 1, 2)));  // a flat disc: on the boundary
  EXPECT_TRUE(isPhysicalInertia(diagonal(0, 0, 0)));  // a point mass
  EXPECT_FALSE(isPhysicalInertia(diagonal(0.066, 0.086, 0.0125)));  // the Puma's link 3
  EXPECT_FALSE(isPhysicalInertia(diagonal(0, 0.35, 0)));            // the Puma's link 1
  EXPECT_FALSE(isPhysicalInertia(diagonal(-1, 1, 1)));
  Matrix<3, 3> asymmetric = diagonal(1, 1, 1);
  asymmetric(0, 1) = 0.1;
  EXPECT_FALSE(isPhysicalInertia(asymmetric));
  EXPECT_FALSE(isPhysicalInertia(diagonal(1, std::nan(""), 1)));
  // A rotated tensor is judged by its principal moments.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  EXPECT_TRUE(isPhysicalInertia(Matrix<3, 3>(R * Eigen::Vector3d(1, 2, 2.9).asDiagonal() * R.transpose())));
  EXPECT_FALSE(isPhysicalInertia(Matrix<3, 3>(R * Eigen::Vector3d(1, 2, 3.1).asDiagonal() * R.transpose())));
}

// The Puma: link 1 (0, 0.35, 0) and no mass, link 3 (0.066, 0.086, 0.0125). Both rods lie along
// the joint axis, which is y of link frames 1 and 3 (alpha = +-pi/2), so Iyy is kept.
TEST(PhysicalModel, PumaLinks1And3) {
  const Puma560Model puma;
  const PhysicalModel p = physicalModel(puma);
  ASSERT_EQ(p.corrections.size(), 3u);
  EXPECT_EQ(p.corrections[0].link, 0);
  EXPECT_EQ(p.corrections[1].link, 0);
  EXPECT_EQ(p.corrections[2].link, 2);
  EXPECT_NE(p.corrections[2].description.find("(0.066, 0.086, 0.0125)"), std::string::npos) << p.corrections[2].description;
  EXPECT_NE(p.corrections[2].description.find("(0.06975, 0.086, 0.01625)"), std::string::npos)
      << p.corrections[2].description;
  const LinkParameters& l1 = p.model.getLink(0);
  const LinkParameters& l3 = p.model.getLink(2);
  const double margin1 = kExportInertiaMargin * 0.35, margin3 = kExportInertiaMargin * (0.066 + 0.086 + 0.0125);
  EXPECT_NEAR(l1.inertia(1, 1), 0.35, 1e-15);
  EXPECT_NEAR(l1.inertia(0, 0), 0.175 + margin1, 1e-15);
  EXPECT_NEAR(l1.inertia(2, 2), 0.175 + margin1, 1e-15);
  EXPECT_EQ(l1.inertia(0, 1), 0);
  EXPECT_EQ(l1.inertia(1, 2), 0);
  EXPECT_DOUBLE_EQ(l1.mass, kExportMassFloor * 23.45);
  EXPECT_NEAR(l3.inertia(1, 1), 0.086, 1e-15);
  EXPECT_NEAR(l3.inertia(0, 0), 0.06975 + margin3, 1e-15);
  EXPECT_NEAR(l3.inertia(2, 2), 0.01625 + margin3, 1e-15);
  EXPECT_EQ(l3.mass, 4.8);
  for (int k = 0; k < 6; ++k) {
    EXPECT_TRUE(isPhysicalInertia(p.model.getLink(k).inertia)) << k;
    if (k != 0 && k != 2) {
      EXPECT_EQ(Eigen::Matrix3d(p.model.getLink(k).inertia), Eigen::Matrix3d(puma.getLink(k).inertia)) << k;
      EXPECT_EQ(p.model.getLink(k).mass, puma.getLink(k).mass) << k;
    }
    EXPECT_EQ(p.model.getArmatureInertia()(k), puma.getArmatureInertia()(k));
    EXPECT_EQ(p.model.getLink(k).coulombFrictionNegative, puma.getLink(k).coulombFrictionNegative);
  }
}

TEST(PhysicalModel, PhysicalModelsComeBackUnchanged) {
  for (const ManipulatorModel& model : {static_cast<const ManipulatorModel&>(WAM7Model()),
                                        static_cast<const ManipulatorModel&>(WAM4Model())}) {
    const PhysicalModel p = physicalModel(model);
    EXPECT_TRUE(p.corrections.empty()) << p.corrections.front().description;
    for (int k = 0; k < model.getNumberOfJoints(); ++k) {
      EXPECT_EQ(Eigen::Matrix3d(p.model.getLink(k).inertia), Eigen::Matrix3d(model.getLink(k).inertia));
      EXPECT_EQ(p.model.getLink(k).mass, model.getLink(k).mass);
      EXPECT_EQ(Eigen::Vector3d(p.model.getLink(k).com), Eigen::Vector3d(model.getLink(k).com));
    }
  }
}

// Random non-physical tensors in random orientations, on links with random twists: the result is
// physical, only inertia was added (the change is positive semi-definite), and when the rod was
// used the moment about the joint axis is the published one.
TEST(PhysicalModel, RandomTensorsBecomePhysicalByAddingInertia) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(0, 1);
  int rods = 0, others = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Eigen::Matrix3d Q =
        Eigen::AngleAxisd(2 * M_PI * u(rng), Eigen::Vector3d(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5).normalized())
            .toRotationMatrix();
    const Eigen::Vector3d moments(u(rng), u(rng), 3 * u(rng) - 0.5);
    LinkParameters l;
    l.mass = 1;
    l.alpha = 2 * M_PI * u(rng);
    l.inertia = Matrix<3, 3>(Q * moments.asDiagonal() * Q.transpose());
    if (isPhysicalInertia(l.inertia)) continue;
    const ManipulatorModel model("random", {l});
    const PhysicalModel p = physicalModel(model);
    ASSERT_FALSE(p.corrections.empty());
    const Eigen::Matrix3d before = l.inertia, after = p.model.getLink(0).inertia;
    ASSERT_TRUE(isPhysicalInertia(after)) << after;
    EXPECT_GE(smallestEigenvalue(after - before), -1e-12) << "inertia was removed";
    // The nearest: no physical tensor has a second moment of mass closer to the published one's.
    const auto sigma = [](const Eigen::Matrix3d& I) { return Eigen::Matrix3d(0.5 * I.trace() * Eigen::Matrix3d::Identity() - I); };
    const double distance = (sigma(after) - sigma(before)).norm();
    for (int k = 0; k < 200; ++k) {
      const Eigen::Matrix3d Qk =
          Eigen::AngleAxisd(2 * M_PI * u(rng), Eigen::Vector3d(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5).normalized())
              .toRotationMatrix();
      const Eigen::Vector3d s(u(rng), u(rng), u(rng));  // second moments >= 0: a physical body
      const Eigen::Matrix3d other = s.sum() * Eigen::Matrix3d::Identity() - Qk * s.asDiagonal() * Qk.transpose();
      ASSERT_TRUE(isPhysicalInertia(other));
      EXPECT_GE((sigma(other) - sigma(before)).norm(), distance - 1e-9);
    }
    const std::string& how = p.corrections.front().description;
    if (how.find("rod") != std::string::npos) {
      ++rods;
      // The rod's axis is the eigenvector of the negative second moment; the moment about it is kept.
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(sigma(before));
      const Eigen::Vector3d v = eig.eigenvectors().col(0);
      EXPECT_NEAR(v.dot(after * v), v.dot(before * v), 1e-12);
    } else {
      ++others;
    }
  }
  std::printf("%d corrected by a rod, %d by adding inertia about every axis\n", rods, others);
  EXPECT_GT(rods, 100);
  EXPECT_GT(others, 100);
}

TEST(PhysicalModel, FloorsForMasslessAndPointMassLinks) {
  LinkParameters heavy, massless, point;
  heavy.mass = 2;
  heavy.a = 0.5;
  heavy.inertia = diagonal(0.1, 0.1, 0.1);
  point.mass = 1;
  point.d = 0.5;
  const ManipulatorModel model("floors", {heavy, massless, point});
  const PhysicalModel p = physicalModel(model);
  ASSERT_EQ(p.corrections.size(), 3u);
  const double floor = kExportInertiaFloor * 3 * 1.0 * 1.0;  // m L^2 with L = 0.5 + 0.5
  EXPECT_EQ(p.model.getLink(1).mass, kExportMassFloor * 3);
  EXPECT_DOUBLE_EQ(p.model.getLink(1).inertia(0, 0), floor);
  EXPECT_DOUBLE_EQ(p.model.getLink(2).inertia(2, 2), floor);
  EXPECT_EQ(p.model.getLink(2).mass, 1);
  EXPECT_EQ(Eigen::Matrix3d(p.model.getLink(0).inertia), Eigen::Matrix3d(heavy.inertia));
  // A model without any mass (kinematics only) is left alone.
  const ManipulatorModel kinematic("kinematic", {massless, massless});
  EXPECT_TRUE(physicalModel(kinematic).corrections.empty());
}

TEST(PhysicalModel, NonFiniteDataIsRefused) {
  // A model cannot even be made with such data (the ManipulatorModel constructor refuses it), so
  // no export ever sees it.
  LinkParameters l;
  l.mass = 1;
  l.inertia = diagonal(1, std::numeric_limits<double>::infinity(), 1);
  try {
    physicalModel(ManipulatorModel("bad", {LinkParameters(), l}));
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'bad' joint 2: a parameter is not a finite number"), std::string::npos) << e.what();
  }
  l.inertia = diagonal(1, 1, 1);
  l.com(1) = std::nan("");
  EXPECT_THROW(physicalModel(ManipulatorModel("bad", {l})), std::invalid_argument);
}

}  // namespace
}  // namespace rp
