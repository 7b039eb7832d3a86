// The payload an arm carries (a work piece in a gripper): ManipulatorSimulation::setPayload() in
// the simulated plant and DefaultManipulator::setPayload() in the gravity compensation, each
// checked against a computation of its own.
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "SimulatedArmTest.hpp"
#include "Vec3.hpp"
#include "rp/RoboticPlatform.hpp"
#include "rp/manipulator/ManipulatorSimulation.hpp"
#include "rp/model/Model.hpp"

namespace rp {
namespace {

using test::vec3;

JointVector testPose() {
  JointVector q(6);
  q << 0.2, -0.5, 0.8, 0.1, 0.6, 0.3;
  return q;
}

// The model with a point mass `mass` at `centre` (end-effector frame) merged into its last link's
// mass and centre of mass (all gravity depends on): no Jacobian involved.
ManipulatorModel withPointMass(const ManipulatorModel& model, double mass, const Vector<3>& centre) {
  std::vector<LinkParameters> links;
  for (int i = 0; i < model.getNumberOfJoints(); ++i) links.push_back(model.getLink(i));
  LinkParameters& last = links.back();
  const Vector<3> p = transformPoint(model.getToolTransform(), centre);
  last.com = Vector<3>((last.mass * last.com + mass * p) / (last.mass + mass));
  last.mass += mass;
  return ManipulatorModel(model.getName(), links, model.getBaseTransform(), model.getToolTransform(),
                          model.getGravity(), model.getConvention());
}

// -J_p^T (m g): the torque that holds the weight m g at `centre` (end-effector frame), from the
// end-effector's geometric Jacobian.
JointVector weightTorque(const ManipulatorModel& model, const JointVector& q, double mass, const Vector<3>& centre) {
  ManipulatorData data(model);
  const Jacobian J = jacobian(model, data, q, ReferenceFrame::Base);
  const Vector<3> r = Vector<3>(data.endEffector.topLeftCorner<3, 3>() * centre);
  const Vector<3> weight = Vector<3>(mass * model.getGravity());
  JointVector tau = JointVector::Zero(model.getNumberOfJoints());
  for (int j = 0; j < tau.size(); ++j) {
    const Vector<3> v = Vector<3>(J.col(j).head<3>()), w = Vector<3>(J.col(j).tail<3>());
    tau(j) = -(v + w.cross(r)).dot(weight);
  }
  return tau;
}

TEST(PayloadPlant, ARunTimePayloadIsTheSamePlantAsOneBuiltIn) {
  // The payload of setPayload() at the tool point against PlantDeviations::payload, which merges
  // the point mass into the last link (parallel-axis theorem): the full dynamics, moving.
  Puma560Model nominal;
  PlantDeviations loaded;
  loaded.payload = 2.5;
  ManipulatorSimulation built(nominal, loaded), runTime(nominal);
  runTime.setPayload(2.5);
  JointVector qd(6), tau(6);
  qd << 0.5, -0.3, 0.8, 1.0, -0.6, 0.4;
  tau << 5, -20, 10, 1, -2, 0.5;
  for (ManipulatorSimulation* sim : {&built, &runTime}) sim->setState(testPose(), qd);
  for (int k = 0; k < 200; ++k) {
    built.step(tau, 1e-3);
    runTime.step(tau, 1e-3);
    ASSERT_LT((built.getAcceleration() - runTime.getAcceleration()).cwiseAbs().maxCoeff(), 1e-9) << "step " << k;
  }
  EXPECT_DOUBLE_EQ(runTime.getPayloadMass(), 2.5);
  EXPECT_LT((built.getTruePosition() - runTime.getTruePosition()).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_GT((built.getTruePosition() - testPose()).cwiseAbs().maxCoeff(), 1e-2) << "the arm moved";
}

TEST(PayloadPlant, ThePayloadsWeightActsThroughTheJacobianTranspose) {
  // At rest, the arm's own gravity torque plus -J_p^T (m g) holds the arm with the payload
  // still; the arm's own alone does not.
  Puma560Model model;
  ManipulatorData data(model);
  const Vector<3> centre = vec3(0.01, -0.02, 0.12);
  const double mass = 1.7;
  ManipulatorSimulation sim(model);
  sim.setIntegrator(SimulationIntegrator::Euler);
  sim.setPayload(mass, centre);
  JointVector own(6);
  gravityTorque(model, data, testPose(), own);
  const JointVector hold = own + weightTorque(model, testPose(), mass, centre);
  ASSERT_GT(weightTorque(model, testPose(), mass, centre).cwiseAbs().maxCoeff(), 1.0);
  sim.setState(testPose(), JointVector::Zero(6));
  sim.step(hold, 1e-3);
  EXPECT_LT(sim.getAcceleration().cwiseAbs().maxCoeff(), 1e-9) << sim.getAcceleration().transpose();
  sim.setState(testPose(), JointVector::Zero(6));
  sim.step(own, 1e-3);
  EXPECT_GT(sim.getAcceleration().cwiseAbs().maxCoeff(), 0.1) << "the payload pulls the arm down";
  // Set back to none: the arm's own gravity torque holds it again.
  sim.setPayload(0, centre);
  sim.setState(testPose(), JointVector::Zero(6));
  sim.step(own, 1e-3);
  EXPECT_LT(sim.getAcceleration().cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_THROW(sim.setPayload(-1), std::invalid_argument);
}

class PayloadTest : public test::SimulatedArmTest {};

TEST_F(PayloadTest, GravityCompensationGrowsByThePayloadsWeightTorque) {
  // The arm holds a bent pose with its gravity compensation alone (a servo control of zero
  // torque): the torque it outputs is the gravity torque of its model, with the payload once set
  // the point mass merged into the last link. The plant carries the same payload: the arm stays
  // where it is. It takes the payload from the period the call falls in (its step to the next
  // cycle's reading), the compensation from the next cycle, as on a real arm: the arm sags for that
  // period (micro-radians), its friction stops it, and it then stays there for good.
  RoboticPlatform::setConfiguration(
      Configuration::parse("[arm]\nclass Puma560\nsimInitialPosition 11.5 -28.6 45.8 5.7 34.4 17.2\n", "rp.cfg"));
  Puma560 puma("arm");
  test::ConstantTorque none(0, 0.0);
  puma.setServoControl(none);
  ASSERT_TRUE(puma.runCycles(20));
  const JointVector q0 = puma.getJointPosition();
  ASSERT_LT((q0 - testPose()).cwiseAbs().maxCoeff(), 1e-3);  // the pose in rp.cfg, in whole tenths of a degree
  const ManipulatorModel& model = puma.getModel();
  ManipulatorData data(model);
  JointVector own(6);
  gravityTorque(model, data, q0, own);
  EXPECT_LT((puma.getControlOutput() - own).cwiseAbs().maxCoeff(), 1e-9);

  const Vector<3> centre = vec3(0.004, 0.0, 0.1);
  const double mass = 2.0;
  puma.setPayload(mass, centre);
  EXPECT_DOUBLE_EQ(puma.getPayloadMass(), mass);
  ASSERT_TRUE(puma.runCycles(100));
  const JointVector q1 = puma.getJointPosition();
  std::printf("  set 2 kg at 10 cm: the arm sags %.2g rad in the period before the compensation has it\n",
              (q1 - q0).cwiseAbs().maxCoeff());
  EXPECT_LT((q1 - q0).cwiseAbs().maxCoeff(), 1e-4) << "one period's sag";
  ASSERT_TRUE(puma.runCycles(400));
  EXPECT_LT((puma.getJointPosition() - q1).cwiseAbs().maxCoeff(), 1e-12) << "plant and compensation carry the same payload";
  const ManipulatorModel loaded = withPointMass(model, mass, centre);
  ManipulatorData loadedData(loaded);
  JointVector expected(6);
  gravityTorque(loaded, loadedData, q1, expected);
  const JointVector out = puma.getControlOutput();
  EXPECT_LT((out - expected).cwiseAbs().maxCoeff(), 1e-9) << out.transpose() << "\n" << expected.transpose();
  gravityTorque(model, data, q1, own);
  EXPECT_GT((out - own).cwiseAbs().maxCoeff(), 1.0) << "the payload's torque is there";
  EXPECT_LT((out - own - weightTorque(model, q1, mass, centre)).cwiseAbs().maxCoeff(), 1e-9);

  puma.setPayload(0);
  ASSERT_TRUE(puma.runCycles(100));
  const JointVector q2 = puma.getJointPosition();
  EXPECT_LT((q2 - q1).cwiseAbs().maxCoeff(), 1e-4);
  ASSERT_TRUE(puma.runCycles(400));
  EXPECT_LT((puma.getJointPosition() - q2).cwiseAbs().maxCoeff(), 1e-12);
  gravityTorque(model, data, q2, own);
  EXPECT_LT((puma.getControlOutput() - own).cwiseAbs().maxCoeff(), 1e-9);
  puma.releaseServoControl(none);
  test::simClock().resume();
}

}  // namespace
}  // namespace rp
