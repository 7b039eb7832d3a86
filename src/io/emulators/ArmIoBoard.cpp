#include "ArmIoBoard.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rp::emulator {

ArmIoBoard::ArmIoBoard(const ManipulatorModel& model) : ArmIoBoard(model, Config{}) {}

ArmIoBoard::ArmIoBoard(const ManipulatorModel& model, const Config& config)
    : model_(model), config_(config), n_(model.getNumberOfJoints()), data_(std::make_unique<ManipulatorData>(model)) {
  if (!(config.countsPerRadian > 0) || !(config.stepSeconds > 0) || !(config.dacRange > 0))
    throw std::invalid_argument("ArmIoBoard: countsPerRadian, stepSeconds and dacRange must be positive");
  q_ = config.initialPosition.size() == n_ ? config.initialPosition : model.getHomePosition();
  qd_ = JointVector::Zero(n_);
  volts_ = JointVector::Zero(n_);
  tau_ = JointVector::Zero(n_);
  gain_ = JointVector::Zero(n_);
  for (int i = 0; i < n_; ++i) {
    if (config.amplifierGain.size() == n_) gain_[i] = config.amplifierGain[i];
    else if (model.getTorqueLimit().size() == n_ && model.getTorqueLimit()[i] > 0)
      gain_[i] = model.getTorqueLimit()[i] / config.dacRange;
    else gain_[i] = 10.0;
  }
  last_ = std::chrono::steady_clock::now();
}

void ArmIoBoard::advance(double seconds) noexcept {
  std::lock_guard lock(mutex_);
  DynamicsOptions options;
  options.motorInertia = true;
  options.friction = true;
  const int steps = static_cast<int>(std::min(seconds, 1.0) / config_.stepSeconds + 0.5);
  for (int s = 0; s < steps; ++s) {
    if (!enabled_) {  // brakes on
      qd_.setZero();
      continue;
    }
    for (int i = 0; i < n_; ++i) tau_[i] = volts_[i] * gain_[i];
    const JointVector& qdd = forwardDynamics(model_, *data_, q_, qd_, tau_, options);
    // Semi-implicit Euler; the joint stops at its limits.
    qd_ += qdd * config_.stepSeconds;
    q_ += qd_ * config_.stepSeconds;
    for (int i = 0; i < n_; ++i) {
      if (q_[i] < model_.getPositionMin()[i]) { q_[i] = model_.getPositionMin()[i]; qd_[i] = 0; }
      if (q_[i] > model_.getPositionMax()[i]) { q_[i] = model_.getPositionMax()[i]; qd_[i] = 0; }
    }
  }
}

void ArmIoBoard::catchUp() noexcept {
  if (!config_.realTime) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - last_).count();
  const int steps = static_cast<int>(elapsed / config_.stepSeconds);
  if (steps <= 0) return;
  last_ += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(steps * config_.stepSeconds));
  if (elapsed > 1.0) last_ = now;  // far behind (stopped in a debugger): do not try to catch up
  advance(steps * config_.stepSeconds);
}

JointVector ArmIoBoard::position() const {
  std::lock_guard lock(mutex_);
  return q_;
}

JointVector ArmIoBoard::velocity() const {
  std::lock_guard lock(mutex_);
  return qd_;
}

IoStatus ArmIoBoard::readDigitalInput(int line, bool&) noexcept { return checkIndex(line, 0, "digital input"); }

IoStatus ArmIoBoard::writeDigitalOutput(int line, bool value) noexcept {
  if (IoStatus s = checkIndex(line, 1, "digital output"); s != IoStatus::kOk) return s;
  catchUp();
  std::lock_guard lock(mutex_);
  enabled_ = value;
  return IoStatus::kOk;
}

IoStatus ArmIoBoard::readDigitalOutput(int line, bool& value) noexcept {
  if (IoStatus s = checkIndex(line, 1, "digital output"); s != IoStatus::kOk) return s;
  std::lock_guard lock(mutex_);
  value = enabled_;
  return IoStatus::kOk;
}

IoStatus ArmIoBoard::readAnalogInput(int channel, double&) noexcept { return checkIndex(channel, 0, "analog input"); }

IoStatus ArmIoBoard::writeAnalogOutput(int channel, double volts) noexcept {
  if (IoStatus s = checkIndex(channel, n_, "analog output"); s != IoStatus::kOk) return s;
  if (IoStatus s = checkVolts(channel, volts); s != IoStatus::kOk) return s;
  catchUp();
  std::lock_guard lock(mutex_);
  volts_[channel] = std::clamp(volts, -config_.dacRange, config_.dacRange);
  return IoStatus::kOk;
}

IoStatus ArmIoBoard::readEncoder(int encoder, std::int64_t& counts) noexcept {
  if (IoStatus s = checkIndex(encoder, n_, "encoder"); s != IoStatus::kOk) return s;
  catchUp();
  std::lock_guard lock(mutex_);
  counts = std::llround(q_[encoder] * config_.countsPerRadian);
  return IoStatus::kOk;
}

}  // namespace rp::emulator
