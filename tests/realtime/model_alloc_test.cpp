// Every kinematics and dynamics algorithm runs without heap allocation once model and data exist.
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <vector>

#include "AllocationCounter.hpp"
#include "rp/model/Model.hpp"

namespace rp {
namespace {

TEST(ModelRealtime, AlgorithmsDoNotAllocate) {
  Puma560Model puma;
  WAM7Model wam;
  ManipulatorData pd(puma), wd(wam);
  JointVector q = puma.getHomePosition(), qd(6), qdd(6), tau(6), out(6);
  qd.setConstant(0.3);
  qdd.setConstant(-0.2);
  JointVector wq = wam.getHomePosition(), wout(7);
  Vector<6> wrench;
  wrench(2) = 5;
  DynamicsOptions all;
  all.motorInertia = true;
  all.friction = true;
  DynamicsOptions withWrench = all;
  withWrench.tipWrench << 2, -1, 3, 0.2, 0.1, -0.3;
  std::array<Puma560IkSolution, 8> branches;
  const Transform target = forwardKinematics(puma, pd, q);
  const Transform wamTarget = forwardKinematics(wam, wd, wq);
  double sink = 0;
  test::AllocationGuard guard;
  for (int i = 0; i < 100; ++i) {
    sink += forwardKinematics(puma, pd, q)(0, 3);
    sink += jacobian(puma, pd, q, ReferenceFrame::EndEffector)(0, 0);
    endEffectorForceToJointTorque(puma, pd, q, wrench, out);
    sink += inverseDynamics(puma, pd, q, qd, qdd, all)(1);
    gravityTorque(puma, pd, q, out);
    coriolisTorque(puma, pd, q, qd, out);
    frictionTorque(puma, qd, out);
    sink += massMatrix(puma, pd, q, true)(0, 0);
    sink += forwardDynamics(puma, pd, q, qd, tau, all)(2);
    sink += forwardDynamics(wam, wd, wq, JointVector(7), JointVector(7))(3);
    // The world-frame paths with every option (motor inertia, friction, a tip wrench) on the WAM 7.
    gravityTorque(wam, wd, wq, wout);
    sink += forwardDynamics(wam, wd, wq, wout, wout, withWrench)(4);
    sink += forwardDynamicsArticulatedBody(puma, pd, q, qd, tau, all)(2);
    sink += puma.inverseKinematicsAll(target, branches) == IkStatus::Solved;
    sink += puma.inverseKinematicsClosest(target, q, out) == IkStatus::Solved;
    sink += inverseKinematics(wam, wd, wamTarget, wq, wout) == IkStatus::Solved;
    sink += puma.branchOf(q).rightShoulder;
  }
  EXPECT_EQ(guard.count(), 0u);
  EXPECT_TRUE(std::isfinite(sink));
}

TEST(ModelRealtime, PrismaticAndModifiedDhAlgorithmsDoNotAllocate) {
  // A five-joint arm in modified DH with two prismatic joints (a lift and a telescope).
  std::vector<LinkParameters> links(5);
  for (std::size_t i = 0; i < links.size(); ++i) {
    LinkParameters& l = links[i];
    l.mass = 2.0 - 0.3 * static_cast<double>(i);
    l.com(0) = 0.05;
    l.com(2) = 0.02;
    l.inertia = Matrix<3, 3>::Identity() * 0.01;
    l.motorInertia = 1e-4;
    l.gearRatio = 50;
    l.viscousFriction = 1e-3;
  }
  links[1].type = JointType::Prismatic;
  links[1].positionMin = -0.2;
  links[1].positionMax = 0.3;
  links[2].alpha = 1.5707963267948966;
  links[2].a = 0.1;
  links[3].type = JointType::Prismatic;
  links[3].alpha = -1.5707963267948966;
  links[3].positionMin = 0;
  links[3].positionMax = 0.4;
  links[4].d = 0.1;
  const ManipulatorModel arm("lift_arm", links, Transform::unit(), Transform::unit(), ManipulatorModel::standardGravity(),
                             DHConvention::Modified);
  ManipulatorData d(arm);
  JointVector q(5), qd(5), qdd(5), out(5);
  q << 0.3, 0.1, -0.4, 0.2, 0.7;
  qd.setConstant(0.2);
  qdd.setConstant(-0.1);
  Vector<6> wrench;
  wrench(0) = 2;
  DynamicsOptions all;
  all.motorInertia = true;
  all.friction = true;
  JointVector q2 = q;
  q2(1) = 0.15;
  q2(3) = 0.25;
  const Transform target = forwardKinematics(arm, d, q2);
  IkOptions position;
  position.positionOnly = true;
  position.timeBudget = 1e-3;
  double sink = 0;
  test::AllocationGuard guard;
  for (int i = 0; i < 100; ++i) {
    sink += forwardKinematics(arm, d, q)(0, 3);
    sink += jacobian(arm, d, q, ReferenceFrame::EndEffector)(0, 1);
    endEffectorForceToJointTorque(arm, d, q, wrench, out);
    sink += inverseDynamics(arm, d, q, qd, qdd, all)(1);
    gravityTorque(arm, d, q, out);
    coriolisTorque(arm, d, q, qd, out);
    sink += massMatrix(arm, d, q, true)(1, 1);
    sink += forwardDynamics(arm, d, q, qd, out, all)(3);
    sink += forwardDynamicsArticulatedBody(arm, d, q, qd, out, all)(3);
    sink += inverseKinematics(arm, d, target, q, out, position) == IkStatus::Solved;
  }
  EXPECT_EQ(guard.count(), 0u);
  EXPECT_TRUE(std::isfinite(sink));
}

// Issue 20: an arm loaded from URDF (the Placement form) runs every algorithm without allocating.
// Every algorithm on a URDF arm, `count` times, counting allocations.
void expectUrdfArmDoesNotAllocate(const std::string& file, const std::string& tip) {
  SCOPED_TRACE(file);
  UrdfOptions options;
  options.tip = tip;
  options.requireDynamics = true;
  const std::unique_ptr<ManipulatorModel> arm = loadUrdf(RP_TEST_MODEL_DATA + "/" + file, options);
  const int n = arm->getNumberOfJoints();
  ManipulatorData d(*arm);
  JointVector q(n), qd(n), qdd(n), out(n);
  for (int i = 0; i < n; ++i) {
    q(i) = 0.2 * i - 0.5;
    qd(i) = 0.1 * i;
    qdd(i) = -0.1;
  }
  Vector<6> wrench;
  wrench(1) = 3;
  DynamicsOptions all;
  all.motorInertia = true;
  all.friction = true;
  const Transform target = forwardKinematics(*arm, d, JointVector::Constant(n, 0.1));
  double sink = 0;
  test::AllocationGuard guard;
  for (int i = 0; i < 100; ++i) {
    sink += forwardKinematics(*arm, d, q)(0, 3);
    sink += jacobian(*arm, d, q, ReferenceFrame::EndEffector)(0, 1);
    endEffectorForceToJointTorque(*arm, d, q, wrench, out);
    sink += inverseDynamics(*arm, d, q, qd, qdd, all)(1);
    gravityTorque(*arm, d, q, out);
    coriolisTorque(*arm, d, q, qd, out);
    sink += massMatrix(*arm, d, q, true)(1, 1);
    sink += forwardDynamics(*arm, d, q, qd, out, all)(3);
    sink += forwardDynamicsArticulatedBody(*arm, d, q, qd, out, all)(3);
    sink += inverseKinematics(*arm, d, target, q, out) == IkStatus::Solved;
  }
  EXPECT_EQ(guard.count(), 0u);
  EXPECT_TRUE(std::isfinite(sink));
}

TEST(ModelRealtime, UrdfArmAlgorithmsDoNotAllocate) { expectUrdfArmDoesNotAllocate("noisy_axes_arm.urdf", "tool0"); }

// Issue 20: with mimic joints on the chain the algorithms work on the whole chain and map back,
// in the data's own storage.
TEST(ModelRealtime, MimicArmAlgorithmsDoNotAllocate) {
  expectUrdfArmDoesNotAllocate("mimic_arm.urdf", "tool");
  ASSERT_TRUE(loadUrdf(RP_TEST_MODEL_DATA + "/mimic_arm.urdf")->hasMimicJoints());
}

}  // namespace
}  // namespace rp
