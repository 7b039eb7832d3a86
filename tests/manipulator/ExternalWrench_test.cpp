// External wrenches at a point on any link in simulation: the joint torques against a
// finite-difference virtual-work reference (revolute and prismatic joints, standard and modified
// DH), the first step's accelerations, a pushed arm, and
// wrenches set from another thread while the servo loop runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <random>
#include <thread>

#include "ModifiedDh.hpp"
#include "PrismaticDhArm.hpp"
#include "SimulatedArmTest.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

using test::simClock;

// Pose of link `link`'s frame (1..n) at q.
Transform linkPose(const ManipulatorModel& model, const JointVector& q, int link) {
  ManipulatorData data(model);
  forwardKinematics(model, data, q);
  return data.linkTransforms[static_cast<std::size_t>(link - 1)];
}

Eigen::Vector3d pointOnLink(const Transform& T, const Vector<3>& point) {
  return T.topLeftCorner<3, 3>() * Eigen::Vector3d(point) + T.topRightCorner<3, 1>();
}

// The principle of virtual work: a wrench (f, m) acting at a point p of link k does the work
// f . dp + m . dphi when q moves by dq, so tau_j = f . dp/dq_j + m . omega_j, where omega_j is the
// link's angular velocity per unit q_j (the axial vector of dR/dq_j R^T). Central differences.
JointVector virtualWorkTorque(const ManipulatorModel& model, const JointVector& q, int link, const Vector<3>& point,
                              const Vector<6>& wrench) {
  const int n = model.getNumberOfJoints();
  const double h = 1e-6;
  JointVector tau(n);
  for (int j = 0; j < n; ++j) {
    JointVector qp = q, qm = q;
    qp(j) += h;
    qm(j) -= h;
    const Transform Tp = linkPose(model, qp, link), Tm = linkPose(model, qm, link);
    const Eigen::Vector3d dp = (pointOnLink(Tp, point) - pointOnLink(Tm, point)) / (2 * h);
    const Eigen::Matrix3d dR = (Tp.topLeftCorner<3, 3>() - Tm.topLeftCorner<3, 3>()) / (2 * h);
    const Eigen::Matrix3d R = linkPose(model, q, link).topLeftCorner<3, 3>();
    const Eigen::Matrix3d S = dR * R.transpose();  // skew(omega_j)
    const Eigen::Vector3d omega(0.5 * (S(2, 1) - S(1, 2)), 0.5 * (S(0, 2) - S(2, 0)), 0.5 * (S(1, 0) - S(0, 1)));
    tau(j) = wrench.head<3>().dot(dp) + wrench.tail<3>().dot(omega);
  }
  return tau;
}

class LinkWrench : public ::testing::TestWithParam<int> {};

// The built-in arms, the Puma in modified DH, and a URDF arm with prismatic joints (standard and
// modified DH): the torques come from the model's own Jacobian, whatever the convention and
// joint types.
std::unique_ptr<ManipulatorModel> makeModel(int which) {
  if (which == 0) return std::make_unique<Puma560Model>();
  if (which == 1) return std::make_unique<WAM7Model>();
  if (which == 2) return std::make_unique<WAM4Model>();
  if (which == 3) return test::toModifiedDh(Puma560Model());
  UrdfOptions o;
  o.tip = "tool";
  o.requireDynamics = true;
  std::unique_ptr<ManipulatorModel> prismatic = loadUrdf(RP_TEST_MODEL_DATA + "/prismatic_arm.urdf", o);
  if (which == 4) return prismatic;  // the Placement form
  return test::toModifiedDh(*test::prismaticDhArm());
}

TEST_P(LinkWrench, JointTorquesMatchVirtualWork) {
  const std::unique_ptr<ManipulatorModel> model = makeModel(GetParam());
  const int n = model->getNumberOfJoints();
  ManipulatorSimulation sim(*model);
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 20; ++trial) {
    JointVector q(n);
    for (int i = 0; i < n; ++i) {
      q(i) = 0.5 * (model->getPositionMin()(i) + model->getPositionMax()(i)) +
             0.4 * unit(rng) * (model->getPositionMax()(i) - model->getPositionMin()(i));
    }
    for (int link = 1; link <= n; ++link) {
      Vector<3> point;
      Vector<6> wrench;
      for (int i = 0; i < 3; ++i) point(i) = 0.3 * unit(rng);
      for (int i = 0; i < 6; ++i) wrench(i) = (i < 3 ? 50.0 : 5.0) * unit(rng);
      sim.setState(q, JointVector(n));
      sim.clearExternalLinkWrenches();
      sim.setExternalLinkWrench(link, point, wrench);
      sim.step(JointVector(n), 1e-6);
      const JointVector& tau = sim.getExternalTorque();
      const JointVector reference = virtualWorkTorque(*model, q, link, point, wrench);
      // Central differences with h = 1e-6: truncation ~h^2 |f| ~ 1e-10, rounding ~1e-16 |f| / h ~ 1e-8.
      for (int j = 0; j < n; ++j) {
        EXPECT_NEAR(tau(j), reference(j), 1e-6) << "trial " << trial << ", link " << link << ", joint " << j + 1;
      }
      // Joints beyond the link: no torque at all (the reference is zero there too).
      for (int j = link; j < n; ++j) EXPECT_EQ(tau(j), 0.0) << "link " << link << ", joint " << j + 1;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 20 * n);
}

TEST_P(LinkWrench, AWrenchOnTheLastLinkAtTheToolEqualsTheEndEffectorWrench) {
  const std::unique_ptr<ManipulatorModel> model = makeModel(GetParam());
  const int n = model->getNumberOfJoints();
  JointVector q = model->getHomePosition();
  for (int i = 0; i < n; ++i) q(i) += 0.1 * (i + 1);
  Vector<6> wrench;
  for (int i = 0; i < 6; ++i) wrench(i) = 3.0 * i - 7.0;
  ManipulatorSimulation a(*model), b(*model);
  a.setState(q, JointVector(n));
  b.setState(q, JointVector(n));
  a.setExternalWrench(wrench);
  // The tool's origin in the last link's frame.
  ManipulatorData data(*model);
  forwardKinematics(*model, data, q);
  const Transform T = data.linkTransforms[static_cast<std::size_t>(n - 1)];
  const Eigen::Vector3d tool = data.endEffector.topRightCorner<3, 1>();
  Vector<3> point;
  point = T.topLeftCorner<3, 3>().transpose() * (tool - T.topRightCorner<3, 1>());
  b.setExternalLinkWrench(n, point, wrench);
  a.step(JointVector(n), 1e-6);
  b.step(JointVector(n), 1e-6);
  for (int j = 0; j < n; ++j) EXPECT_NEAR(a.getExternalTorque()(j), b.getExternalTorque()(j), 1e-9) << "joint " << j + 1;
}

TEST_P(LinkWrench, TheFirstStepAcceleratesOnlyThroughTheExternalTorque) {
  // From rest, with the gravity torque applied, the accelerations of the first step are
  // M^-1 tau_ext (M with motor inertia; plus what torque saturation takes off the gravity
  // torque): the wrench enters as joint torques on joints 1..k only.
  const std::unique_ptr<ManipulatorModel> model = makeModel(GetParam());
  const int n = model->getNumberOfJoints();
  const int link = (n + 1) / 2;  // a middle link
  JointVector q(n);  // away from the joint stops
  for (int i = 0; i < n; ++i) {
    const double lo = model->getPositionMin()(i), hi = model->getPositionMax()(i);
    q(i) = lo + (0.5 + 0.04 * (i + 1)) * (hi - lo);
  }
  ManipulatorData data(*model);
  JointVector g(n);
  gravityTorque(*model, data, q, g);
  ManipulatorSimulation sim(*model);
  sim.setState(q, JointVector(n));
  Vector<3> point;
  point(0) = -0.1;
  point(2) = 0.05;
  Vector<6> wrench;
  wrench(0) = 20;
  wrench(1) = -10;
  wrench(2) = 30;
  wrench(4) = 2;
  sim.setExternalLinkWrench(link, point, wrench);
  sim.step(g, 1e-3);
  const JointVector tauExt = sim.getExternalTorque();
  for (int j = link; j < n; ++j) EXPECT_EQ(tauExt(j), 0.0) << "no direct torque on joint " << j + 1;
  EXPECT_GT(tauExt.head(link).norm(), 1.0);
  // The simulation saturates the applied torque at the limits (the prismatic arm's gravity load
  // exceeds some of them): M qdd = sat(g) - g + tau_ext at rest.
  JointVector applied = tauExt;
  for (int i = 0; i < n; ++i) {
    applied(i) += std::clamp(g(i), -model->getTorqueLimit()(i), model->getTorqueLimit()(i)) - g(i);
  }
  const JointMatrix M = massMatrix(*model, data, q, true);
  const JointVector expected = M.ldlt().solve(applied);
  for (int j = 0; j < n; ++j) {
    EXPECT_NEAR(sim.getAcceleration()(j), expected(j), 1e-9 * (1 + expected.norm())) << "joint " << j + 1;
  }
}

std::string robotName(const ::testing::TestParamInfo<int>& info) {
  const char* names[] = {"Puma560", "WAM7", "WAM4", "Puma560Craig", "PrismaticArm", "PrismaticArmCraig"};
  return names[info.param];
}

INSTANTIATE_TEST_SUITE_P(Robots, LinkWrench, ::testing::Values(0, 1, 2, 3, 4, 5), robotName);

TEST(LinkWrenchValidation, LinkOutOfRangeIsRefused) {
  Puma560Model model;
  ManipulatorSimulation sim(model);
  EXPECT_THROW(sim.setExternalLinkWrench(0, Vector<3>(), Vector<6>()), std::out_of_range);
  EXPECT_THROW(sim.setExternalLinkWrench(7, Vector<3>(), Vector<6>()), std::out_of_range);
}

using ManipulatorLinkWrench = test::SimulatedArmTest;

TEST_F(ManipulatorLinkWrench, AForceOnTheUpperArmPushesItAlongTheForce) {
  // Zero-gravity mode (gravity compensation only): a 150 N horizontal force on the middle of the
  // Puma's upper arm (link 2) moves that point along the force.
  Puma560 puma;
  const ManipulatorModel& model = puma.getModel();
  ASSERT_TRUE(puma.waitForCycles(5));
  puma.setZeroGravityModeOn();
  Vector<3> point;
  point(0) = -0.2;  // half-way back along the upper arm from the elbow (frame 2 sits at the elbow)
  Vector<6> wrench;
  wrench(0) = 150.0;  // along +x (the upper arm stands upright at home)
  const JointVector q0 = puma.getJointPosition();
  const Eigen::Vector3d p0 = pointOnLink(linkPose(model, q0, 2), point);
  // Exactly 150 cycles of the simulated clock (waiting for them while the clock runs on would let
  // a loaded machine run many more before the wrench is cleared).
  simClock().pause();
  puma.applyExternalWrench(2, point, wrench);
  ASSERT_TRUE(puma.runCycles(150));
  puma.clearExternalWrench(2);
  const JointVector q1 = puma.getJointPosition();
  simClock().resume();
  const Eigen::Vector3d p1 = pointOnLink(linkPose(model, q1, 2), point);
  const Eigen::Vector3d moved = p1 - p0;
  EXPECT_GT(moved.x(), 0.005) << "moved along +x by at least 5 mm";
  EXPECT_GT(moved.x(), 0.9 * moved.norm()) << "mostly along the force";
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  EXPECT_THROW(puma.applyExternalWrench(7, point, wrench), std::out_of_range);
  EXPECT_THROW(puma.applyExternalWrench(0, point, wrench), std::out_of_range);
}

TEST_F(ManipulatorLinkWrench, WrenchesSetFromAnotherThreadWhileTheLoopRuns) {
  // A user thread changes the wrenches on every link and the end-effector as fast as it can
  // while the servo thread reads them each cycle (run under TSan: no data race). The pushes
  // alternate in sign around zero and end cleared, so the held arm ends where it started.
  Puma560 puma;
  ASSERT_TRUE(puma.waitForCycles(5));
  const JointVector start = puma.getJointPosition();
  std::atomic<bool> done{false};
  std::atomic<long> writes{0};
  std::thread user([&] {
    Vector<3> point;
    point(0) = 0.05;
    Vector<6> wrench;
    double sign = 1;
    while (!done.load()) {
      for (int link = 1; link <= 6; ++link) {
        wrench.setZero();
        wrench(link % 3) = sign * 5.0;
        puma.applyExternalWrench(link, point, wrench);
      }
      wrench.setZero();
      wrench(0) = sign * 5.0;
      puma.applyExternalWrench(wrench);
      sign = -sign;
      writes.fetch_add(1);
    }
    for (int link = 1; link <= 6; ++link) puma.clearExternalWrench(link);
    puma.clearExternalWrench();
  });
  // The simulated clock can run 500 cycles before the user thread is first scheduled: wait until
  // it writes, then let the loop run while it goes on writing.
  for (int i = 0; i < 10000 && writes.load() < 10; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_GE(writes.load(), 10);
  ASSERT_TRUE(puma.waitForCycles(500));
  done.store(true);
  user.join();
  ASSERT_TRUE(puma.waitForCycles(2000));
  const JointVector end = puma.getJointPosition();
  // Held by the PID: 5 N pushes are far below what moves it more than a few mrad, and the
  // integral action brings it back once they are gone.
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(end(i), start(i), 2e-3) << "joint " << i + 1;
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

}  // namespace
}  // namespace rp
