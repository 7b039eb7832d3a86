// Manipulators in simulation mode on the platform's simulated clock: holding under gravity
// compensation, switching servo controls mid-motion between two cycles, each kind of limit
// violation shutting down in the cycle it happens, two arms at once, determinism, zero-gravity
// mode, bumpless hand-overs (one test each), and an allocation-free servo cycle. (Step and
// trajectory tracking: Tracking_test.cpp.)
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <thread>
#include <utility>
#include <vector>

#include "AllocationCounter.hpp"
#include "SimulatedArmTest.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

using test::ConstantTorque;
using test::simClock;
using ManipulatorTest = test::SimulatedArmTest;

// A trajectory generator that gives a constant target (a step) once `start` has passed.
class StepGenerator : public TrajectoryGenerator {
 public:
  StepGenerator(const JointVector& target, double start) : target_(target), start_(start) {}
  ~StepGenerator() override { releaseFromManipulators(); }
  bool getCurrentSetpoint(double time, Setpoint& sp) override {
    if (time < start_) return false;
    sp.position = target_;
    return true;
  }

 private:
  JointVector target_;
  double start_;
};

// Records the joint positions the servo thread sees at a given cycle, and the largest excursion
// of one joint past a value, by wrapping another servo control.
class Probe : public test::WrappedControl {
 public:
  explicit Probe(ServoControl& inner, std::uint64_t recordAt = 0) : WrappedControl(inner), recordAt_(recordAt) {}
  ~Probe() override { release(); }
  // Track how far each joint goes past `target` (for steps in the positive direction).
  void trackOvershoot(const JointVector& target) {
    target_ = target;
    overshoot_.setZero(target.size());
  }
  void calculate() override {
    ++cycles_;
    const JointVector q = d_manipulator->getJointPosition();
    // Read by the test thread once recorded() is true: stop writing then.
    if (target_.size() == q.size() && cycles_ <= recordAt_) overshoot_ = overshoot_.cwiseMax(q - target_);
    if (cycles_ == recordAt_) {
      recorded_ = q;
      recordedFlag_.store(true);
    }
    inner().calculate();
  }
  bool recorded() const { return recordedFlag_.load(); }
  JointVector recorded_, overshoot_;

 private:
  JointVector target_;
  std::uint64_t recordAt_;
  std::uint64_t cycles_ = 0;
  std::atomic<bool> recordedFlag_{false};
};

TEST_F(ManipulatorTest, GravityCompensationHoldsTheArmAtRest) {
  Puma560 puma;
  const JointVector home = puma.getModel().getHomePosition();
  ASSERT_TRUE(puma.waitForCycles(3000));
  const JointVector q = puma.getJointPosition();
  // With the gravity torque fed forward and the PID holding, the arm stays where it is: the
  // only disturbance is the integration of the exactly compensated dynamics (drift < 1e-6 rad).
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(q(i), home(i), 1e-6) << "joint " << i + 1;
  EXPECT_TRUE(puma.isArmPowerOn());
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

TEST_F(ManipulatorTest, GravityCompensationAloneHoldsRandomPosesAtRest) {
  // Zero-gravity mode outputs only the model's gravity torque: at rest in any pose the arm must
  // stay put (the simulation uses the same model, so the only drift is rounding).
  Puma560 puma;
  DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);
  std::mt19937_64 rng(8);
  const ManipulatorModel& model = puma.getModel();
  for (int trial = 0; trial < 4; ++trial) {
    JointVector q(6);
    for (int i = 0; i < 6; ++i) {
      q(i) = std::uniform_real_distribution<double>(0.7 * model.getPositionMin()(i), 0.7 * model.getPositionMax()(i))(rng);
    }
    tragen.moveRadians(q);
    tragen.stop(1.0);
    puma.setZeroGravityModeOn();
    ASSERT_TRUE(puma.waitForCycles(100));
    const JointVector start = puma.getJointPosition();
    ASSERT_TRUE(puma.waitForCycles(2000));
    const JointVector end = puma.getJointPosition();
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(end(i), start(i), 1e-6) << "pose " << trial << ", joint " << i + 1;
    puma.setZeroGravityModeOff();
    EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  }
}

// Step and trajectory tracking with derived bounds: Tracking_test.cpp.


// A command above the torque limit is saturated, not a fault: Safety_test.cpp.

// Moves joint `joint` at a constant speed from the home position.
class RampGenerator : public TrajectoryGenerator {
 public:
  RampGenerator(const JointVector& start, int joint, double speed) : start_(start), joint_(joint), speed_(speed) {}
  ~RampGenerator() override { releaseFromManipulators(); }
  bool getCurrentSetpoint(double time, Setpoint& sp) override {
    if (t0_ < 0) t0_ = time;  // the shared simulated clock does not start at 0
    sp.position = start_;
    sp.position(joint_) += speed_ * (time - t0_);
    sp.velocity.setZero();
    sp.velocity(joint_) = speed_;
    return true;
  }

 private:
  JointVector start_;
  int joint_;
  double speed_;
  double t0_ = -1;
};

// Wraps a servo control and counts its cycles; records the first cycle in which the state it is
// given (the state the limit check of the same cycle sees) has joint `joint` past its velocity
// limit (kind 'v') or its upper position limit (kind 'p').
class FirstExcess : public test::WrappedControl {
 public:
  FirstExcess(ServoControl& inner, char kind, int joint) : WrappedControl(inner), kind_(kind), joint_(joint) {}
  ~FirstExcess() override { release(); }
  void calculate() override {
    const int call = calls.load() + 1;
    const ManipulatorModel& model = d_manipulator->getModel();
    const bool past = kind_ == 'v' ? std::abs(d_manipulator->getJointVelocity()(joint_)) > model.getVelocityLimit()(joint_)
                                   : d_manipulator->getJointPosition()(joint_) > model.getPositionMax()(joint_);
    if (past && first.load() == 0) first.store(call);
    calls.store(call);
    inner().calculate();
  }
  std::atomic<int> calls{0}, first{0};

 private:
  char kind_;
  int joint_;
};

// The servo control ran in every cycle up to and including the first one past the limit and in
// none after it (that cycle's check switched to the damped hold and requested the shutdown); the
// error names the joint and the kind; the shutdown completes with the power off.
void expectShutdownInTheCycleOfTheExcess(Puma560& puma, const FirstExcess& watch, const std::string& what) {
  ASSERT_TRUE(ObjectManager::waitForShutdown(10));
  puma.waitForCycles(100);
  EXPECT_GT(watch.first.load(), 1);
  EXPECT_EQ(watch.calls.load(), watch.first.load());
  EXPECT_NE(puma.getErrorStatus().message.find(what), std::string::npos) << puma.getErrorStatus().message;
  for (int i = 0; i < 10000 && !puma.isShutdownComplete(); ++i) puma.waitForCycles(1, 1);
  EXPECT_TRUE(puma.isShutdownComplete());
  EXPECT_FALSE(puma.isArmPowerOn());
}

TEST_F(ManipulatorTest, VelocityViolationIsDetectedInTheCycleItHappens) {
  Puma560 puma;
  ConstantTorque spin(5, 20.0);
  FirstExcess watch(spin, 'v', 5);
  simClock().pause();
  puma.setServoControl(watch);
  simClock().resume();
  expectShutdownInTheCycleOfTheExcess(puma, watch, "joint 6 velocity");
}

TEST_F(ManipulatorTest, PositionViolationIsDetectedInTheCycleItHappens) {
  simClock().pause();
  Puma560 puma;
  RampGenerator gen(puma.getModel().getHomePosition(), 4, 1.0);  // joint 5 towards its upper limit
  FirstExcess watch(puma.getDefaultPositionControl(), 'p', 4);
  puma.setServoControl(watch);
  puma.setTrajectoryGenerator(gen);
  simClock().resume();
  expectShutdownInTheCycleOfTheExcess(puma, watch, "joint 5 position");
}

// Wraps a servo control and records the first and last servo cycles it ran in, and the speed of
// joint 1 in its first cycle.
class CycleSpan : public test::WrappedControl {
 public:
  explicit CycleSpan(ServoControl& inner) : WrappedControl(inner) {}
  ~CycleSpan() override { release(); }
  void calculate() override {
    const auto cycle = static_cast<long>(dynamic_cast<DefaultManipulator&>(*d_manipulator).getCycleCount());
    if (first.load() < 0) {
      firstSpeed.store(std::abs(d_manipulator->getJointVelocity()(0)));
      first.store(cycle);
    }
    last.store(cycle);
    inner().calculate();
  }
  std::atomic<long> first{-1}, last{-1};
  std::atomic<double> firstSpeed{0};
};

// Checks, in the servo thread, that getDesiredJointPosition() is the cycle's own setpoint there.
class SetpointProbe : public test::WrappedControl {
 public:
  explicit SetpointProbe(ServoControl& inner) : WrappedControl(inner) {}
  ~SetpointProbe() override { release(); }
  void calculate() override {
    ++cycles;
    if (d_manipulator->getDesiredJointPosition() != d_manipulator->getSetpoint().position) ++different;
    inner().calculate();
  }
  std::atomic<int> cycles{0}, different{0};
};

// getDesiredJointPosition(): the setpoint's position, for the servo thread this cycle's, for other
// threads the last cycle's, as the trajectory generator gave it.
TEST_F(ManipulatorTest, TheDesiredJointPositionIsTheSetpointInAnyThread) {
  Puma560 puma;
  ASSERT_TRUE(puma.waitForCycles(2));
  const JointVector home = puma.getJointPosition();
  EXPECT_EQ(puma.getDesiredJointPosition(), home) << "holding where the arm started";
  JointVector target = home;
  target(1) -= 0.05;
  target(4) += 0.1;
  StepGenerator gen(target, 0.0);
  SetpointProbe probe(puma.getDefaultPositionControl());
  simClock().pause();  // the arm stays on its way however long this thread waits
  puma.setServoControl(probe);
  puma.setTrajectoryGenerator(gen);
  ASSERT_TRUE(puma.runCycles(20));
  EXPECT_EQ(puma.getDesiredJointPosition(), target) << "the step's target, not where the arm is";
  EXPECT_GT((puma.getJointPosition() - target).norm(), 1e-3) << "the arm is still on its way";
  simClock().resume();
  ASSERT_TRUE(puma.waitForCycles(20));
  EXPECT_GE(probe.cycles.load(), 40);
  EXPECT_EQ(probe.different.load(), 0);
}

TEST_F(ManipulatorTest, ServoControlsSwitchMidMotion) {
  // A step on joint 1 under the default control; 30 cycles in, with the joint moving, a stiffer
  // PID takes over. The switch happens between two cycles: the new control's first cycle is the
  // one right after the old control's last, no cycle is skipped or run by both.
  Puma560 puma;
  JointVector target = puma.getModel().getHomePosition();
  target(0) += 0.02;
  StepGenerator gen(target, 0.0);
  CycleSpan before(puma.getDefaultPositionControl());
  simClock().pause();
  puma.setServoControl(before);
  puma.setTrajectoryGenerator(gen);
  ASSERT_TRUE(puma.runCycles(30));  // in motion
  DefaultPositionControl stiffer;
  stiffer.attach(puma);
  JointVector kp = stiffer.getKp() * 2.0, kd = stiffer.getKd() * 1.5, ki = stiffer.getKi();
  stiffer.setGains(kp, kd, ki);
  CycleSpan after(stiffer);
  puma.setServoControl(after);
  simClock().resume();
  ASSERT_TRUE(puma.waitForCycles(2000));
  EXPECT_EQ(&puma.getServoControl(), &after);
  EXPECT_EQ(after.first.load(), before.last.load() + 1) << "taken over between two consecutive cycles";
  EXPECT_GT(after.firstSpeed.load(), 0.01) << "joint 1 was moving at the switch [rad/s]";
  // Within the Coulomb-friction dead band of the new proportional gain (see Tracking_test.cpp).
  const LinkParameters& l = puma.getModel().getLink(0);
  const double fc = std::abs(l.gearRatio) * std::max(l.coulombFrictionPositive, -l.coulombFrictionNegative);
  EXPECT_NEAR(puma.getJointPosition()(0), target(0), fc / kp(0));
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

TEST_F(ManipulatorTest, TwoArmsRunTogetherDeterministically) {
  auto run = [](JointVector& a, JointVector& b) {
    simClock().pause();
    Puma560 first;
    WAM second("", 7);
    // A loop runs its first cycle as soon as its thread starts, even on a paused clock: wait for
    // both, so that nothing below races with a thread that starts late.
    while (first.getCycleCount() < 1 || second.getCycleCount() < 1) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    JointVector ta = first.getModel().getHomePosition(), tb = second.getModel().getHomePosition();
    ta(1) += 0.01;
    tb(0) += 0.01;
    StepGenerator ga(ta, 0.0), gb(tb, 0.0);
    first.setTrajectoryGenerator(ga);
    second.setTrajectoryGenerator(gb);
    Probe pa(first.getDefaultPositionControl(), 700), pb(second.getDefaultPositionControl(), 700);
    first.setServoControl(pa);
    second.setServoControl(pb);
    simClock().resume();
    while (!pa.recorded() || !pb.recorded()) first.waitForCycles(10);
    a = pa.recorded_;
    b = pb.recorded_;
    // Each arm follows its own step (0.7 s in, past half-way to its 0.01 rad step).
    EXPECT_NEAR(a(1), ta(1), 0.005);
    EXPECT_NEAR(b(0), tb(0), 0.005);
    EXPECT_EQ(first.getErrorCode(), 0) << first.getErrorStatus().message;
    EXPECT_EQ(second.getErrorCode(), 0) << second.getErrorStatus().message;
  };
  JointVector a1, b1, a2, b2;
  run(a1, b1);
  run(a2, b2);
  EXPECT_EQ(a1.size(), 6);
  EXPECT_EQ(b1.size(), 7);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(a1(i), a2(i)) << "bit-identical runs";
  for (int i = 0; i < 7; ++i) EXPECT_EQ(b1(i), b2(i)) << "bit-identical runs";
}

TEST_F(ManipulatorTest, ZeroGravityModeLetsAnExternalForcePushTheArm) {
  Puma560 puma;
  puma.setZeroGravityModeOn();
  const Transform before = puma.getEndEffectorTransform();
  Vector<6> push;
  push(0) = 20.0;  // 20 N along +x at the end-effector
  puma.applyExternalWrench(push);
  ASSERT_TRUE(puma.waitForCycles(300));
  puma.clearExternalWrench();
  const Transform after = puma.getEndEffectorTransform();
  EXPECT_GT(after(0, 3) - before(0, 3), 0.01) << "the arm moved along the push";
  // Back under the servo control it stops where it was pushed to.
  puma.setZeroGravityModeOff();
  ASSERT_TRUE(puma.waitForCycles(3000));
  const Transform rest1 = puma.getEndEffectorTransform();
  ASSERT_TRUE(puma.waitForCycles(1000));
  const Transform rest2 = puma.getEndEffectorTransform();
  EXPECT_NEAR(rest1(0, 3), rest2(0, 3), 1e-4) << "at rest (within 0.1 mm per second)";
  EXPECT_GT(rest2(0, 3) - before(0, 3), 0.01) << "where it was pushed to";
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

TEST_F(ManipulatorTest, PowerOffEngagesTheBrakes) {
  Puma560 puma;
  puma.disableArmPower();
  ASSERT_TRUE(puma.waitForCycles(500));
  EXPECT_FALSE(puma.isArmPowerOn());
  const JointVector q = puma.getJointPosition();
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(q(i), puma.getModel().getHomePosition()(i), 1e-6);
  EXPECT_EQ(puma.getControlOutput().squaredNorm(), 0.0);
  puma.enableArmPower();
  ASSERT_TRUE(puma.waitForCycles(50));
  EXPECT_TRUE(puma.isArmPowerOn());
}

// On the paused simulated clock: `tragen` drives `puma` to joint 1 + `radians`; the power goes
// off after `cycles` cycles. Returns the target.
JointVector moveJointOneThenPowerOff(Puma560& puma, DefaultTrajectoryGenerator<6>& tragen, double radians, int cycles) {
  simClock().pause();
  puma.setTrajectoryGenerator(tragen);
  JointVector target = puma.getJointPosition();
  target(0) += radians;
  tragen.moveRadians(target);
  EXPECT_TRUE(puma.runCycles(static_cast<std::uint64_t>(cycles)));
  puma.disableArmPower();
  return target;
}

TEST_F(ManipulatorTest, PoweringOnMidMotionStopsSafelyInsteadOfJumpingToTheGeneratorsSetpoint) {
  // The power goes off 0.4 s into a 1 rad motion of joint 1: the brakes stop the arm there while
  // the generator's motion goes on in time. A program powering the arm on again must not pull it
  // to where that motion is by now (the target): the servo loop refuses the hand-over in that
  // cycle, a visible fault; the arm stays where the brakes stopped it, and the power goes off.
  Puma560 puma;
  DefaultTrajectoryGenerator<6> tragen;
  const JointVector target = moveJointOneThenPowerOff(puma, tragen, 1.0, 400);
  ASSERT_TRUE(puma.runCycles(3000));
  const JointVector braked = puma.getJointPosition();
  ASSERT_GT(target(0) - braked(0), 0.3) << "the brakes stopped the arm short of the target [rad]";
  puma.enableArmPower();
  (void)puma.runCycles(1000);  // false once the loop has ended
  EXPECT_TRUE(ObjectManager::isShutdownRequested());
  EXPECT_NE(puma.getErrorStatus().message.find("power on with the trajectory generator's setpoint"),
            std::string::npos)
      << puma.getErrorStatus().message;
  EXPECT_NE(puma.getErrorStatus().message.find("from joint 1"), std::string::npos) << puma.getErrorStatus().message;
  EXPECT_LT((puma.getJointPosition() - braked).cwiseAbs().maxCoeff(), 0.01) << "the arm did not jump";
  EXPECT_FALSE(puma.isArmPowerOn()) << "the safe stop ends with the power off";
  simClock().resume();
  puma.clearTrajectoryGenerator();
}

TEST_F(ManipulatorTest, PoweringOnAtTheGeneratorsLastTargetFollowsItAgain) {
  // The same off and on at rest after the motion ended: the generator holds the target, where the
  // arm is, so the power comes on without a fault and the next motion runs.
  Puma560 puma;
  DefaultTrajectoryGenerator<6> tragen;
  JointVector target = moveJointOneThenPowerOff(puma, tragen, 0.5, 4000);
  ASSERT_TRUE(tragen.isDone());
  ASSERT_TRUE(puma.runCycles(500));
  puma.enableArmPower();
  ASSERT_TRUE(puma.runCycles(100));
  EXPECT_TRUE(puma.isArmPowerOn());
  target(1) += 0.3;
  tragen.moveRadians(target);
  ASSERT_TRUE(puma.runCycles(4000));
  EXPECT_LT((puma.getJointPosition() - target).cwiseAbs().maxCoeff(), 1e-2) << "the next motion ran";
  simClock().resume();
  EXPECT_FALSE(ObjectManager::isShutdownRequested()) << ObjectManager::getShutdownReason();
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  puma.clearTrajectoryGenerator();
}

// A servo control that outputs nothing: gravity compensation alone holds the arm, so a push moves
// it away from where the last hand-over held it.
struct DoNothing : ServoControl {
  ~DoNothing() override { releaseFromManipulator(); }
  void calculate() override {}
};

// Wraps a servo control and records, in its first cycle, the setpoint it is given and the joints
// read in that cycle.
class FirstCycle : public test::WrappedControl {
 public:
  explicit FirstCycle(ServoControl& inner) : WrappedControl(inner) {}
  ~FirstCycle() override { release(); }
  void calculate() override {
    if (!recorded.load(std::memory_order_relaxed)) {
      setpoint = d_manipulator->getSetpoint().position;
      q = d_manipulator->getJointPosition();
      recorded.store(true, std::memory_order_release);  // the test reads them after this
    }
    inner().calculate();
  }
  JointVector setpoint, q;
  std::atomic<bool> recorded{false};
};

// A push of `newtons` along +x at the end-effector for `cycles` cycles while `control` outputs
// nothing, then 1.5 s for friction to stop the arm; returns the joints it rests at.
JointVector pushAside(DefaultManipulator& arm, DoNothing& control, double newtons, std::uint64_t cycles) {
  arm.setServoControl(control);
  Vector<6> push;
  push(0) = newtons;
  arm.applyExternalWrench(push);
  EXPECT_TRUE(arm.runCycles(cycles));
  arm.clearExternalWrench();
  EXPECT_TRUE(arm.runCycles(1500));
  EXPECT_LT(arm.getJointVelocity().cwiseAbs().maxCoeff(), 1e-3) << "at rest";
  return arm.getJointPosition();
}

// Where the end-effector is at joint positions `q` [m].
Eigen::Vector3d tipAt(const Manipulator& arm, const JointVector& q) {
  const ManipulatorModel& model = arm.getModel();
  ManipulatorData data(model);
  return forwardKinematics(model, data, q).topRightCorner<3, 1>();
}

TEST_F(ManipulatorTest, ReleasingAServoControlHoldsTheArmWhereItIsNotWhereItWas) {
  // A servo control that does nothing (gravity compensation only) while a 40 N push moves the arm
  // for 1 s, then the control is destroyed: the default control takes over holding the arm where
  // it is at that cycle. Before, it pulled the arm back to the pose of before the push and tripped
  // the torque limit ("joint 2 torque 237.202 N m exceeds the limit") every time.
  Puma560 puma;
  simClock().pause();
  const Transform start = puma.getEndEffectorTransform();
  Vector<6> push;
  push(0) = 40;
  JointVector atRelease;
  {
    DoNothing nothing;
    puma.setServoControl(nothing);
    puma.applyExternalWrench(push);
    ASSERT_TRUE(puma.runCycles(1000));
    puma.clearExternalWrench();
    atRelease = puma.getJointPosition();
  }
  ASSERT_TRUE(puma.runCycles(500));
  simClock().resume();
  EXPECT_FALSE(ObjectManager::isShutdownRequested()) << ObjectManager::getShutdownReason();
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  const JointVector q = puma.getJointPosition();
  const ManipulatorModel& model = puma.getModel();
  ManipulatorData data(model);
  const Eigen::Vector3d released = forwardKinematics(model, data, atRelease).topRightCorner<3, 1>();
  const Eigen::Vector3d now = forwardKinematics(model, data, q).topRightCorner<3, 1>();
  const Eigen::Vector3d before = start.topRightCorner<3, 1>();
  ASSERT_GT((released - before).norm(), 0.05) << "the push moved the arm";
  EXPECT_LT((now - released).norm(), 0.25 * (released - before).norm()) << "held near where it was released";
}

TEST_F(ManipulatorTest, ReleasingATrajectoryGeneratorMidMotionHoldsTheArmWhereItIs) {
  // A ramp moves joint 1 at 0.5 rad/s; released after 1 s (cleared, or destroyed), the default
  // control holds the arm where it is at that cycle: not back at the start, not on to a target.
  Puma560 puma;
  simClock().pause();
  const double start = puma.getJointPosition()(0);
  for (const bool destroy : {false, true}) {
    double atRelease = 0;
    {
      test::JointRamp ramp(0, 0.5);
      puma.setTrajectoryGenerator(ramp);
      ASSERT_TRUE(puma.runCycles(1000));
      atRelease = puma.getJointPosition()(0);
      if (!destroy) puma.clearTrajectoryGenerator();
    }
    ASSERT_TRUE(puma.runCycles(1500));
    const double now = puma.getJointPosition()(0);
    EXPECT_GT(std::abs(atRelease - start), 0.3) << "the ramp moved the joint";
    EXPECT_NEAR(now, atRelease, 0.02) << (destroy ? "destroyed" : "cleared") << ": held where it was released";
    EXPECT_LT(std::abs(puma.getJointVelocity()(0)), 1e-3) << "and at rest";
  }
  simClock().resume();
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

TEST_F(ManipulatorTest, ATrajectoryGeneratorAndAServoControlTakeOverFromWhereTheArmIs) {
  // Each hand-over gives the newcomer, in its first cycle, a setpoint at the arm's position then:
  // a generator starts from it, a servo control set while the arm was moved holds it there.
  // (Here a control and zero-gravity mode's end come in the same cycle; the tests below make
  // each hand-over alone.)
  struct FirstSetpoint : TrajectoryGenerator {
    ~FirstSetpoint() override { releaseFromManipulators(); }
    void attach(Manipulator& m) override { arm = &m; }
    bool getCurrentSetpoint(double, Setpoint& sp) override {
      if (!recorded.load(std::memory_order_relaxed)) {
        first = sp.position;
        q = arm->getJointPosition();  // in the servo thread: this cycle's reading
        recorded.store(true, std::memory_order_release);  // the test reads them after this
      }
      return false;  // hold
    }
    Manipulator* arm = nullptr;
    JointVector first, q;
    std::atomic<bool> recorded{false};
  };
  struct Tracker : ServoControl {  // PD on the setpoint; records the first one it sees
    ~Tracker() override { releaseFromManipulator(); }
    void calculate() override {
      Manipulator& m = *d_manipulator;
      if (!recorded.load(std::memory_order_relaxed)) {
        first = m.getSetpoint().position;
        qAtFirst = m.getJointPosition();
        recorded.store(true, std::memory_order_release);  // the test reads them after this
      }
      const JointVector tau = 400.0 * (m.getSetpoint().position - m.getJointPosition()) - 40.0 * m.getJointVelocity();
      m.setControlOutput(tau);
    }
    JointVector first, qAtFirst;
    std::atomic<bool> recorded{false};
  };
  Puma560 puma;
  simClock().pause();
  // Zero-gravity mode and a push move the arm away from where the default control held it.
  puma.setZeroGravityModeOn();
  Vector<6> push;
  push(0) = 30;
  puma.applyExternalWrench(push);
  ASSERT_TRUE(puma.runCycles(600));
  puma.clearExternalWrench();
  Tracker tracker;
  puma.setServoControl(tracker);
  puma.setZeroGravityModeOff();
  ASSERT_TRUE(puma.runCycles(2));
  ASSERT_TRUE(tracker.recorded.load(std::memory_order_acquire));
  const JointVector held = tracker.qAtFirst;
  ASSERT_EQ(tracker.first.size(), 6);
  EXPECT_LT((tracker.first - held).cwiseAbs().maxCoeff(), 1e-12) << "the new control's first setpoint is where the arm is";
  EXPECT_GT((held - puma.getModel().getHomePosition()).cwiseAbs().maxCoeff(), 0.02) << "the push moved the arm";

  FirstSetpoint generator;
  puma.setTrajectoryGenerator(generator);
  ASSERT_TRUE(puma.runCycles(2));
  ASSERT_TRUE(generator.recorded.load(std::memory_order_acquire));
  ASSERT_EQ(generator.first.size(), 6);
  EXPECT_LT((generator.first - generator.q).cwiseAbs().maxCoeff(), 1e-12) << "the generator starts where the arm is";
  EXPECT_LT((generator.first - held).cwiseAbs().maxCoeff(), 0.01) << "near where the control took over";
  ASSERT_TRUE(puma.runCycles(1000));
  // The arm was still coasting when the control took over: it stops near there (a stale hold
  // would pull it back toward the home position instead).
  const JointVector home = puma.getModel().getHomePosition();
  EXPECT_LT((puma.getJointPosition() - held).norm(), 0.5 * (held - home).norm()) << "held near the take-over";
  puma.clearTrajectoryGenerator();
  puma.releaseServoControl(tracker);
  simClock().resume();
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

// Hand-overs, one test each: the arm is away from where the last hand-over held it (a push moved
// it while a do-nothing control was in use, or while the power was off), then one change alone
// is made. Each must hold the arm where it is in the cycle the change is taken.

TEST_F(ManipulatorTest, SettingAServoControlHoldsTheArmWhereItIsNotWhereItWas) {
  // A 40 N push moves the arm for 1 s under a do-nothing control; then, alone, a position control
  // of the program is set. Its first setpoint is where the arm is in its first cycle, and it holds
  // the arm near there: no pull back to the hold of before the push (which saturates the torque
  // and trips the arm, as releasing the control used to).
  Puma560 puma;
  simClock().pause();
  const JointVector start = puma.getJointPosition();
  DoNothing nothing;
  const JointVector pushed = pushAside(puma, nothing, 40, 1000);
  DefaultPositionControl position;
  FirstCycle takeOver(position);
  takeOver.attach(puma);
  const std::uint64_t saturated = puma.getSaturatedCycleCount();
  puma.setServoControl(takeOver);
  ASSERT_TRUE(puma.runCycles(1));
  ASSERT_TRUE(takeOver.recorded.load(std::memory_order_acquire));
  EXPECT_LT((takeOver.setpoint - takeOver.q).cwiseAbs().maxCoeff(), 1e-12) << "the first setpoint is where the arm is";
  ASSERT_TRUE(puma.runCycles(1000));
  const Eigen::Vector3d before = tipAt(puma, start), atSwitch = tipAt(puma, pushed), now = tipAt(puma, puma.getJointPosition());
  ASSERT_GT((atSwitch - before).norm(), 0.05) << "the push moved the arm";
  EXPECT_LT((now - atSwitch).norm(), 0.25 * (atSwitch - before).norm()) << "held near where the control took over";
  EXPECT_EQ(puma.getSaturatedCycleCount(), saturated) << "no torque at a limit";
  EXPECT_FALSE(ObjectManager::isShutdownRequested()) << ObjectManager::getShutdownReason();
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  puma.releaseServoControl(takeOver);
  simClock().resume();
}

TEST_F(ManipulatorTest, SettingATrajectoryGeneratorStartsItWhereTheArmIs) {
  // A 40 N push moves the arm under a do-nothing control; then, alone, a trajectory generator is
  // set. Its first call gets, as the setpoint it starts from, the joints read in that cycle, not
  // the hold of before the push: a ramp from there starts where the arm is.
  struct RecordingRamp : test::JointRamp {
    RecordingRamp() : test::JointRamp(0, 0.2) {}
    ~RecordingRamp() override { releaseFromManipulators(); }
    void attach(Manipulator& m) override { arm = &m; }
    bool getCurrentSetpoint(double time, Setpoint& sp) override {
      if (!recorded.load(std::memory_order_relaxed)) {
        entry = sp.position;
        q = arm->getJointPosition();  // in the servo thread: this cycle's reading
      }
      const bool given = test::JointRamp::getCurrentSetpoint(time, sp);
      if (!recorded.load(std::memory_order_relaxed)) {
        first = sp.position;
        recorded.store(true, std::memory_order_release);  // the test reads them after this
      }
      return given;
    }
    Manipulator* arm = nullptr;
    JointVector entry, first, q;
    std::atomic<bool> recorded{false};
  };
  Puma560 puma;
  simClock().pause();
  const JointVector start = puma.getJointPosition();
  DoNothing nothing;
  const JointVector pushed = pushAside(puma, nothing, 40, 1000);
  ASSERT_GT((pushed - start).cwiseAbs().maxCoeff(), 0.05) << "the push moved the arm";
  RecordingRamp ramp;
  puma.setTrajectoryGenerator(ramp);
  ASSERT_TRUE(puma.runCycles(2));
  ASSERT_TRUE(ramp.recorded.load(std::memory_order_acquire));
  ASSERT_EQ(ramp.entry.size(), 6);
  EXPECT_LT((ramp.entry - ramp.q).cwiseAbs().maxCoeff(), 1e-12) << "the generator is handed the arm's position";
  EXPECT_LT((ramp.first - ramp.q).cwiseAbs().maxCoeff(), 1e-12) << "and its motion starts there";
  EXPECT_GT((ramp.q - start).cwiseAbs().maxCoeff(), 0.05) << "away from the hold of before the push";
  puma.clearTrajectoryGenerator();
  puma.releaseServoControl(nothing);
  ASSERT_TRUE(puma.runCycles(500));
  simClock().resume();
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

TEST_F(ManipulatorTest, ZeroGravityModeOnMidMotionLetsTheArmCoastWithoutAJump) {
  // A ramp drives joint 1 at 0.5 rad/s under the default control; mid-motion, alone, zero-gravity
  // mode goes on. From that very cycle only the gravity torque goes out: no servo torque braking
  // the moving arm or pulling it to a hold, and the ramp no longer drives it. The arm goes on
  // under its own momentum until friction stops it, and floats there.
  Puma560 puma;
  simClock().pause();
  test::JointRamp ramp(0, 0.5);
  puma.setTrajectoryGenerator(ramp);
  ASSERT_TRUE(puma.runCycles(1000));
  const double speed = puma.getJointVelocity()(0), atSwitch = puma.getJointPosition()(0);
  ASSERT_GT(speed, 0.4) << "joint 1 follows the ramp [rad/s]";
  puma.setZeroGravityModeOn();
  const ManipulatorModel& model = puma.getModel();
  ManipulatorData data(model);
  JointVector gravity = JointVector::Zero(6);
  for (int k = 0; k < 100; ++k) {
    ASSERT_TRUE(puma.runCycles(1));
    const JointVector q = puma.getJointPosition(), tau = puma.getControlOutput();  // of the same cycle
    gravityTorque(model, data, q, gravity);
    EXPECT_LT((tau - gravity).cwiseAbs().maxCoeff(), 1e-9) << "cycle " << k + 1 << ": the gravity torque alone";
    if (k == 0) {
      EXPECT_GT(puma.getJointVelocity()(0), 0.95 * speed) << "the arm goes on at its speed";
    }
  }
  ASSERT_TRUE(puma.runCycles(1000));
  const double now = puma.getJointPosition()(0);
  EXPECT_GT(now, atSwitch + 1e-3) << "it coasted on";
  EXPECT_LT(now, atSwitch + 0.1) << "friction stopped it; the ramp (0.55 rad on by now) no longer drives it";
  EXPECT_LT(puma.getJointVelocity().cwiseAbs().maxCoeff(), 1e-3) << "at rest";
  puma.clearTrajectoryGenerator();
  puma.setZeroGravityModeOff();
  ASSERT_TRUE(puma.runCycles(100));
  simClock().resume();
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

TEST_F(ManipulatorTest, ZeroGravityModeOffStartsTheServoControlAfreshWhereTheArmIs) {
  // The default control holds the arm against a steady 20 N push (its integral takes the load);
  // zero-gravity mode lets the push move the arm, the push ends and the arm comes to rest; then,
  // alone, zero-gravity mode goes off. The control starts afresh where the arm is: its first
  // output is the gravity torque, not the integral wound up against the push before.
  Puma560 puma;
  simClock().pause();
  const ManipulatorModel& model = puma.getModel();
  ManipulatorData data(model);
  JointVector gravity = JointVector::Zero(6);
  Vector<6> push;
  push(0) = 20;
  puma.applyExternalWrench(push);
  ASSERT_TRUE(puma.runCycles(3000));
  gravityTorque(model, data, puma.getJointPosition(), gravity);
  const double against = (puma.getControlOutput() - gravity).cwiseAbs().maxCoeff();
  ASSERT_GT(against, 5.0) << "the control holds the push [N m]";
  puma.setZeroGravityModeOn();
  ASSERT_TRUE(puma.runCycles(300));
  puma.clearExternalWrench();
  ASSERT_TRUE(puma.runCycles(1500));
  const JointVector atSwitch = puma.getJointPosition();
  ASSERT_LT(puma.getJointVelocity().cwiseAbs().maxCoeff(), 1e-3) << "at rest";
  puma.setZeroGravityModeOff();
  ASSERT_TRUE(puma.runCycles(1));
  gravityTorque(model, data, puma.getJointPosition(), gravity);
  EXPECT_LT((puma.getControlOutput() - gravity).cwiseAbs().maxCoeff(), 0.05 * against)
      << "the first output is (nearly) the gravity torque alone";
  ASSERT_TRUE(puma.runCycles(1000));
  EXPECT_LT((puma.getJointPosition() - atSwitch).cwiseAbs().maxCoeff(), 1e-3) << "held where zero-gravity mode ended";
  simClock().resume();
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

TEST_F(ManipulatorTest, AnArmWhoseSimulationStartsOffHomeIsHeldWhereItStarts) {
  // rp.cfg starts the simulated arm 30 and -60 degrees away from its home position: the program's
  // start holds it there, not at home.
  RoboticPlatform::setConfiguration(
      Configuration::parse("[puma]\nclass Puma560\nsimInitialPosition 0 30 -60 0 10 0\n", "rp.cfg"));
  simClock().pause();
  Puma560 puma("puma");
  const double deg = std::numbers::pi / 180;
  JointVector start(6);
  start << 0, 30 * deg, -60 * deg, 0, 10 * deg, 0;
  ASSERT_GT((start - puma.getModel().getHomePosition()).cwiseAbs().maxCoeff(), 1.0) << "off home [rad]";
  ASSERT_TRUE(puma.runCycles(2000));
  EXPECT_LT((puma.getJointPosition() - start).cwiseAbs().maxCoeff(), 1e-4) << "held where it started";
  EXPECT_EQ(puma.getSaturatedCycleCount(), 0u) << "no torque at a limit";
  simClock().resume();
  EXPECT_FALSE(ObjectManager::isShutdownRequested()) << ObjectManager::getShutdownReason();
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

TEST_F(ManipulatorTest, PoweringOnAnArmMovedWhilePoweredOffHoldsItWhereItIs) {
  // Powered off, the brakes hold the joints with at most their torque limit: a 40 N m twist about
  // the tool axis slips the wrist joints (25 N m) and turns them. Powered on again, the arm is
  // held where it is then, not turned back to where it was held before the power went off.
  Puma560 puma;
  simClock().pause();
  ASSERT_TRUE(puma.runCycles(10));
  const JointVector before = puma.getJointPosition();
  puma.disableArmPower();
  ASSERT_TRUE(puma.runCycles(50));
  ASSERT_FALSE(puma.isArmPowerOn());
  const Transform tip = puma.getEndEffectorTransform();
  Vector<6> twist;
  for (int i = 0; i < 3; ++i) twist(3 + i) = 40 * tip(i, 2);  // about the tool's z axis [N m]
  puma.applyExternalWrench(twist);
  ASSERT_TRUE(puma.runCycles(100));
  puma.clearExternalWrench();
  ASSERT_TRUE(puma.runCycles(500));
  const JointVector moved = puma.getJointPosition();
  ASSERT_GT((moved - before).cwiseAbs().maxCoeff(), 0.05) << "the twist turned the wrist [rad]";
  ASSERT_LT(puma.getJointVelocity().cwiseAbs().maxCoeff(), 1e-9) << "the brakes stopped it";
  puma.enableArmPower();
  ASSERT_TRUE(puma.runCycles(2000));
  EXPECT_TRUE(puma.isArmPowerOn());
  EXPECT_LT((puma.getJointPosition() - moved).cwiseAbs().maxCoeff(), 1e-3) << "held where the power came on";
  EXPECT_EQ(puma.getSaturatedCycleCount(), 0u) << "no torque at a limit";
  simClock().resume();
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

TEST_F(ManipulatorTest, WithoutHardwareAnArmWaitsUnpoweredForSimulationModeOn) {
  // The paper's Figure 23 under -nosim: `Puma560 pumaSimulated; pumaSimulated.setSimulationModeOn();`
  // The declaration used to throw (no hardware configured); now the switch takes effect.
  RoboticPlatform::setSimulationModeOff();
  {
    Puma560 puma;
    puma.setSimulationModeOn();
    ASSERT_TRUE(puma.waitForCycles(1000));
    EXPECT_TRUE(puma.isArmPowerOn());
    EXPECT_FALSE(ObjectManager::isShutdownRequested()) << ObjectManager::getShutdownReason();
  }
  {
    // Never switched: enableArmPower() says why, and half a second later it is a fault.
    Puma560 puma("lonely");
    EXPECT_FALSE(puma.isArmPowerOn());
    try {
      puma.enableArmPower();
      ADD_FAILURE() << "enableArmPower() without hardware or simulation";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("manipulator 'lonely': simulation mode is off but no hardware is configured"),
                std::string::npos)
          << e.what();
    }
    ASSERT_TRUE(ObjectManager::waitForShutdown(20));
    EXPECT_NE(puma.getErrorStatus().message.find("lonely: simulation mode is off but no hardware"), std::string::npos)
        << puma.getErrorStatus().message;
    EXPECT_FALSE(puma.isArmPowerOn());
  }
  RoboticPlatform::setSimulationModeOn();
}

TEST_F(ManipulatorTest, ARateFromTheQMotorConfigIsThePeriodTheServoControlIntegratesOver) {
  // The qmotorConfig file is applied at the end of the constructor, after the default control
  // took the period: the control must integrate over the new one (2 ms), not the default 1 ms.
  const auto dir = std::filesystem::temp_directory_path() / ("rp-rate-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "leader.cfg") << "rate 500\n";
  std::ofstream(dir / "rp.cfg") << "[leader]\nclass Puma560\nqmotorConfig leader.cfg\n";
  RoboticPlatform::setConfiguration(Configuration::read((dir / "rp.cfg").string()));
  std::filesystem::remove_all(dir);
  Puma560 puma("leader");
  ASSERT_TRUE(puma.waitForCycles(10));
  puma.stop();  // the servo thread's own data is read once it has ended
  EXPECT_EQ(puma.getPeriod(), 0.002);
  EXPECT_EQ(puma.getDefaultPositionControl().getPeriod(), 0.002);
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

TEST_F(ManipulatorTest, CreatedByNameFromTheConfiguration) {
  RoboticPlatform::setConfiguration(Configuration::parse("[leader]\nclass Puma560\n\n[follower]\nclass WAM\nlinks 4\n"
                                                         "position 300 0 0\n",
                                                         "rp.cfg"));
  ObjectManager om;
  Manipulator* leader = om.createDerivedObject<Manipulator>("leader");
  Manipulator* follower = om.createDerivedObject<Manipulator>("follower");
  EXPECT_EQ(leader->getNumberOfJoints(), 6);
  EXPECT_EQ(follower->getNumberOfJoints(), 4);
  EXPECT_NEAR(follower->getModel().getBaseTransform()(0, 3), 0.3, 1e-12) << "position is in millimetres";
  om.deleteObject(leader);
  om.deleteObject(follower);
}

TEST_F(ManipulatorTest, AnyArmFromAUrdfFileIsSimulatedAndHeld) {
  RoboticPlatform::setConfiguration(Configuration::parse(
      "[arm]\nclass UrdfManipulator\nurdf " + RP_TEST_MODEL_DATA + "/test_arm.urdf\ntip tool\nposition 0 0 100\n", "rp.cfg"));
  ObjectManager om;
  Manipulator* arm = om.createDerivedObject<Manipulator>("arm");
  ASSERT_EQ(arm->getNumberOfJoints(), 6);
  EXPECT_EQ(arm->getModel().getName(), "test_arm");
  auto* loop = dynamic_cast<DefaultManipulator*>(arm);
  ASSERT_NE(loop, nullptr);
  ASSERT_TRUE(loop->waitForCycles(2000));
  const JointVector q = arm->getJointPosition();
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(q(i), 0.0, 1e-6) << "held under gravity compensation, joint " << i + 1;
  EXPECT_EQ(arm->getErrorCode(), 0) << arm->getErrorStatus().message;
  om.deleteObject(arm);
  // Errors name rp.cfg's line as well as the URDF file (they used to name the URDF file only).
  RoboticPlatform::setConfiguration(Configuration::parse("[arm]\nclass UrdfManipulator\nurdf nosuchfile.urdf\n", "rp.cfg"));
  try {
    om.createDerivedObject<Manipulator>("arm");
    ADD_FAILURE() << "a missing URDF file was accepted";
  } catch (const UrdfError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("rp.cfg:3: urdf: nosuchfile.urdf: ", 0), 0u) << e.what();
  }
  RoboticPlatform::setConfiguration(Configuration::parse(
      "[arm]\nclass UrdfManipulator\nurdf " + RP_TEST_MODEL_DATA + "/test_arm.urdf\ntip nolink\n", "rp.cfg"));
  try {
    om.createDerivedObject<Manipulator>("arm");
    ADD_FAILURE() << "an unknown tip was accepted";
  } catch (const UrdfError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("rp.cfg:4: tip: ", 0), 0u) << e.what();  // the tip's line
    EXPECT_NE(std::string(e.what()).find("nolink"), std::string::npos) << e.what();
  }
  RoboticPlatform::setConfiguration(Configuration::parse("\n[arm]\nclass UrdfManipulator\n", "rp.cfg"));
  try {
    om.createDerivedObject<Manipulator>("arm");
    ADD_FAILURE() << "a UrdfManipulator without a file was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "rp.cfg:2: [arm] (class UrdfManipulator) needs 'urdf FILE', the arm's description");
  }
}

// Issue 20: rp.cfg's offChainPositions puts the jaw where it is lumped into the arm (deg, as
// simInitialPosition): the same link 6 as loadUrdf() with the jaw at -pi/4 rad. A word that is no
// joint=value pair, a joint the file has no moving joint off the chain of, a value outside the
// joint's limits or a joint given twice is a ConfigError at the setting's line naming the joint.
TEST_F(ManipulatorTest, UrdfArmLumpsLinksOffTheChainWhereRpCfgSays) {
  const std::string head = "[arm]\nclass UrdfManipulator\nurdf " + RP_TEST_MODEL_DATA + "/jaw_arm.urdf\noffChainPositions ";
  RoboticPlatform::setConfiguration(Configuration::parse(head + "jointGripper=-45\n", "rp.cfg"));
  ObjectManager om;
  Manipulator* arm = om.createDerivedObject<Manipulator>("arm");
  UrdfOptions options;
  options.offChainPositions["jointGripper"] = -std::numbers::pi / 4;
  const std::unique_ptr<ManipulatorModel> expected = loadUrdf(RP_TEST_MODEL_DATA + "/jaw_arm.urdf", options);
  const std::unique_ptr<ManipulatorModel> closed = loadUrdf(RP_TEST_MODEL_DATA + "/jaw_arm.urdf");
  ASSERT_EQ(arm->getNumberOfJoints(), 6);
  const LinkParameters &got = arm->getModel().getLink(5), &want = expected->getLink(5);
  EXPECT_LT((Eigen::Vector3d(got.com) - Eigen::Vector3d(want.com)).norm(), 1e-15);
  EXPECT_LT((Eigen::Matrix3d(got.inertia) - Eigen::Matrix3d(want.inertia)).norm(), 1e-15);
  EXPECT_GT((Eigen::Vector3d(got.com) - Eigen::Vector3d(closed->getLink(5).com)).norm(), 1e-3) << "the jaw moved";
  om.deleteObject(arm);
  for (const auto& [value, message] : std::vector<std::pair<std::string, std::string>>{
           {"nosuch=0", "offChainPositions: there is no joint 'nosuch' (moving joints off the chain: jointGripper) in "},
           {"jointGripper=open", "offChainPositions: joint 'jointGripper': 'open' is not a finite number"},
           {"jointGripper=+-10", "offChainPositions: joint 'jointGripper': '+-10' is not a finite number"},
           {"jointGripper", "offChainPositions: 'jointGripper' is not a joint=value pair"},
           {"jointGripper=10", "offChainPositions: joint 'jointGripper': 10 deg is outside its limits -89.9544 .. 0 deg in "},
           {"joint3=5", "offChainPositions: joint 'joint3' is a joint of the arm, not off the chain"},
           {"jointGripper=-10 jointGripper=-20", "offChainPositions: joint 'jointGripper' is given twice"}}) {
    RoboticPlatform::setConfiguration(Configuration::parse(head + value + "\n", "rp.cfg"));
    try {
      om.createDerivedObject<Manipulator>("arm");
      ADD_FAILURE() << value << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("rp.cfg:4: " + message, 0), 0u) << value << ": " << e.what();
    }
  }
}

// Counts the allocations the servo thread makes between two consecutive calculate() calls: the
// whole cycle (simulation step, limit checks, state publication, log sampling, trajectory).
class AllocationProbe : public test::WrappedControl {
 public:
  explicit AllocationProbe(ServoControl& inner) : WrappedControl(inner) {}
  ~AllocationProbe() override { release(); }
  void calculate() override {
    const std::size_t now = test::allocationCount();
    if (cycles_ > 2) allocations_ += now - last_;
    ++cycles_;
    inner().calculate();
    last_ = test::allocationCount();
    if (cycles_ > 2) allocations_ += last_ - now;
    total_.store(allocations_);
    cycleCount_.store(cycles_);
  }
  std::size_t allocations() const { return total_.load(); }
  std::uint64_t cycles() const { return cycleCount_.load(); }

 private:
  std::size_t last_ = 0, allocations_ = 0;
  std::uint64_t cycles_ = 0;
  std::atomic<std::uint64_t> cycleCount_{0};
  std::atomic<std::size_t> total_{0};  // allocations_, published for the test thread
};

// StateSnapshot::readTime, which the ROS 2 bridge stamps joint states with, of a simulated arm: the
// cycle's time, on a simulated clock and on the real one alike, where a cycle may run late: the
// joints are the simulation's state at the cycle's time (a late cycle integrates to it, a cycle
// after skipped deadlines catches up to it), and a stamp of when the late cycle ran would not match
// their motion (a reader differentiating over the stamps sees a velocity spike). The hardware's
// read time: HardwareManipulator_test. StateSnapshot::cycle numbers the cycles: one more per period
// of the simulated clock, and rising on the real one.
TEST_F(ManipulatorTest, TheStateSnapshotOfASimulatedArmHoldsAtItsCyclesTime) {
  {
    Puma560 puma("puma");
    ASSERT_TRUE(puma.waitForCycles(3));
    StateSnapshot s;
    ASSERT_TRUE(puma.getStateSnapshot(s));
    EXPECT_GT(s.time, 0);
    EXPECT_EQ(s.readTime, s.time);
    ASSERT_TRUE(puma.waitForCycles(7));
    StateSnapshot later;
    ASSERT_TRUE(puma.getStateSnapshot(later));
    EXPECT_GE(later.cycle, s.cycle + 7);
    EXPECT_NEAR((later.time - s.time) * puma.getRate(), static_cast<double>(later.cycle - s.cycle), 1e-6);
  }
  RoboticPlatform::useRealClock();
  {
    // Cycles made late on purpose: the servo control stalls the loop for 5 ms every 50 cycles.
    Puma560 puma("puma");
    test::StallingControl stalling(puma.getDefaultPositionControl(), 50, 50, std::chrono::milliseconds(5));
    puma.setServoControl(stalling);
    ASSERT_TRUE(puma.waitForCycles(3));
    const Clock& clock = puma.getControlProgram()->getClock();
    ASSERT_FALSE(clock.isSimulated());
    double lastTime = -1;
    std::uint64_t lastCycle = 0;
    int cycles = 0;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (cycles < 300 && std::chrono::steady_clock::now() < deadline) {
      StateSnapshot s;
      ASSERT_TRUE(puma.getStateSnapshot(s));
      if (s.time == lastTime) {
        std::this_thread::sleep_for(std::chrono::microseconds(300));
        continue;
      }
      lastTime = s.time;
      if (cycles > 0) {
        EXPECT_GT(s.cycle, lastCycle) << "a later cycle with no later number";
      }
      lastCycle = s.cycle;
      ++cycles;
      EXPECT_EQ(s.readTime, s.time) << "cycle " << s.cycle << " stamped " << (s.readTime - s.time) * 1e3
                                    << " ms after its time";
    }
    EXPECT_GE(cycles, 300);
    EXPECT_GT(puma.getStatistics().missedCycles, 0u) << "the stalls made cycles late";
    puma.releaseServoControl(stalling);
  }
  simClock();  // back to the simulated clock for the other tests
}

TEST_F(ManipulatorTest, TheServoCycleDoesNotAllocate) {
  Puma560 puma;
  JointVector target = puma.getModel().getHomePosition();
  target(2) += 0.01;
  StepGenerator gen(target, 0.0);
  AllocationProbe probe(puma.getDefaultPositionControl());
  puma.setServoControl(probe);
  puma.setTrajectoryGenerator(gen);
  Vector<6> push;
  push(2) = 5.0;
  puma.applyExternalWrench(push);
  while (probe.cycles() < 1000) puma.waitForCycles(100);
  // A wrench on a link too: the servo thread copies it in and the simulation applies it.
  Vector<3> point;
  point(0) = -0.2;
  puma.applyExternalWrench(2, point, push);
  while (probe.cycles() < 2000) puma.waitForCycles(100);
  // A payload picked up and put down: the servo thread takes it for the gravity compensation
  // and the simulated plant (whose unit payload model setPayload() built in this thread).
  Vector<3> centre;
  centre(2) = 0.1;
  puma.setPayload(1.5, centre);
  while (probe.cycles() < 3000) puma.waitForCycles(100);
  puma.setPayload(0, centre);
  while (probe.cycles() < 3500) puma.waitForCycles(100);
  puma.setPayload(0.7, centre);
  while (probe.cycles() < 4000) puma.waitForCycles(100);
  simClock().pause();
  EXPECT_EQ(probe.allocations(), 0u);
}

}  // namespace
}  // namespace rp
