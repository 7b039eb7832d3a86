#pragma once
/// @file
/// Driver for the BarrettHand's RS-232 supervisory command protocol (GCL).

#include <array>
#include <string>

#include "rp/io/DeviceError.hpp"
#include "rp/io/IoStatus.hpp"

namespace rp {

/// Speaks the BarrettHand BH8-262 supervisory protocol over a serial port
/// (reference: `refdata/07_barretthand_serial_protocol.txt`): 9600 baud 8N1 without flow
/// control; each command is one line ended by a carriage return; the hand echoes the command,
/// may print a reply, and ends with the prompt `"=> "`; a failed command prints `ERR <n>`
/// (n a bit mask, see `describeErrorCode()`) before the prompt.
///
/// Every wait is bounded by the reply timeout, so an absent, silent, garbled or unplugged hand
/// gives a status (`kNotConnected`, `kTimeout`, `kProtocolError`, `kDeviceError`) and a message
/// naming the port and command, never a hang.
///
/// Example: `BarrettHandSerial hand({"/dev/ttyS0"}); if (hand.open() == IoStatus::kOk) hand.initialize();`
///
/// Not real-time safe: commands wait for the hand (a grasp takes seconds on the real hand).
class BarrettHandSerial {
 public:
  /// Serial port settings.
  struct Config {
    std::string port;              ///< serial device, e.g. `/dev/ttyS0` (rp.cfg setting `port`)
    int baud = 9600;               ///< 9600 (the hand's default), 19200, 38400, 57600 or 115200
    int timeoutMs = 1000;          ///< how long to wait for the prompt after a command [ms]
    int motionTimeoutMs = 10000;   ///< the same for HI, C, O, M and HOME, which move the hand [ms]
  };

  /// Creates the driver (the port is opened by `open()`).
  /// @param[in] config  port and timeouts
  /// @throws IoException if the baud rate is not supported or a timeout is not positive
  /// Real-time safe: no.
  explicit BarrettHandSerial(const Config& config);
  ~BarrettHandSerial();
  BarrettHandSerial(const BarrettHandSerial&) = delete;             ///< not copyable
  BarrettHandSerial& operator=(const BarrettHandSerial&) = delete;  ///< not copyable

  /// Opens the serial port and sets it to raw mode, the baud rate, 8N1, no flow control.
  /// @return `kOk`, or `kNotConnected` (e.g. no such port) with `lastError()` saying why
  /// Real-time safe: no.
  IoStatus open() noexcept;
  /// Closes the port.
  /// Real-time safe: no.
  void close() noexcept;
  /// True while the port is open.
  /// Real-time safe: yes.
  bool isOpen() const noexcept { return fd_ >= 0; }

  /// Sends one command line (without the carriage return) and waits for the prompt.
  /// @param[in] command  e.g. `"GC"`, `"FGET P"`; printable ASCII, at most 120 characters
  /// @param[out] reply  if not null, the reply text between the echo and the prompt, trimmed (null: none allowed)
  /// @param[in] timeoutMs  how long to wait for the prompt [ms]; 0 = the configured timeout
  /// @return `kOk`; `kNotConnected` (port not open or closed by the device), `kTimeout` (no
  ///         prompt: silent or truncated reply), `kProtocolError` (a garbled echo, text where none
  ///         was asked for, an unreadable `ERR`), `kDeviceError` (`ERR <n>`, see `lastErrorCode()`)
  /// Real-time safe: no.
  IoStatus command(const std::string& command, std::string* reply = nullptr, int timeoutMs = 0);

  /// Initialises all motors (`HI`). Real-time safe: no. @return as command()
  IoStatus initialize() { return command("HI", nullptr, config_.motionTimeoutMs); }
  /// Opens the three fingers (`GO`). Real-time safe: no. @return as command()
  IoStatus openGrasp() { return command("GO", nullptr, config_.motionTimeoutMs); }
  /// Closes the three fingers (`GC`). Real-time safe: no. @return as command()
  IoStatus closeGrasp() { return command("GC", nullptr, config_.motionTimeoutMs); }
  /// Relaxes the hand: terminates all motors, torque off (`T`). Real-time safe: no. @return as command()
  IoStatus relax() { return command("T"); }

  /// Reads the positions of fingers 1, 2, 3 and the spread (`FGET P`).
  /// @param[out] counts  encoder counts (fingers 0 .. 17500 ~ 0 .. 140 deg; spread 0 .. 3150 ~ 0 .. 180 deg)
  /// @return as command(), or `kProtocolError` if the reply is not four integers
  /// Real-time safe: no.
  IoStatus readPositions(std::array<int, 4>& counts);

  /// The `ERR` code of the last `kDeviceError` (0 if the last command did not fail that way).
  /// Real-time safe: yes.
  int lastErrorCode() const noexcept { return lastErrorCode_; }
  /// Status of the last failed command (`kOk` if none).
  /// Real-time safe: yes.
  IoStatus lastStatus() const noexcept { return error_.status(); }
  /// Message of the last failed command, e.g.
  /// `"BarrettHand /dev/pts/3: 'GC' failed: ERR 4 (motor not initialized)"`.
  /// Real-time safe: yes.
  const char* lastError() const noexcept { return error_.message(); }

  /// The meaning of an `ERR` bit mask, e.g. `"motor not initialized"`; bits joined with `", "`.
  /// @param[in] code  the number after `ERR`
  /// @return a description (`"unknown error"` for bits the protocol does not define)
  /// Real-time safe: no.
  static std::string describeErrorCode(int code);

 private:
  Config config_;
  int fd_ = -1;
  int lastErrorCode_ = 0;
  DeviceError error_;
};

}  // namespace rp
