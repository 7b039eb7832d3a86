// Modified (Craig) DH: a modified-DH description of a standard-DH robot, derived by hand
// (ModifiedDh.hpp), gives the same end-effector pose, Jacobians, torques, mass matrix and forward
// dynamics as the standard one on seeded random configurations (the algorithms take different
// paths for the two conventions). KDL agreement is in Kdl_test.cpp.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <random>

#include "ModifiedDh.hpp"
#include "PrismaticDhArm.hpp"
#include "rp/model/Dynamics.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/model/UrdfModel.hpp"
#include "rp/model/WAMModel.hpp"

namespace rp {
namespace {

double maxDiff(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return (a - b).cwiseAbs().maxCoeff(); }

void compare(const ManipulatorModel& standard, int trials, bool withTipWrench = true) {
  const std::unique_ptr<ManipulatorModel> modified = test::toModifiedDh(standard);
  ASSERT_EQ(modified->getConvention(), DHConvention::Modified);
  const int n = standard.getNumberOfJoints();
  ManipulatorData a(standard), b(*modified);
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> u(0, 1);
  DynamicsOptions all;
  all.motorInertia = true;
  all.friction = true;
  if (withTipWrench)
    for (int i = 0; i < 6; ++i) all.tipWrench(i) = 0.5 * (i + 1);
  for (int trial = 0; trial < trials; ++trial) {
    JointVector q(n), qd(n), qdd(n), tau(n);
    for (int i = 0; i < n; ++i) {
      q(i) = standard.getPositionMin()(i) + u(rng) * (standard.getPositionMax()(i) - standard.getPositionMin()(i));
      qd(i) = 4 * u(rng) - 2;
      qdd(i) = 6 * u(rng) - 3;
      tau(i) = 20 * u(rng) - 10;
    }
    ASSERT_LT(maxDiff(forwardKinematics(standard, a, q), forwardKinematics(*modified, b, q)), 1e-9) << trial;
    ASSERT_LT(maxDiff(jacobian(standard, a, q), jacobian(*modified, b, q)), 1e-9) << trial;
    ASSERT_LT(maxDiff(jacobian(standard, a, q, ReferenceFrame::EndEffector),
                      jacobian(*modified, b, q, ReferenceFrame::EndEffector)),
              1e-9);
    ASSERT_LT(maxDiff(inverseDynamics(standard, a, q, qd, qdd), inverseDynamics(*modified, b, q, qd, qdd)), 1e-9);
    // The tip wrench acts at link frame n, which is the same frame in both conventions when the
    // last link has a = alpha = 0 (the Puma's and the WAM's).
    ASSERT_LT(maxDiff(inverseDynamics(standard, a, q, qd, qdd, all), inverseDynamics(*modified, b, q, qd, qdd, all)),
              1e-9);
    JointVector g1(n), g2(n), c1(n), c2(n);
    gravityTorque(standard, a, q, g1);
    gravityTorque(*modified, b, q, g2);
    ASSERT_LT(maxDiff(g1, g2), 1e-9);
    coriolisTorque(standard, a, q, qd, c1);
    coriolisTorque(*modified, b, q, qd, c2);
    ASSERT_LT(maxDiff(c1, c2), 1e-9);
    ASSERT_LT(maxDiff(massMatrix(standard, a, q, true), massMatrix(*modified, b, q, true)), 1e-9);
    // Accelerations of the light wrist links reach thousands of rad/s^2: relative agreement.
    const JointVector qdd1 = forwardDynamics(standard, a, q, qd, tau, all);
    const JointVector qdd2 = forwardDynamics(*modified, b, q, qd, tau, all);
    ASSERT_LT(maxDiff(qdd1, qdd2), 1e-11 * (1 + qdd1.cwiseAbs().maxCoeff())) << qdd1.transpose();
    const JointVector qdd3 = forwardDynamicsArticulatedBody(*modified, b, q, qd, tau, all);
    ASSERT_LT(maxDiff(qdd1, qdd3), 1e-11 * (1 + qdd1.cwiseAbs().maxCoeff())) << qdd1.transpose();
  }
}

TEST(ModifiedDh, Puma560SameAsStandard) { compare(Puma560Model(), 1000); }

TEST(ModifiedDh, Wam7SameAsStandard) { compare(WAM7Model(), 1000); }

TEST(ModifiedDh, PrismaticArmSameAsStandard) {
  const std::unique_ptr<ManipulatorModel> arm = test::prismaticDhArm();
  // Its last DH link has a non-zero a or alpha, so link frame n (where a tip wrench acts) differs
  // between the conventions: compare without one.
  compare(*arm, 1000, false);
}

TEST(ModifiedDh, PumaModifiedParametersAreCraigs) {
  // The derived parameters: a_{i-1}, alpha_{i-1} of the standard table shifted down one link.
  const Puma560Model puma;
  const std::unique_ptr<ManipulatorModel> m = test::toModifiedDh(puma);
  EXPECT_EQ(m->getLink(0).a, 0.0);
  EXPECT_EQ(m->getLink(0).alpha, 0.0);
  EXPECT_DOUBLE_EQ(m->getLink(1).alpha, puma.getLink(0).alpha);
  EXPECT_DOUBLE_EQ(m->getLink(2).a, 0.4318);
  EXPECT_DOUBLE_EQ(m->getLink(3).a, 0.0203);
  EXPECT_DOUBLE_EQ(m->getLink(2).d, 0.15005);
  EXPECT_DOUBLE_EQ(m->getLink(3).d, 0.4318);
}

// Issue 20: the Placement form reproduces a modified-DH model exactly when given the same fixed
// parts (they run the same code), and the constructor refuses what would make a wrong model.
TEST(ManipulatorModel, PlacementFormIsCheckedAndKeepsNames) {
  const std::unique_ptr<ManipulatorModel> mdh = test::toModifiedDh(Puma560Model());
  std::vector<LinkParameters> links;
  for (int i = 0; i < mdh->getNumberOfJoints(); ++i) {
    LinkParameters l = mdh->getLink(i);
    l.placement = mdh->getPlacement(i);
    l.a = l.alpha = l.d = l.offset = 0;
    l.jointName = "j" + std::to_string(i);
    l.linkName = "body" + std::to_string(i);
    links.push_back(l);
  }
  const ManipulatorModel placed("placed", links, mdh->getBaseTransform(), mdh->getToolTransform(), mdh->getGravity(),
                                DHConvention::Placement);
  EXPECT_EQ(placed.getJointName(2), "j2");
  EXPECT_EQ(placed.getLinkName(5), "body5");
  EXPECT_EQ(placed.findJoint("j4"), 4);
  EXPECT_EQ(placed.findJoint("joint4"), -1);
  EXPECT_EQ(mdh->getJointName(0), "joint1");
  EXPECT_EQ(mdh->getLinkName(0), "link1");
  ManipulatorData a(*mdh), b(placed);
  JointVector q(6), qd(6), qdd(6);
  for (int i = 0; i < 6; ++i) {
    q(i) = 0.4 * i - 1;
    qd(i) = 0.3 - 0.1 * i;
    qdd(i) = 0.2 * i;
  }
  EXPECT_EQ(forwardKinematics(*mdh, a, q), forwardKinematics(placed, b, q));
  EXPECT_EQ(inverseDynamics(*mdh, a, q, qd, qdd), inverseDynamics(placed, b, q, qd, qdd));

  auto refused = [&](std::vector<LinkParameters> l, DHConvention c) -> std::string {
    try {
      ManipulatorModel("bad", std::move(l), Transform::unit(), Transform::unit(), ManipulatorModel::standardGravity(), c);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no error";
  };
  std::vector<LinkParameters> bad = links;
  bad[1].placement(0, 0) = 2;  // not a rotation
  EXPECT_EQ(refused(bad, DHConvention::Placement).rfind("ManipulatorModel 'bad' joint 2 ('j1'): the placement is not a rigid transform", 0), 0u);
  bad = links;
  bad[2].a = 0.1;
  EXPECT_EQ(refused(bad, DHConvention::Placement),
            "ManipulatorModel 'bad' joint 3 ('j2'): DH parameters (a, alpha, d, offset) given with DHConvention::Placement");
  EXPECT_EQ(refused(links, DHConvention::Modified),
            "ManipulatorModel 'bad' joint 1 ('j0'): a placement given with DH parameters (use DHConvention::Placement)");
  bad = links;
  bad[3].inertia(1, 1) = std::nan("");
  EXPECT_EQ(refused(bad, DHConvention::Placement), "ManipulatorModel 'bad' joint 4 ('j3'): a parameter is not a finite number");
  bad = links;
  bad[4].placement(1, 3) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(refused(bad, DHConvention::Placement), "ManipulatorModel 'bad' joint 5 ('j4'): a parameter is not a finite number");
  bad = links;
  bad[5].jointName = "j0";
  EXPECT_EQ(refused(bad, DHConvention::Placement), "ManipulatorModel 'bad' joint 6 ('j0'): a second joint named 'j0'");
  bad = links;
  bad[5].linkName = "body1";
  EXPECT_EQ(refused(bad, DHConvention::Placement), "ManipulatorModel 'bad' joint 6 ('j5'): a second link named 'body1'");
}

// Placements turned by multiples of 90 degrees (every signed permutation with determinant +1, as
// rpy = (pi/2, 0, 0) gives them with cos(pi/2) = 6e-17) take the kinematics' short path; a
// placement turned by 4e-8 rad does not. Both agree with the product of the 4 x 4 matrices
// P_i Rz(q_i) or P_i Tz(q_i) to rounding.
TEST(ManipulatorModel, QuarterTurnPlacementsAreSignedPermutationsAndComputeAsTheProduct) {
  std::vector<Eigen::Matrix3d> rotations;
  for (int x = 0; x < 3; ++x)
    for (int y = 0; y < 3; ++y) {
      if (y == x) continue;
      for (double sx : {-1.0, 1.0})
        for (double sy : {-1.0, 1.0}) {
          Eigen::Matrix3d R = Eigen::Matrix3d::Zero();
          R(x, 0) = sx;
          R(y, 1) = sy;
          R.col(2) = Eigen::Vector3d(R.col(0)).cross(Eigen::Vector3d(R.col(1)));
          rotations.push_back(R);
        }
    }
  ASSERT_EQ(rotations.size(), 24u);
  // rpy = (pi/2, 0, 0) as a URDF loader computes it, and a turn of 4e-8 rad about z.
  rotations.push_back(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix());
  rotations.push_back(Eigen::AngleAxisd(4e-8, Eigen::Vector3d::UnitZ()).toRotationMatrix());
  ASSERT_NE(rotations[24](1, 1), 0.0) << "cos(pi/2) in double is not 0";
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (std::size_t first : {std::size_t{0}, std::size_t{13}}) {  // two arms of 13 links (a model has at most 16)
    std::vector<LinkParameters> links;
    for (std::size_t k = first; k < first + 13; ++k) {
      LinkParameters l;
      l.placement.topLeftCorner<3, 3>() = rotations[k];
      l.placement.topRightCorner<3, 1>() = Eigen::Vector3d(u(rng), u(rng), u(rng));
      if (k % 3 == 1) {
        l.type = JointType::Prismatic;
        l.positionMin = -1;
        l.positionMax = 1;
      }
      links.push_back(l);
    }
    const ManipulatorModel model("turns", links, Transform::unit(), Transform::unit(), ManipulatorModel::standardGravity(),
                                 DHConvention::Placement);
    for (int i = 0; i < 13; ++i) {
      const std::size_t k = first + static_cast<std::size_t>(i);
      const PlacementAxes& ax = model.getPlacementAxes(i);
      if (k == 25) {
        EXPECT_FALSE(ax.permutation);
        continue;
      }
      ASSERT_TRUE(ax.permutation) << k;
      for (int c = 0; c < 3; ++c) EXPECT_EQ(std::round(rotations[k](ax.axis[c], c)), ax.sign[c]) << k;
      if (k == 24) {
        EXPECT_EQ(ax.axis, (std::array<int, 3>{0, 2, 1}));
        EXPECT_EQ(ax.sign, (std::array<double, 3>{1, 1, -1}));
      }
    }
    ManipulatorData data(model);
    const int n = model.getNumberOfJoints();
    for (int trial = 0; trial < 50; ++trial) {
      JointVector q(n);
      for (int i = 0; i < n; ++i) q(i) = 3 * u(rng);
      Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
      forwardKinematics(model, data, q);
      for (int i = 0; i < n; ++i) {
        Eigen::Matrix4d J = Eigen::Matrix4d::Identity();
        if (model.isPrismatic(i)) {
          J(2, 3) = q(i);
        } else {
          J.topLeftCorner<3, 3>() = Eigen::AngleAxisd(q(i), Eigen::Vector3d::UnitZ()).toRotationMatrix();
        }
        T = T * Eigen::Matrix4d(links[static_cast<std::size_t>(i)].placement) * J;
        ASSERT_LT(maxDiff(data.linkTransforms[static_cast<std::size_t>(i)], T), 1e-13)
            << "link " << first + i << ", trial " << trial;
      }
    }
  }
}

}  // namespace
}  // namespace rp
