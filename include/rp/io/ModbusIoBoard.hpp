#pragma once
/// @file
/// An I/O board reached over Modbus TCP (libmodbus): coils, discrete inputs, holding and input registers.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rp/io/IoBoard.hpp"

namespace rp {

/// An I/O board on the network that speaks Modbus TCP, such as a remote I/O coupler.
///
/// Which Modbus object is which line is configurable (in rp.cfg for the devices that use it):
/// digital output k is coil `digitalOutputCoils[k]`, digital input k is discrete input
/// `digitalInputs[k]`, analog input k is input register `analogInputRegisters[k]`, analog output
/// k is holding register `analogOutputRegisters[k]`, and encoder k is the two input registers
/// starting at `encoderRegisters[k]` (high word first, a signed 32-bit count). Analog registers
/// hold signed 16-bit counts of `voltsPerCount` volts.
///
/// The board connects on first use and after every communication failure tries once per
/// operation to reconnect, so each operation takes at most about two response timeouts.
/// Failures come back as `kNotConnected` (refused, reset), `kTimeout`, `kProtocolError`
/// (garbled or truncated reply) or `kDeviceError` (a Modbus exception reply), with a message
/// naming the address, e.g. `"ModbusIoBoard 127.0.0.1:1502: connect failed: Connection refused"`.
///
/// Not real-time safe: every operation is a network round trip. A servo loop reaches such a
/// board through a hardware server (`rp-hwserver`, `HwServerIoBoard`).
class ModbusIoBoard : public IoBoard {
 public:
  /// Network address and line mapping.
  struct Config {
    std::string address = "127.0.0.1";       ///< IPv4 address of the Modbus TCP server
    int port = 502;                          ///< TCP port (Modbus default 502)
    int unitId = 1;                          ///< Modbus unit (slave) id, 0 .. 247
    int responseTimeoutMs = 200;             ///< connect and response timeout [ms], 1 .. 60000
    std::vector<int> digitalOutputCoils;     ///< coil address of each digital output line
    std::vector<int> digitalInputs;          ///< discrete-input address of each digital input line
    std::vector<int> analogInputRegisters;   ///< input-register address of each analog input
    std::vector<int> analogOutputRegisters;  ///< holding-register address of each analog output
    std::vector<int> encoderRegisters;       ///< first of two input registers of each encoder
    double voltsPerCount = 10.0 / 32768.0;   ///< analog scale [V/count] of the 16-bit registers
  };

  /// Creates the board (no connection yet; the first operation or `connect()` connects).
  /// @param[in] config  address and mapping; addresses must be 0 .. 65535
  /// @throws IoException naming the field if a setting is out of range
  /// Real-time safe: no.
  explicit ModbusIoBoard(const Config& config);
  ~ModbusIoBoard() override;
  ModbusIoBoard(const ModbusIoBoard&) = delete;             ///< not copyable
  ModbusIoBoard& operator=(const ModbusIoBoard&) = delete;  ///< not copyable

  /// Connects now (otherwise the first operation does).
  /// @return `kOk` or `kNotConnected` (with `lastError()` saying why)
  /// Real-time safe: no.
  IoStatus connect() noexcept;
  /// Closes the connection (the next operation reconnects).
  /// Real-time safe: no.
  void disconnect() noexcept;
  /// True while a connection is open.
  /// Real-time safe: yes.
  bool isConnected() const noexcept;

  /// The configuration the board was created with.
  /// Real-time safe: yes.
  const Config& config() const noexcept { return config_; }

  int numDigitalInputs() const noexcept override;
  int numDigitalOutputs() const noexcept override;
  int numAnalogInputs() const noexcept override;
  int numAnalogOutputs() const noexcept override;
  int numEncoders() const noexcept override;

  IoStatus readDigitalInput(int line, bool& value) noexcept override;
  IoStatus writeDigitalOutput(int line, bool value) noexcept override;
  IoStatus readDigitalOutput(int line, bool& value) noexcept override;
  IoStatus readAnalogInput(int channel, double& volts) noexcept override;
  IoStatus writeAnalogOutput(int channel, double volts) noexcept override;
  IoStatus readEncoder(int encoder, std::int64_t& counts) noexcept override;

 private:
  struct Impl;
  IoStatus ensureConnected() noexcept;
  IoStatus failure(const char* operation, int address) noexcept;

  Config config_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rp
