#include "rp/io/ModbusIoBoard.hpp"

#include <modbus.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <string>

#include "rp/io/IoException.hpp"

namespace rp {

struct ModbusIoBoard::Impl {
  modbus_t* ctx = nullptr;
  bool connected = false;
};

namespace {
void checkRange(long value, long lo, long hi, const std::string& field) {
  if (value < lo || value > hi)
    throw IoException("ModbusIoBoard: " + field + " = " + std::to_string(value) + " (must be " +
                      std::to_string(lo) + " .. " + std::to_string(hi) + ")");
}
void checkAddresses(const std::vector<int>& addresses, const char* field, int span) {
  for (std::size_t i = 0; i < addresses.size(); ++i)
    checkRange(addresses[i], 0, 65536 - span, std::string(field) + "[" + std::to_string(i) + "]");
}
}  // namespace

ModbusIoBoard::ModbusIoBoard(const Config& config) : config_(config), impl_(std::make_unique<Impl>()) {
  checkRange(config.port, 1, 65535, "port");
  checkRange(config.unitId, 0, 247, "unitId");
  checkRange(config.responseTimeoutMs, 1, 60000, "responseTimeoutMs");
  checkAddresses(config.digitalOutputCoils, "digitalOutputCoils", 1);
  checkAddresses(config.digitalInputs, "digitalInputs", 1);
  checkAddresses(config.analogInputRegisters, "analogInputRegisters", 1);
  checkAddresses(config.analogOutputRegisters, "analogOutputRegisters", 1);
  checkAddresses(config.encoderRegisters, "encoderRegisters", 2);
  if (!(config.voltsPerCount > 0.0) || !std::isfinite(config.voltsPerCount))
    throw IoException("ModbusIoBoard: voltsPerCount = " + std::to_string(config.voltsPerCount) +
                      " (must be positive)");
  impl_->ctx = modbus_new_tcp(config.address.c_str(), config.port);
  if (impl_->ctx == nullptr)
    throw IoException("ModbusIoBoard: cannot create a Modbus TCP context for address '" + config.address +
                      "': " + modbus_strerror(errno));
  modbus_set_slave(impl_->ctx, config.unitId);
  const auto sec = static_cast<std::uint32_t>(config.responseTimeoutMs / 1000);
  const auto usec = static_cast<std::uint32_t>((config.responseTimeoutMs % 1000) * 1000);
  modbus_set_response_timeout(impl_->ctx, sec, usec);
  modbus_set_byte_timeout(impl_->ctx, sec, usec);
  // No automatic link recovery: libmodbus would retry without bound; we reconnect once per call.
  modbus_set_error_recovery(impl_->ctx, MODBUS_ERROR_RECOVERY_NONE);
}

ModbusIoBoard::~ModbusIoBoard() {
  disconnect();
  modbus_free(impl_->ctx);
}

IoStatus ModbusIoBoard::connect() noexcept {
  if (impl_->connected) return IoStatus::kOk;
  if (modbus_connect(impl_->ctx) == -1) {
    const int err = errno;
    modbus_close(impl_->ctx);
    return error_.set(err == ETIMEDOUT ? IoStatus::kTimeout : IoStatus::kNotConnected,
                      "ModbusIoBoard %s:%d: connect failed: %s", config_.address.c_str(), config_.port,
                      modbus_strerror(err));
  }
  impl_->connected = true;
  return IoStatus::kOk;
}

void ModbusIoBoard::disconnect() noexcept {
  if (impl_->connected) modbus_close(impl_->ctx);
  impl_->connected = false;
}

bool ModbusIoBoard::isConnected() const noexcept { return impl_->connected; }

IoStatus ModbusIoBoard::ensureConnected() noexcept { return connect(); }

IoStatus ModbusIoBoard::failure(const char* operation, int address) noexcept {
  const int err = errno;
  IoStatus status = IoStatus::kNotConnected;
  if (err == ETIMEDOUT || err == EAGAIN) {
    status = IoStatus::kTimeout;
  } else if (err == EMBBADDATA || err == EMBBADCRC || err == EMBMDATA || err == EMBBADSLAVE ||
             err == EMBBADEXC || err == EMBUNKEXC || err == EINVAL) {
    status = IoStatus::kProtocolError;
  } else if (err >= EMBXILFUN && err <= EMBXGTAR) {
    status = IoStatus::kDeviceError;  // a Modbus exception reply: the connection is still good
  }
  if (status != IoStatus::kDeviceError) disconnect();  // the stream may be out of step: start afresh
  return error_.set(status, "ModbusIoBoard %s:%d: %s %d failed: %s", config_.address.c_str(), config_.port,
                    operation, address, modbus_strerror(err));
}

int ModbusIoBoard::numDigitalInputs() const noexcept { return static_cast<int>(config_.digitalInputs.size()); }
int ModbusIoBoard::numDigitalOutputs() const noexcept {
  return static_cast<int>(config_.digitalOutputCoils.size());
}
int ModbusIoBoard::numAnalogInputs() const noexcept {
  return static_cast<int>(config_.analogInputRegisters.size());
}
int ModbusIoBoard::numAnalogOutputs() const noexcept {
  return static_cast<int>(config_.analogOutputRegisters.size());
}
int ModbusIoBoard::numEncoders() const noexcept { return static_cast<int>(config_.encoderRegisters.size()); }

IoStatus ModbusIoBoard::readDigitalInput(int line, bool& value) noexcept {
  if (IoStatus s = checkIndex(line, numDigitalInputs(), "digital input"); s != IoStatus::kOk) return s;
  if (IoStatus s = ensureConnected(); s != IoStatus::kOk) return s;
  std::uint8_t bit = 0;
  const int address = config_.digitalInputs[static_cast<std::size_t>(line)];
  if (modbus_read_input_bits(impl_->ctx, address, 1, &bit) != 1) return failure("read discrete input", address);
  value = bit != 0;
  return IoStatus::kOk;
}

IoStatus ModbusIoBoard::writeDigitalOutput(int line, bool value) noexcept {
  if (IoStatus s = checkIndex(line, numDigitalOutputs(), "digital output"); s != IoStatus::kOk) return s;
  if (IoStatus s = ensureConnected(); s != IoStatus::kOk) return s;
  const int address = config_.digitalOutputCoils[static_cast<std::size_t>(line)];
  if (modbus_write_bit(impl_->ctx, address, value ? 1 : 0) != 1) return failure("write coil", address);
  return IoStatus::kOk;
}

IoStatus ModbusIoBoard::readDigitalOutput(int line, bool& value) noexcept {
  if (IoStatus s = checkIndex(line, numDigitalOutputs(), "digital output"); s != IoStatus::kOk) return s;
  if (IoStatus s = ensureConnected(); s != IoStatus::kOk) return s;
  std::uint8_t bit = 0;
  const int address = config_.digitalOutputCoils[static_cast<std::size_t>(line)];
  if (modbus_read_bits(impl_->ctx, address, 1, &bit) != 1) return failure("read coil", address);
  value = bit != 0;
  return IoStatus::kOk;
}

IoStatus ModbusIoBoard::readAnalogInput(int channel, double& volts) noexcept {
  if (IoStatus s = checkIndex(channel, numAnalogInputs(), "analog input"); s != IoStatus::kOk) return s;
  if (IoStatus s = ensureConnected(); s != IoStatus::kOk) return s;
  std::uint16_t reg = 0;
  const int address = config_.analogInputRegisters[static_cast<std::size_t>(channel)];
  if (modbus_read_input_registers(impl_->ctx, address, 1, &reg) != 1)
    return failure("read input register", address);
  volts = static_cast<std::int16_t>(reg) * config_.voltsPerCount;
  return IoStatus::kOk;
}

IoStatus ModbusIoBoard::writeAnalogOutput(int channel, double volts) noexcept {
  if (IoStatus s = checkIndex(channel, numAnalogOutputs(), "analog output"); s != IoStatus::kOk) return s;
  if (IoStatus s = checkVolts(channel, volts); s != IoStatus::kOk) return s;  // NaN cannot become a count
  if (IoStatus s = ensureConnected(); s != IoStatus::kOk) return s;
  // Clamped to the 16-bit register range (+-32768 counts of voltsPerCount) before the conversion.
  const double counts = std::clamp(std::round(volts / config_.voltsPerCount), -32768.0, 32767.0);
  const auto reg = static_cast<std::uint16_t>(static_cast<std::int16_t>(counts));
  const int address = config_.analogOutputRegisters[static_cast<std::size_t>(channel)];
  if (modbus_write_register(impl_->ctx, address, reg) != 1) return failure("write holding register", address);
  return IoStatus::kOk;
}

IoStatus ModbusIoBoard::readEncoder(int encoder, std::int64_t& counts) noexcept {
  if (IoStatus s = checkIndex(encoder, numEncoders(), "encoder"); s != IoStatus::kOk) return s;
  if (IoStatus s = ensureConnected(); s != IoStatus::kOk) return s;
  std::uint16_t regs[2] = {0, 0};
  const int address = config_.encoderRegisters[static_cast<std::size_t>(encoder)];
  if (modbus_read_input_registers(impl_->ctx, address, 2, regs) != 2)
    return failure("read encoder input registers", address);
  const std::uint32_t raw = (static_cast<std::uint32_t>(regs[0]) << 16) | regs[1];
  counts = static_cast<std::int32_t>(raw);
  return IoStatus::kOk;
}

}  // namespace rp
