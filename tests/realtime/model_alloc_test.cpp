// Every kinematics and dynamics algorithm runs without heap allocation once model and data exist.
#include <gtest/gtest.h>

#include <array>

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
    sink += puma.inverseKinematicsAll(target, branches) == IkStatus::Solved;
    sink += puma.inverseKinematicsClosest(target, q, out) == IkStatus::Solved;
    sink += inverseKinematics(wam, wd, wamTarget, wq, wout) == IkStatus::Solved;
  }
  EXPECT_EQ(guard.count(), 0u);
  EXPECT_TRUE(std::isfinite(sink));
}

}  // namespace
}  // namespace rp
