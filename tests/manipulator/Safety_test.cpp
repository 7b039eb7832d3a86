// What the servo loop does with faults: a torque or a joint reading that is not a number and an
// exception in a user's servo control or trajectory generator shut the system down safely with
// the message; a torque limit is a saturation (counted), not a fault; after a fault the damped
// hold really runs until the arm is at rest (its stopping distance and time against an
// independent scalar model of the joint), then the brakes engage; simulated brakes stop a moving
// joint with a finite braking torque and hold an arm at rest under gravity.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <thread>

#include "SimulatedArmTest.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

using test::ConstantTorque;
using test::JointRamp;
using test::simClock;
using SafetyTest = test::SimulatedArmTest;

// A user's control that fails on its third call: a torque that is not a number, or a throw.
class FailingControl : public ServoControl {
 public:
  explicit FailingControl(char how) : how_(how) {}
  ~FailingControl() override { releaseFromManipulator(); }
  void calculate() override {
    const int call = ++calls;
    JointVector t = JointVector::Zero(d_manipulator->getNumberOfJoints());
    if (call >= 3 && how_ == 'n') t(2) = std::numeric_limits<double>::quiet_NaN();
    if (call >= 3 && how_ == 'i') t(4) = -std::numeric_limits<double>::infinity();
    if (call >= 3 && how_ == 't') throw std::runtime_error("force sensor unplugged");
    d_manipulator->setControlOutput(t);
  }
  std::atomic<int> calls{0};

 private:
  char how_;
};

// The value of the control-panel field `name` in the object's published state (what a Scene
// Viewer page shows).
double panelValue(const RoboticObject& object, const std::string& name) {
  StateSnapshot snapshot;
  EXPECT_TRUE(object.getStateSnapshot(snapshot));
  for (const ControlPanelField& f : object.getControlPanel().fields)
    if (f.name == name && f.stateIndex >= 0 && f.stateIndex < snapshot.size) return snapshot.values[f.stateIndex];
  ADD_FAILURE() << "no panel field " << name;
  return -1;
}

// Shutdown completed by the servo loop: power off, the state still finite.
void expectSafeStop(Puma560& puma) {
  ASSERT_TRUE(ObjectManager::waitForShutdown(10));
  for (int i = 0; i < 10000 && !puma.isShutdownComplete(); ++i) puma.waitForCycles(1, 1);
  EXPECT_TRUE(puma.isShutdownComplete());
  EXPECT_FALSE(puma.isArmPowerOn());
  const JointVector q = puma.getJointPosition();
  for (int i = 0; i < 6; ++i) EXPECT_TRUE(std::isfinite(q(i))) << "joint " << i + 1;
}

TEST_F(SafetyTest, ATorqueThatIsNotANumberShutsDownInTheSameCycle) {
  for (char how : {'n', 'i'}) {
    ObjectManager::resetShutdown();
    Puma560 puma;
    FailingControl control(how);
    simClock().pause();
    puma.setServoControl(control);
    simClock().resume();
    expectSafeStop(puma);
    EXPECT_EQ(control.calls.load(), 3) << "the control ran no cycle after the one that failed";
    const std::string message = puma.getErrorStatus().message;
    EXPECT_NE(message.find(how == 'n' ? "joint 3 a torque that is not a number" : "joint 5 a torque that is not a number"),
              std::string::npos)
        << message;
    EXPECT_NE(ObjectManager::getShutdownReason().find("not a number"), std::string::npos);
  }
}

// A joint reading that is not a number cannot be controlled (no damped hold can be computed from
// it): the power goes off in that cycle, the brakes engage, and the system shuts down with the
// joint named. Here the simulated environment goes bad: an infinite force, or one that is not a
// number, on the end-effector turns the simulated joints into infinities and NaN (the plant never
// takes such a force for none).
TEST_F(SafetyTest, AJointReadingThatIsNotANumberPowersOffAtOnce) {
  for (double bad : {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    ObjectManager::resetShutdown();
    Puma560 puma;
    ASSERT_TRUE(puma.waitForCycles(5, 10));
    ASSERT_TRUE(puma.isArmPowerOn());
    Vector<6> wrench;
    wrench(0) = bad;
    puma.applyExternalWrench(wrench);
    ASSERT_TRUE(ObjectManager::waitForShutdown(10)) << "force " << bad;
    for (int i = 0; i < 10000 && !puma.isShutdownComplete(); ++i) puma.waitForCycles(1, 1);
    EXPECT_TRUE(puma.isShutdownComplete());
    EXPECT_FALSE(puma.isArmPowerOn());
    EXPECT_EQ(puma.getErrorCode(), 2);
    const std::string message = puma.getErrorStatus().message;
    EXPECT_NE(message.find("reading is not a number"), std::string::npos) << message;
    EXPECT_NE(ObjectManager::getShutdownReason().find("reading is not a number"), std::string::npos)
        << ObjectManager::getShutdownReason();
    EXPECT_TRUE(puma.getControlOutput().isZero()) << "no torque is sent after a reading that is not a number";
  }
}

TEST_F(SafetyTest, AnExceptionInCalculateShutsDownWithItsMessage) {
  Puma560 puma;
  FailingControl control('t');
  simClock().pause();
  puma.setServoControl(control);
  simClock().resume();
  expectSafeStop(puma);
  EXPECT_EQ(control.calls.load(), 3);
  EXPECT_NE(puma.getErrorStatus().message.find("the servo control threw: force sensor unplugged"), std::string::npos)
      << puma.getErrorStatus().message;
}

class ThrowingGenerator : public TrajectoryGenerator {
 public:
  ~ThrowingGenerator() override { releaseFromManipulators(); }
  bool getCurrentSetpoint(double, Setpoint&) override { throw std::runtime_error("no plan for this pose"); }
};

TEST_F(SafetyTest, AnExceptionInTheTrajectoryGeneratorShutsDownWithItsMessage) {
  Puma560 puma;
  ThrowingGenerator generator;
  puma.setTrajectoryGenerator(generator);
  expectSafeStop(puma);
  EXPECT_NE(puma.getErrorStatus().message.find("the trajectory generator threw: no plan for this pose"), std::string::npos)
      << puma.getErrorStatus().message;
}

TEST_F(SafetyTest, ATorqueAtTheLimitPlusGravityIsSaturatedNotAFault) {
  // The control asks for 1.5 times joint 2's torque limit for 20 cycles (a user's control that
  // does not saturate its output; the default control's output at the limit plus gravity
  // compensation is the same case). That is a saturation (counted), not a shutdown, and the arm
  // then goes back to holding.
  Puma560 puma;
  const double limit = puma.getModel().getTorqueLimit()(1);
  ConstantTorque push(1, 1.5 * limit, 20);
  simClock().pause();
  puma.setServoControl(push);
  ASSERT_TRUE(puma.runCycles(1000));
  simClock().resume();
  EXPECT_FALSE(ObjectManager::isShutdownRequested()) << ObjectManager::getShutdownReason();
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  EXPECT_GE(puma.getSaturatedCycleCount(), 20u);
  EXPECT_EQ(panelValue(puma, "saturated"), static_cast<double>(puma.getSaturatedCycleCount()));
  for (int i = 0; i < 6; ++i)
    EXPECT_LE(std::abs(puma.getControlOutput()(i)), puma.getModel().getTorqueLimit()(i)) << "joint " << i + 1;
}

// Joint 1 of the Puma (a vertical axis: no gravity torque) after a fault at its velocity limit,
// as a scalar model: M qdd = -sat(kd qd, limit) - Fc sgn(qd) - b qd, with M the joint's inertia
// (motor included) at the pose, kd the default derivative gain, Fc and b its friction. Returns
// the distance [rad] and time [s] until |qd| < 1e-3 rad/s.
std::pair<double, double> scalarStop(double v0, double M, double kd, double limit, double fc, double b) {
  const double h = 1e-6;
  double v = v0, x = 0, t = 0;
  while (std::abs(v) >= 1e-3 && t < 10) {
    const double tau = -std::clamp(kd * v, -limit, limit) - std::copysign(fc, v) - b * v;
    v += h * tau / M;
    x += h * v;
    t += h;
  }
  return {x, t};
}

TEST_F(SafetyTest, AfterAFaultTheDampedHoldStopsTheArmThenTheBrakesEngage) {
  ObjectManager::setShutdownTimeout(60);  // the test steps the clock one cycle at a time
  Puma560 puma;
  const ManipulatorModel& model = puma.getModel();
  ConstantTorque runaway(0, 60.0);  // joint 1 runs away into its 2 rad/s limit
  simClock().pause();
  puma.setServoControl(runaway);
  while (puma.getErrorCode() == 0) ASSERT_TRUE(puma.runCycles(1, 10));
  // The cycle of the violation: the state the check saw, and the hold from that cycle on.
  const double q0 = puma.getJointPosition()(0), v0 = puma.getJointVelocity()(0);
  ASSERT_NE(puma.getErrorStatus().message.find("joint 1 velocity"), std::string::npos) << puma.getErrorStatus().message;
  ASSERT_GT(v0, 2.0);
  ManipulatorData data(model);
  const double M = massMatrix(model, data, puma.getJointPosition(), true)(0, 0);
  const double kd = puma.getDefaultPositionControl().getKd()(0);
  const LinkParameters& l = model.getLink(0);
  const double g = std::abs(l.gearRatio);
  const auto [distance, time] =
      scalarStop(v0, M, kd, model.getTorqueLimit()(0), g * l.coulombFrictionPositive, l.viscousFriction * g * g);

  int cycles = 0, restCycle = -1;
  double peakTorque = 0;
  while (!puma.isShutdownComplete() && cycles < 5000) {
    ASSERT_TRUE(puma.runCycles(1, 10));
    ++cycles;
    if (restCycle < 0 && std::abs(puma.getJointVelocity()(0)) < 1e-3) restCycle = cycles;
    for (int i = 0; i < 6; ++i) peakTorque = std::max(peakTorque, std::abs(puma.getControlOutput()(i)) / model.getTorqueLimit()(i));
  }
  const double travelled = puma.getJointPosition()(0) - q0;
  ASSERT_TRUE(puma.isShutdownComplete());
  EXPECT_FALSE(puma.isArmPowerOn());
  // The hold ran: the joint stopped over the distance and time of the scalar model (within 12 %
  // and 10 ms: the other joints, held too, couple a little), not in one cycle.
  EXPECT_NEAR(travelled, distance, 0.12 * distance) << "reference " << distance << " rad";
  std::printf("hold: %.4f rad in %.3f s (reference %.4f rad, %.3f s)\n", travelled, restCycle * puma.getPeriod(), distance, time);
  ASSERT_GT(restCycle, 0);
  EXPECT_NEAR(restCycle * puma.getPeriod(), time, 0.1 * time + 0.01) << "reference " << time << " s";
  // Documented bounds (docs/manipulators.md, Safety): from its velocity limit the Puma's joint 1
  // stops within 0.1 rad and 0.15 s; the power goes off after 50 ms at rest.
  EXPECT_LT(travelled, 0.1);
  EXPECT_LT(restCycle * puma.getPeriod(), 0.15);
  EXPECT_GE(cycles - restCycle, 45);
  EXPECT_LE(peakTorque, 1.0) << "the hold stays within the torque limits";
  simClock().resume();
  ASSERT_TRUE(ObjectManager::waitForShutdown(30));  // the manager is done with every object
  ObjectManager::setShutdownTimeout(5);
}

// A user's arm class as the docs say to write one: a DefaultManipulator (a Puma 560 model) that
// starts its loop last in its constructor and stops it first in its destructor, then records the
// state its servo loop published last.
class RecordingPuma : public DefaultManipulator {
 public:
  RecordingPuma(JointVector& velocity, bool& power)
      : DefaultManipulator("", [](const Transform& base) { return std::make_unique<Puma560Model>(0.67183, base); }),
        velocity_(velocity),
        power_(power) {
    startControlLoop();
  }
  ~RecordingPuma() override {
    stopControlLoop();
    velocity_ = getJointVelocity();
    power_ = isArmPowerOn();
  }

 private:
  JointVector& velocity_;
  bool& power_;
};

TEST_F(SafetyTest, DestroyingAMovingArmHoldsItUntilAtRestFirst) {
  // Before, the most-derived destructor stopped the loop at once: the power went off with the arm
  // moving. Now stopControlLoop() first runs the damped hold until the arm is at rest.
  JointVector velocity;
  bool power = true;
  {
    JointRamp ramp(0, 0.8);
    simClock().pause();
    RecordingPuma puma(velocity, power);
    puma.setTrajectoryGenerator(ramp);
    ASSERT_TRUE(puma.runCycles(300));
    ASSERT_GT(std::abs(puma.getJointVelocity()(0)), 0.5) << "the arm moves";
    simClock().resume();  // the ramp goes on (joint 1 is 2 rad from its limit) until the hold begins
  }
  ASSERT_EQ(velocity.size(), 6);
  for (int i = 0; i < 6; ++i) EXPECT_LT(std::abs(velocity(i)), 1e-3) << "joint " << i + 1 << " at rest";
  EXPECT_FALSE(power);
  EXPECT_FALSE(ObjectManager::isShutdownRequested()) << "destroying an arm is no system shutdown";
}

// Pushes joint 1 with a constant torque and stalls the servo thread once for 60 ms, as a busy
// machine may; records each cycle's time and joint-1 velocity.
class StallingPush : public ServoControl {
 public:
  static constexpr int kCycles = 300;
  ~StallingPush() override { releaseFromManipulator(); }
  void calculate() override {
    auto& m = dynamic_cast<DefaultManipulator&>(*d_manipulator);
    const int k = count.load();
    if (k < kCycles) {
      time[k] = m.getTime();
      velocity[k] = m.getJointVelocity()(0);
      count.store(k + 1);
    }
    if (k == 100) std::this_thread::sleep_for(std::chrono::milliseconds(60));
    JointVector t = JointVector::Zero(6);
    t(0) = 35;
    m.setControlOutput(t);
  }
  double time[kCycles] = {}, velocity[kCycles] = {};
  std::atomic<int> count{0};
};

TEST(BusyMachine, OnTheRealClockTheSimulatedArmMovesOnThroughAStall) {
  // The stalled cycle skips deadlines; the next cycle's reading must show the arm accelerated for
  // the whole time that passed, as a real arm under the last torque would (before, the simulation
  // advanced one period per cycle whatever the time, so the arm fell behind its setpoints and the
  // controller's catch-up could trip a velocity limit).
  RoboticPlatform::setConfiguration(Configuration());
  RoboticPlatform::setSimulationModeOn();
  RoboticPlatform::useRealClock();
  ObjectManager::resetShutdown();
  {
    Puma560 puma;
    StallingPush push;
    puma.setServoControl(push);
    for (int i = 0; i < 4000 && push.count.load() < StallingPush::kCycles; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ASSERT_EQ(push.count.load(), StallingPush::kCycles);
    puma.disableArmPower();
    // The stall: the largest gap between two cycles' times (with 20 cycles before it to compare).
    int k = 21;
    for (int i = 21; i < StallingPush::kCycles; ++i)
      if (push.time[i] - push.time[i - 1] > push.time[k] - push.time[k - 1]) k = i;
    const double gap = push.time[k] - push.time[k - 1];
    ASSERT_GT(gap, 0.05);
    // Acceleration over the 20 cycles before the stall, and over the stall itself.
    const double before = (push.velocity[k - 1] - push.velocity[k - 21]) / (push.time[k - 1] - push.time[k - 21]);
    const double across = (push.velocity[k] - push.velocity[k - 1]) / gap;
    EXPECT_GT(before, 1.0);
    EXPECT_NEAR(across / before, 1.0, 0.25) << "before " << before << " rad/s^2, across the stall " << across;
    EXPECT_FALSE(ObjectManager::isShutdownRequested()) << ObjectManager::getShutdownReason();
    EXPECT_GT(puma.getStatistics().missedCycles, 40u);
    // The Scene Viewer's panel shows the count (and the log has it in the column `missed`).
    EXPECT_GT(panelValue(puma, "missed"), 40.0);
  }
  RoboticPlatform::useSimulatedClock();
  ObjectManager::resetShutdown();
}

TEST(SimulatedBrakes, StopAMovingJointWithAFiniteTorqueAndHoldAtRest) {
  Puma560Model model;
  ManipulatorSimulation sim(model);
  const JointVector home = model.getHomePosition();
  JointVector qd = JointVector::Zero(6);
  qd(0) = 1.5;
  sim.setState(home, qd);
  sim.setBrakes(true);
  const JointVector zero = JointVector::Zero(6);
  const double dt = 1e-3;
  int steps = 0;
  while (sim.getVelocity()(0) > 0 && steps < 10000) {
    sim.step(zero, dt);
    ++steps;
  }
  const double travelled = sim.getPosition()(0) - home(0);
  // Reference: the joint alone, decelerated by its brake (the torque limit), its Coulomb friction
  // and viscous friction: M qdd = -(B + Fc) - b qd.
  ManipulatorData data(model);
  const double M = massMatrix(model, data, home, true)(0, 0);
  const LinkParameters& l = model.getLink(0);
  const double g = std::abs(l.gearRatio);
  const double brake = model.getTorqueLimit()(0), fc = g * l.coulombFrictionPositive, b = l.viscousFriction * g * g;
  double v = 1.5, x = 0, t = 0;
  while (v > 0) {
    v -= 1e-6 * (brake + fc + b * v) / M;
    x += 1e-6 * std::max(v, 0.0);
    t += 1e-6;
  }
  EXPECT_NEAR(travelled, x, 0.05 * x);
  EXPECT_NEAR(steps * dt, t, 0.05 * t + 2 * dt);
  EXPECT_GT(steps, 5) << "brakes are not infinitely strong";
  // At rest the brakes hold the arm under gravity exactly.
  const JointVector held = sim.getPosition();
  for (int k = 0; k < 2000; ++k) sim.step(zero, dt);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(sim.getPosition()(i), held(i)) << "joint " << i + 1;
  // The motors are off while the brakes are on: a torque command does not move the arm.
  JointVector tau = JointVector::Zero(6);
  tau(5) = 10;
  for (int k = 0; k < 100; ++k) sim.step(tau, dt);
  EXPECT_EQ(sim.getPosition()(5), held(5));
  // With the upper arm horizontal (gravity loads the shoulder) the brakes hold; a shoulder brake
  // weaker than gravity lets it slip.
  JointVector horizontal = home;
  horizontal(1) = 0;
  sim.setState(horizontal, JointVector::Zero(6));
  for (int k = 0; k < 500; ++k) sim.step(zero, dt);
  EXPECT_EQ(sim.getPosition()(1), 0.0);
  JointVector weak = model.getTorqueLimit();
  weak(1) = 1.0;
  sim.setBrakeTorque(weak);
  for (int k = 0; k < 100; ++k) sim.step(zero, dt);
  EXPECT_GT(std::abs(sim.getPosition()(1)), 1e-3);
  JointVector bad = model.getTorqueLimit();
  bad(2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(sim.setBrakeTorque(bad), std::invalid_argument);
}

}  // namespace
}  // namespace rp
