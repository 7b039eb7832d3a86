#include "rp/io/SimulatedIoBoard.hpp"

#include <algorithm>
#include <string>

#include "rp/io/IoException.hpp"

namespace rp {

namespace {
void checkCount(int count, const char* what) {
  if (count < 0 || count > 1024)
    throw IoException(std::string("SimulatedIoBoard: ") + what + " = " + std::to_string(count) +
                      " (must be 0 .. 1024)");
}
template <typename T>
std::unique_ptr<std::atomic<T>[]> makeLines(int count, T value) {
  auto lines = std::make_unique<std::atomic<T>[]>(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) lines[i].store(value);
  return lines;
}
}  // namespace

SimulatedIoBoard::SimulatedIoBoard() : SimulatedIoBoard(Config{}) {}

SimulatedIoBoard::SimulatedIoBoard(const Config& config) : config_(config) {
  checkCount(config.digitalInputs, "digitalInputs");
  checkCount(config.digitalOutputs, "digitalOutputs");
  checkCount(config.analogInputs, "analogInputs");
  checkCount(config.analogOutputs, "analogOutputs");
  checkCount(config.encoders, "encoders");
  if (!(config.analogRange > 0.0))
    throw IoException("SimulatedIoBoard: analogRange = " + std::to_string(config.analogRange) +
                      " (must be positive)");
  digitalIn_ = makeLines<bool>(config.digitalInputs, false);
  digitalOut_ = makeLines<bool>(config.digitalOutputs, false);
  analogIn_ = makeLines<double>(config.analogInputs, 0.0);
  analogOut_ = makeLines<double>(config.analogOutputs, 0.0);
  encoders_ = makeLines<std::int64_t>(config.encoders, 0);
}

SimulatedIoBoard::~SimulatedIoBoard() = default;

IoStatus SimulatedIoBoard::readDigitalInput(int line, bool& value) noexcept {
  if (IoStatus s = checkIndex(line, config_.digitalInputs, "digital input"); s != IoStatus::kOk) return s;
  value = digitalIn_[line].load();
  return IoStatus::kOk;
}

IoStatus SimulatedIoBoard::writeDigitalOutput(int line, bool value) noexcept {
  if (IoStatus s = checkIndex(line, config_.digitalOutputs, "digital output"); s != IoStatus::kOk) return s;
  digitalOut_[line].store(value);
  if (config_.loopback && line < config_.digitalInputs) digitalIn_[line].store(value);
  return IoStatus::kOk;
}

IoStatus SimulatedIoBoard::readDigitalOutput(int line, bool& value) noexcept {
  if (IoStatus s = checkIndex(line, config_.digitalOutputs, "digital output"); s != IoStatus::kOk) return s;
  value = digitalOut_[line].load();
  return IoStatus::kOk;
}

IoStatus SimulatedIoBoard::readAnalogInput(int channel, double& volts) noexcept {
  if (IoStatus s = checkIndex(channel, config_.analogInputs, "analog input"); s != IoStatus::kOk) return s;
  volts = analogIn_[channel].load();
  return IoStatus::kOk;
}

IoStatus SimulatedIoBoard::writeAnalogOutput(int channel, double volts) noexcept {
  if (IoStatus s = checkIndex(channel, config_.analogOutputs, "analog output"); s != IoStatus::kOk) return s;
  if (IoStatus s = checkVolts(channel, volts); s != IoStatus::kOk) return s;
  const double clamped = std::clamp(volts, -config_.analogRange, config_.analogRange);
  analogOut_[channel].store(clamped);
  if (config_.loopback && channel < config_.analogInputs) analogIn_[channel].store(clamped);
  return IoStatus::kOk;
}

IoStatus SimulatedIoBoard::readEncoder(int encoder, std::int64_t& counts) noexcept {
  if (IoStatus s = checkIndex(encoder, config_.encoders, "encoder"); s != IoStatus::kOk) return s;
  counts = encoders_[encoder].load();
  return IoStatus::kOk;
}

IoStatus SimulatedIoBoard::setDigitalInput(int line, bool value) noexcept {
  if (IoStatus s = checkIndex(line, config_.digitalInputs, "digital input"); s != IoStatus::kOk) return s;
  digitalIn_[line].store(value);
  return IoStatus::kOk;
}

IoStatus SimulatedIoBoard::setAnalogInput(int channel, double volts) noexcept {
  if (IoStatus s = checkIndex(channel, config_.analogInputs, "analog input"); s != IoStatus::kOk) return s;
  analogIn_[channel].store(volts);
  return IoStatus::kOk;
}

IoStatus SimulatedIoBoard::readAnalogOutput(int channel, double& volts) noexcept {
  if (IoStatus s = checkIndex(channel, config_.analogOutputs, "analog output"); s != IoStatus::kOk) return s;
  volts = analogOut_[channel].load();
  return IoStatus::kOk;
}

IoStatus SimulatedIoBoard::setEncoder(int encoder, std::int64_t counts) noexcept {
  if (IoStatus s = checkIndex(encoder, config_.encoders, "encoder"); s != IoStatus::kOk) return s;
  encoders_[encoder].store(counts);
  return IoStatus::kOk;
}

}  // namespace rp
