// Shared by the manipulator tests: the platform's simulated clock, a fixture that runs each test
// in simulation mode on it with a fresh configuration and no pending shutdown, a constant-torque
// servo control and a joint ramp.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <limits>
#include <thread>

#include "rp/RoboticPlatform.hpp"

namespace rp::test {

inline SimulatedClock& simClock() {
  RoboticPlatform::useSimulatedClock();
  return dynamic_cast<SimulatedClock&>(RoboticPlatform::getDefaultClock());
}

class SimulatedArmTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RoboticPlatform::setConfiguration(Configuration());
    RoboticPlatform::setSimulationModeOn();
    ObjectManager::resetShutdown();
    simClock().resume();
  }
  void TearDown() override { simClock().resume(); }
};

// A servo control that wraps another (the arm's default position control, say): attached and
// activated with it; a subclass's calculate() observes the cycle and calls inner().calculate().
// The subclass calls release() in its destructor: there, before any base destructor, the object
// is still whole for the servo thread's last call and a shutdown's thread.
class WrappedControl : public ServoControl {
 public:
  explicit WrappedControl(ServoControl& inner) : inner_(inner) {}
  void attach(Manipulator& m) override {
    ServoControl::attach(m);
    if (inner_.getManipulator() != &m) inner_.attach(m);
  }
  void activate() override { inner_.activate(); }

 protected:
  ServoControl& inner() { return inner_; }
  // Withdraws the object (a system shutdown's thread keeps off from here on, RoboticObject's rule)
  // and waits until no servo cycle uses it.
  void release() {
    withdrawObject();
    releaseFromManipulator();
  }

 private:
  ServoControl& inner_;
};

// Wraps a servo control and stalls the servo thread in calculate(), as a busy machine may: for
// `stall` in call `first`, then every `every` calls after it (0: only once). Counts its calls.
class StallingControl : public WrappedControl {
 public:
  StallingControl(ServoControl& inner, int first, int every, std::chrono::milliseconds stall)
      : WrappedControl(inner), first_(first), every_(every), stall_(stall) {}
  ~StallingControl() override { release(); }
  void calculate() override {
    const int call = ++calls;
    if (call == first_ || (every_ > 0 && call > first_ && (call - first_) % every_ == 0)) std::this_thread::sleep_for(stall_);
    inner().calculate();
  }
  std::atomic<int> calls{0};

 private:
  const int first_, every_;
  const std::chrono::milliseconds stall_;
};

// Outputs a constant torque on one joint (for the first `cycles` cycles if given, then the
// default position control's output); counts its calls.
class ConstantTorque : public ServoControl {
 public:
  ConstantTorque(int joint, double torque, int cycles = -1) : joint_(joint), torque_(torque), cycles_(cycles) {}
  ~ConstantTorque() override {
    withdrawObject();  // first: a system shutdown's thread keeps off from here on (RoboticObject's rule)
    releaseFromManipulator();
  }
  void calculate() override {
    ++calls;
    auto& m = dynamic_cast<DefaultManipulator&>(*d_manipulator);
    if (cycles_ >= 0 && calls > cycles_) return m.getDefaultPositionControl().calculate();
    JointVector t = JointVector::Zero(m.getNumberOfJoints());
    t(joint_) = torque_;
    m.setControlOutput(t);
  }
  std::atomic<int> calls{0};

 private:
  int joint_;
  double torque_;
  int cycles_;
};

// Moves one joint at a constant speed for `duration` seconds (for ever by default) from the hold
// position the manipulator gives at the first call, then holds there.
class JointRamp : public TrajectoryGenerator {
 public:
  JointRamp(int joint, double speed, double duration = std::numeric_limits<double>::infinity())
      : joint_(joint), speed_(speed), duration_(duration) {}
  ~JointRamp() override {
    withdrawObject();  // first: a system shutdown's thread keeps off from here on (RoboticObject's rule)
    releaseFromManipulators();
  }
  bool getCurrentSetpoint(double time, Setpoint& sp) override {
    if (t0_ < 0) {
      t0_ = time;
      start_ = sp.position;  // the hold position the manipulator filled in
    }
    const double moving = std::min(time - t0_, duration_);
    sp.position = start_;
    sp.position(joint_) += speed_ * moving;
    sp.velocity.setZero();
    sp.velocity(joint_) = time - t0_ < duration_ ? speed_ : 0.0;
    return true;
  }

 private:
  int joint_;
  double speed_, duration_, t0_ = -1;
  JointVector start_;
};

}  // namespace rp::test
