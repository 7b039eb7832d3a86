#include "EffortCommandControl.hpp"

#include "Ros2Common.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "rp/control/DefaultPositionControl.hpp"
#include "rp/manipulator/Manipulator.hpp"
#include "rp/model/Dynamics.hpp"

namespace rp::ros2detail {


EffortCommandControl::EffortCommandControl(const std::string& name, double timeout) : ServoControl(name), timeout_(timeout) {}

EffortCommandControl::~EffortCommandControl() {
  withdrawObject();
  releaseFromManipulator();
}

void EffortCommandControl::attach(Manipulator& manipulator) {
  auto* position = dynamic_cast<DefaultPositionControl*>(&manipulator.getServoControl());
  if (position == nullptr)
    throw std::logic_error("the arm is driven by a servo control of its program ('" + manipulator.getServoControl().getName() + "')");
  kp_ = position->getKp();
  kd_ = position->getKd();
  const int n = manipulator.getModel().getNumberOfJoints();
  data_ = std::make_unique<ManipulatorData>(manipulator.getModel());
  for (JointVector* v : {&hold_, &out_, &gravity_}) v->setZero(n);
  ServoControl::attach(manipulator);
}

void EffortCommandControl::command(const double* torques, int n) noexcept {
  // A sequence lock without fences (ThreadSanitizer has none): stores with release after the odd
  // count, loads with acquire before the second look at it.
  sequence_.fetch_add(1, std::memory_order_relaxed);  // odd: storing
  for (int i = 0; i < n && i < kMaxJoints; ++i) torques_[static_cast<std::size_t>(i)].store(torques[i], std::memory_order_release);
  received_.store(steadyNanoseconds(), std::memory_order_release);
  sequence_.fetch_add(1, std::memory_order_release);  // even: stored
}

void EffortCommandControl::release() noexcept {
  sequence_.fetch_add(1, std::memory_order_relaxed);
  received_.store(0, std::memory_order_release);
  sequence_.fetch_add(1, std::memory_order_release);
}

bool EffortCommandControl::latest(double* torques, int n, std::int64_t& received) const noexcept {
  for (int attempt = 0; attempt < 8; ++attempt) {
    const std::uint64_t before = sequence_.load(std::memory_order_acquire);
    if (before & 1u) continue;
    for (int i = 0; i < n; ++i) torques[i] = torques_[static_cast<std::size_t>(i)].load(std::memory_order_acquire);
    received = received_.load(std::memory_order_acquire);
    if (sequence_.load(std::memory_order_relaxed) == before) return true;
  }
  return false;  // the receive thread kept storing: this cycle holds
}

void EffortCommandControl::activate() {
  holding_ = false;  // the first stale cycle holds where the arm is then
  driving_.store(false, std::memory_order_relaxed);
}

void EffortCommandControl::calculate() {
  Manipulator& m = *d_manipulator;
  const JointVector q = m.getJointPosition();
  const JointVector qd = m.getJointVelocity();
  const int n = static_cast<int>(q.size());
  double torques[kMaxJoints];
  std::int64_t received = 0;
  if (latest(torques, n, received)) {
    std::copy(torques, torques + n, lastTorques_);
    lastReceived_ = received;
  } else {  // the receive thread was storing each time: the last command read whole, while fresh
    std::copy(lastTorques_, lastTorques_ + n, torques);
    received = lastReceived_;
  }
  const bool fresh = received != 0 && 1e-9 * static_cast<double>(steadyNanoseconds() - received) <= timeout_;
  if (fresh) {
    for (int i = 0; i < n; ++i) out_(i) = torques[i];
    if (m.isGravityCompensationOn()) {  // the manipulator adds it: the arm's torque is the command
      gravityTorque(m.getModel(), *data_, q, gravity_);
      out_ -= gravity_;
    }
    holding_ = false;
  } else {
    if (!holding_) hold_ = q;  // the commands stopped: hold here
    holding_ = true;
    for (int i = 0; i < n; ++i) out_(i) = kp_(i) * (hold_(i) - q(i)) - kd_(i) * qd(i);
  }
  driving_.store(fresh, std::memory_order_relaxed);
  m.setControlOutput(out_);
}

}  // namespace rp::ros2detail
