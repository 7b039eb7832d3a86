#pragma once
/// @file
/// The generic interface of an I/O board: digital and analog inputs and outputs, encoder counters.

#include <cstdint>

#include "rp/io/DeviceError.hpp"
#include "rp/io/IoStatus.hpp"

namespace rp {

/// Generic interface of an I/O board (the paper's hardware interfacing, section 1, and the
/// boards behind QMotor's hardware servers, section 3.8): digital inputs and outputs, analog
/// inputs and outputs in volts, and encoder counters.
///
/// Lines, channels and encoders are numbered from 0. Every operation returns an `IoStatus`;
/// on failure `lastError()` says what went wrong. Whether an operation is real-time safe depends
/// on the implementation: `SimulatedIoBoard` and `HwServerIoBoard` are, `ModbusIoBoard` is not
/// (it does a network round trip), which is why a servo loop reaches a network board through
/// a hardware server (`rp-hwserver`).
///
/// Example: `bool in; if (board.readDigitalInput(0, in) != IoStatus::kOk) puts(board.lastError());`
class IoBoard {
 public:
  virtual ~IoBoard() = default;

  /// Number of digital input lines.
  /// Real-time safe: yes.
  virtual int numDigitalInputs() const noexcept = 0;
  /// Number of digital output lines.
  /// Real-time safe: yes.
  virtual int numDigitalOutputs() const noexcept = 0;
  /// Number of analog input channels.
  /// Real-time safe: yes.
  virtual int numAnalogInputs() const noexcept = 0;
  /// Number of analog output channels.
  /// Real-time safe: yes.
  virtual int numAnalogOutputs() const noexcept = 0;
  /// Number of encoder counters.
  /// Real-time safe: yes.
  virtual int numEncoders() const noexcept = 0;

  /// Reads a digital input line.
  /// @param[in] line  input line, 0 .. numDigitalInputs()-1
  /// @param[out] value  the line's state (unchanged on failure)
  /// @return `kOk`, `kInvalidLine`, or a communication error
  /// Real-time safe: depends on the implementation (see the class comment).
  virtual IoStatus readDigitalInput(int line, bool& value) noexcept = 0;

  /// Sets a digital output line.
  /// @param[in] line  output line, 0 .. numDigitalOutputs()-1
  /// @param[in] value  true = on
  /// @return `kOk`, `kInvalidLine`, or a communication error
  /// Real-time safe: depends on the implementation.
  virtual IoStatus writeDigitalOutput(int line, bool value) noexcept = 0;

  /// Reads back the state of a digital output line.
  /// @param[in] line  output line, 0 .. numDigitalOutputs()-1
  /// @param[out] value  the line's state (unchanged on failure)
  /// @return `kOk`, `kInvalidLine`, or a communication error
  /// Real-time safe: depends on the implementation.
  virtual IoStatus readDigitalOutput(int line, bool& value) noexcept = 0;

  /// Reads an analog input channel.
  /// @param[in] channel  0 .. numAnalogInputs()-1
  /// @param[out] volts  the input voltage [V] (unchanged on failure)
  /// @return `kOk`, `kInvalidLine`, or a communication error
  /// Real-time safe: depends on the implementation.
  virtual IoStatus readAnalogInput(int channel, double& volts) noexcept = 0;

  /// Sets an analog output channel.
  /// @param[in] channel  0 .. numAnalogOutputs()-1
  /// @param[in] volts  the output voltage [V]; the implementation clamps it to its range
  /// @return `kOk`, `kInvalidLine`, `kInvalidValue` (NaN: refused, the output keeps its value),
  ///         or a communication error
  /// Real-time safe: depends on the implementation.
  virtual IoStatus writeAnalogOutput(int channel, double volts) noexcept = 0;

  /// Reads an encoder counter.
  /// @param[in] encoder  0 .. numEncoders()-1
  /// @param[out] counts  the counter value [counts] (unchanged on failure)
  /// @return `kOk`, `kInvalidLine`, or a communication error
  /// Real-time safe: depends on the implementation.
  virtual IoStatus readEncoder(int encoder, std::int64_t& counts) noexcept = 0;

  /// Waits until the outputs written so far reached the device and returns its answer. Boards
  /// that write synchronously (every board but `HwServerIoBoard`) have nothing to wait for: each
  /// write already returned the device's answer.
  /// @param[in] timeoutMs  the longest wait [ms]
  /// @return `kOk`, or the failure of one of the writes, or `kTimeout`
  /// Real-time safe: depends on the implementation (`HwServerIoBoard`: no, it sleeps).
  virtual IoStatus confirmWrites(int timeoutMs) noexcept {
    (void)timeoutMs;
    return IoStatus::kOk;
  }

  /// When the inputs that the reads return were sampled, for a board that samples them on a clock
  /// of its own (a hardware server reads its board once per server cycle): CLOCK_MONOTONIC [ns].
  /// Two calls that return the same time bracket reads of one sample; a reader that differentiates
  /// positions divides by the time between samples, and knows a repeated sample for one.
  /// @return the sample time [ns]; 0 if the inputs are sampled when read (all but
  ///         `HwServerIoBoard` and `Ros2IoBoard`); -1 while a new sample is being stored (read again)
  /// Real-time safe: yes.
  virtual std::int64_t inputSampleTime() const noexcept { return 0; }

  /// Status of the last failed operation (`kOk` if none failed yet).
  /// Real-time safe: yes.
  IoStatus lastStatus() const noexcept { return error_.status(); }

  /// Message of the last failed operation, for example
  /// `"ModbusIoBoard 127.0.0.1:1502: connection refused"` (empty if none failed yet).
  /// Real-time safe: yes.
  const char* lastError() const noexcept { return error_.message(); }

 protected:
  /// Records a failed operation: implementations call `return error_.set(status, "...", ...)`.
  DeviceError error_;

  /// Checks an index against a count and records `kInvalidLine` naming `what` if it is outside.
  /// @param[in] index  the line, channel or encoder number
  /// @param[in] count  how many the board has
  /// @param[in] what  what is indexed, e.g. "digital output"
  /// @return `kOk` or `kInvalidLine`
  /// Real-time safe: yes.
  IoStatus checkIndex(int index, int count, const char* what) noexcept {
    if (index >= 0 && index < count) return IoStatus::kOk;
    return error_.set(IoStatus::kInvalidLine, "%s %d out of range (board has %d)", what, index, count);
  }

  /// Checks a voltage for an analog output: NaN is refused (`kInvalidValue`, nothing is written);
  /// every other value, infinities too, is then clamped to the board's range by the caller.
  /// @param[in] channel  the analog output, for the message
  /// @param[in] volts  the voltage to check
  /// @return `kOk` or `kInvalidValue`
  /// Real-time safe: yes.
  IoStatus checkVolts(int channel, double volts) noexcept {
    if (volts == volts) return IoStatus::kOk;  // false only for NaN
    return error_.set(IoStatus::kInvalidValue, "analog output %d: NaN volts refused (nothing written)", channel);
  }
};

}  // namespace rp
