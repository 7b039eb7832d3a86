// Modified (Craig) DH: a modified-DH description of a standard-DH robot, derived by hand
// (ModifiedDh.hpp), gives the same end-effector pose, Jacobians, torques, mass matrix and forward
// dynamics as the standard one on seeded random configurations (the algorithms take different
// paths for the two conventions). KDL agreement is in Kdl_test.cpp.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace rp
