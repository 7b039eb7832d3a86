#pragma once
/// @file
/// An I/O board held in memory: the simulation-mode board, and the board behind tests.

#include <atomic>
#include <cstdint>
#include <memory>

#include "rp/io/IoBoard.hpp"

namespace rp {

/// An I/O board that exists only in memory. Outputs keep the last value written; inputs and
/// encoders hold whatever the simulation (or a test) sets with `setDigitalInput()`,
/// `setAnalogInput()` and `setEncoder()`. With `loopback` on, digital output k drives digital
/// input k and analog output k drives analog input k (when both exist), like a test plug.
///
/// Every value is an atomic, so one thread may run a simulation that sets the inputs while
/// another reads them.
class SimulatedIoBoard : public IoBoard {
 public:
  /// Sizes of a simulated board.
  struct Config {
    int digitalInputs = 16;    ///< number of digital input lines
    int digitalOutputs = 16;   ///< number of digital output lines
    int analogInputs = 8;      ///< number of analog input channels
    int analogOutputs = 8;     ///< number of analog output channels
    int encoders = 8;          ///< number of encoder counters
    double analogRange = 10.0; ///< analog outputs are clamped to +-analogRange [V]
    bool loopback = false;     ///< outputs drive the inputs with the same number
  };

  /// Creates a board with all lines off and all values zero.
  /// @param[in] config  sizes; every count must be between 0 and 1024
  /// @throws IoException if a count is negative or larger than 1024, or analogRange is not positive
  /// Real-time safe: no (allocates the lines).
  explicit SimulatedIoBoard(const Config& config);
  /// Creates a board with the default sizes of `Config`.
  /// Real-time safe: no.
  SimulatedIoBoard();
  ~SimulatedIoBoard() override;

  int numDigitalInputs() const noexcept override { return config_.digitalInputs; }
  int numDigitalOutputs() const noexcept override { return config_.digitalOutputs; }
  int numAnalogInputs() const noexcept override { return config_.analogInputs; }
  int numAnalogOutputs() const noexcept override { return config_.analogOutputs; }
  int numEncoders() const noexcept override { return config_.encoders; }

  /// Reads a digital input (real-time safe: yes). @copydoc IoBoard::readDigitalInput
  IoStatus readDigitalInput(int line, bool& value) noexcept override;
  /// Sets a digital output (real-time safe: yes). @copydoc IoBoard::writeDigitalOutput
  IoStatus writeDigitalOutput(int line, bool value) noexcept override;
  /// Reads back a digital output (real-time safe: yes). @copydoc IoBoard::readDigitalOutput
  IoStatus readDigitalOutput(int line, bool& value) noexcept override;
  /// Reads an analog input (real-time safe: yes). @copydoc IoBoard::readAnalogInput
  IoStatus readAnalogInput(int channel, double& volts) noexcept override;
  /// Sets an analog output (real-time safe: yes). @copydoc IoBoard::writeAnalogOutput
  IoStatus writeAnalogOutput(int channel, double volts) noexcept override;
  /// Reads an encoder (real-time safe: yes). @copydoc IoBoard::readEncoder
  IoStatus readEncoder(int encoder, std::int64_t& counts) noexcept override;

  /// Sets a digital input line, as the simulated world would.
  /// @param[in] line  0 .. numDigitalInputs()-1
  /// @param[in] value  the line's new state
  /// @return `kOk` or `kInvalidLine`
  /// Real-time safe: yes.
  IoStatus setDigitalInput(int line, bool value) noexcept;
  /// Sets an analog input channel.
  /// @param[in] channel  0 .. numAnalogInputs()-1
  /// @param[in] volts  the channel's new voltage [V]
  /// @return `kOk` or `kInvalidLine`
  /// Real-time safe: yes.
  IoStatus setAnalogInput(int channel, double volts) noexcept;
  /// Reads back an analog output channel.
  /// @param[in] channel  0 .. numAnalogOutputs()-1
  /// @param[out] volts  the last value written [V]
  /// @return `kOk` or `kInvalidLine`
  /// Real-time safe: yes.
  IoStatus readAnalogOutput(int channel, double& volts) noexcept;
  /// Sets an encoder counter.
  /// @param[in] encoder  0 .. numEncoders()-1
  /// @param[in] counts  the counter's new value [counts]
  /// @return `kOk` or `kInvalidLine`
  /// Real-time safe: yes.
  IoStatus setEncoder(int encoder, std::int64_t counts) noexcept;

 private:
  Config config_;
  std::unique_ptr<std::atomic<bool>[]> digitalIn_, digitalOut_;
  std::unique_ptr<std::atomic<double>[]> analogIn_, analogOut_;
  std::unique_ptr<std::atomic<std::int64_t>[]> encoders_;
};

}  // namespace rp
