#pragma once
/// @file
/// The client side of a hardware server: an `IoBoard` whose lines live in the server's shared memory.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include "rp/io/IoBoard.hpp"

namespace rp {

namespace internal {
struct HwServerShm;
}

/// An `IoBoard` served by a hardware server (`rp-hwserver` or `HwServer`): reads return what the
/// server read from its board in its last cycle; writes are handed to the server, which writes
/// them to the board in its next cycle. Every operation is a few atomic loads and stores in
/// shared memory, so it is real-time safe whatever board the server drives.
///
/// Each operation first checks the server: if it stopped, or its heartbeat is older than
/// `staleTimeoutMs` (the server died or hangs), the operation returns `kNotConnected`; if the
/// server's board failed in its last cycle, `kDeviceError` with the server's message.
///
/// The client has a heartbeat of its own, which the server's watchdog checks (see `HwServer`):
/// with `Heartbeat::kOperations` every operation (and `checkServer()`) beats it, so a servo loop
/// that stops calling the board, hangs, is stopped or killed has its outputs switched off by the
/// server after the watchdog time (`rp-hwserver -watchdog MS`, 50 ms by default). A client that
/// writes a line now and then (a gripper, a tool changer) uses `Heartbeat::kBackgroundThread`:
/// a thread beats while the process runs, so its outputs stay until the process stops, dies or
/// detaches. Destroying the client detaches it: the server switches its outputs off.
/// After the watchdog cut a client off, its operations return `kNotConnected`; attach anew.
class HwServerIoBoard : public IoBoard {
 public:
  /// What keeps the client's heartbeat going.
  enum class Heartbeat {
    kOperations,       ///< every operation: the server cuts the client off when its loop stops (servo clients)
    kBackgroundThread  ///< a thread of the client, while its process runs (clients that write now and then)
  };

  /// Attaches to the running server `name` as a new client. If a client that is gone left an
  /// output on, waits (at most the watchdog time + `staleTimeoutMs`) until the server switched it
  /// off: a new client always starts with the outputs of the clients before it off. (A client
  /// that is only stopped counts as another live client until the watchdog cuts it off.)
  /// @param[in] name  the server's name (`rp-hwserver -name NAME`)
  /// @param[in] staleTimeoutMs  a heartbeat older than this means the server is gone [ms]
  /// @param[in] heartbeat  what keeps this client's heartbeat going
  /// @throws IoException if no server of that name exists, its segment is not a hardware-server
  ///         segment, it has no free client slot, or a gone client's outputs do not go off
  /// Real-time safe: no.
  explicit HwServerIoBoard(const std::string& name, int staleTimeoutMs = 500,
                           Heartbeat heartbeat = Heartbeat::kOperations);
  ~HwServerIoBoard() override;
  HwServerIoBoard(const HwServerIoBoard&) = delete;             ///< not copyable
  HwServerIoBoard& operator=(const HwServerIoBoard&) = delete;  ///< not copyable

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

  /// Waits until the server handled every output this client wrote so far and returns the
  /// board's answer: `kOk` only when the board accepted each of them.
  /// @param[in] timeoutMs  the longest wait [ms]
  /// @return `kOk`, the first refusal or connection failure the server reported for one of them
  ///         (`lastError()` names the line and the board's message), or `kTimeout`/`kNotConnected`
  /// Real-time safe: no (sleeps).
  IoStatus confirmWrites(int timeoutMs) noexcept override;

  /// Checks that the server runs, this client is still attached (not cut off by the watchdog)
  /// and the board works; beats the client's heartbeat.
  /// @return `kOk`, `kNotConnected` (server stopped or not responding, or client cut off) or
  ///         `kDeviceError` (board failure)
  /// Real-time safe: yes.
  IoStatus checkServer() noexcept;
  /// Beats the client's heartbeat without any other operation (a servo loop with nothing to do
  /// with the board in a cycle).
  /// Real-time safe: yes.
  void heartbeat() noexcept;
  /// What the server last wrote to the board and the board accepted on a digital output (the
  /// real output, whoever wrote it: a monitoring client or a test reads the server's outputs so).
  /// @param[in] line  0 .. numDigitalOutputs()-1
  /// @param[out] value  the output's state
  /// @return `kOk` or `kInvalidLine`
  /// Real-time safe: yes.
  IoStatus readAppliedDigitalOutput(int line, bool& value) noexcept;
  /// What the server last wrote to the board and the board accepted on an analog output.
  /// @param[in] channel  0 .. numAnalogOutputs()-1
  /// @param[out] volts  the output [V]
  /// @return `kOk` or `kInvalidLine`
  /// Real-time safe: yes.
  IoStatus readAppliedAnalogOutput(int channel, double& volts) noexcept;
  /// How many clients the server's watchdog cut off so far.
  /// Real-time safe: yes.
  std::uint64_t watchdogTrips() const noexcept;
  /// The server's watchdog time [ms].
  /// Real-time safe: yes.
  double watchdogMs() const noexcept;
  /// When the server last read the board's inputs (CLOCK_MONOTONIC [ns]); -1 while it stores a
  /// new sample. See IoBoard::inputSampleTime().
  /// Real-time safe: yes.
  std::int64_t inputSampleTime() const noexcept override;
  /// Completed cycles of the server.
  /// Real-time safe: yes.
  std::uint64_t serverCycles() const noexcept;
  /// Waits until the server completed at least one more cycle (so that a written output reached
  /// the board and inputs are fresh).
  /// @param[in] timeoutMs  the longest wait [ms]
  /// @return `kOk`, or `kTimeout`/`kNotConnected` if the server does not cycle
  /// Real-time safe: no (sleeps).
  IoStatus waitForCycle(int timeoutMs) noexcept;

 private:
  IoStatus checked(int index, int count, const char* what) noexcept;
  void claimSlot();
  void waitForGoneClientsOutputsOff();
  void keepAlive();
  IoStatus writeResult(bool digital, int line) noexcept;

  std::string name_;
  int staleTimeoutMs_;
  internal::HwServerShm* shm_ = nullptr;
  int slot_ = -1;
  std::uint32_t digitalRequest_[64] = {};  // this client's last request per line (0 = none)
  std::uint32_t analogRequest_[64] = {};
  std::thread keepAlive_;
  std::mutex keepAliveMutex_;
  std::condition_variable keepAliveWake_;
  bool stopKeepAlive_ = false;
};

}  // namespace rp
