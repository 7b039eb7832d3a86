#pragma once
/// @file
/// The QMotor-style hardware server: does a board's I/O at a fixed rate and serves its lines to
/// any number of client processes through POSIX shared memory.

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

#include "rp/io/IoBoard.hpp"

namespace rp {

namespace internal {
struct HwServerShm;
}

/// A hardware server in the manner of QMotor's (paper section 3.8): a loop that, at a fixed
/// rate, reads every input of an `IoBoard` into a shared-memory segment named after the server
/// and writes every output that a client changed from the segment to the board. Clients
/// (`HwServerIoBoard`, in the same or another process) see only the generic line operations, so
/// switching boards means starting a different server. The program `rp-hwserver` wraps this class.
///
/// The segment is `/dev/shm/rp-hwserver-<name>`; it is created by `start()` and removed by
/// `stop()`. Each cycle also publishes a heartbeat (monotonic time), the cycle count and the
/// board's status, so clients notice a server that died or a board that failed.
///
/// Client watchdog: every output line belongs to the client that wrote it last, and every client
/// publishes a heartbeat of its own (`HwServerIoBoard`). When a client falls silent for longer
/// than the watchdog time (killed, stopped, hung) while one of its outputs is on, or detaches, or
/// its process is gone, the server writes its outputs off (digital false, analog 0 V) in its next
/// cycle: within the watchdog time plus one server period after its last operation. A silent client
/// that wakes up again finds its writes refused (`kNotConnected`) until it attaches anew, so it
/// cannot switch amplifiers back on with stale commands.
///
/// Writes are acknowledged: the server reports the board's answer to each written line (see
/// `HwServerIoBoard::confirmWrites()`). A write the board refuses (`kDeviceError`,
/// `kInvalidLine`, `kNotSupported`) is reported to that line only and the cycle goes on; a
/// connection failure (`kNotConnected`, `kTimeout`, `kProtocolError`) ends the cycle, is
/// reported to every pending write and becomes the board status.
class HwServer {
 public:
  /// Creates the server for a board (not yet started).
  /// @param[in] board  the board to serve; must outlive the server; at most 64 lines of each kind are served
  /// @param[in] name  server name: letters, digits, '-', '_' and '.', 1 to 64 characters
  /// @param[in] rateHz  I/O rate [Hz], 1 .. 10000
  /// @param[in] watchdogMs  a client silent for longer than this [ms] has its outputs switched off, 1 .. 60000
  /// @throws IoException if the name, rate or watchdog time is invalid
  /// Real-time safe: no.
  HwServer(IoBoard& board, const std::string& name, double rateHz, double watchdogMs = kDefaultWatchdogMs);

  /// The default client watchdog time [ms] (`rp-hwserver -watchdog MS` changes it).
  static constexpr double kDefaultWatchdogMs = 50.0;
  /// Stops the server if it is running.
  ~HwServer();
  HwServer(const HwServer&) = delete;             ///< not copyable
  HwServer& operator=(const HwServer&) = delete;  ///< not copyable

  /// Creates the shared-memory segment and starts the I/O thread.
  /// @throws IoException if the segment cannot be created (for example another server of this name runs)
  /// Real-time safe: no.
  void start();
  /// Stops the I/O thread, marks the segment stopped and removes it.
  /// Real-time safe: no.
  void stop();

  /// The server name.
  /// Real-time safe: yes.
  const std::string& name() const noexcept { return name_; }
  /// Completed I/O cycles (also after stop()).
  /// Real-time safe: yes.
  std::uint64_t cycles() const noexcept;
  /// Cycles that started after their deadline.
  /// Real-time safe: yes.
  std::uint64_t overruns() const noexcept;
  /// Status of the board in the last cycle (`kOk`, or the first failure of that cycle).
  /// Real-time safe: yes.
  IoStatus boardStatus() const noexcept;
  /// The client watchdog time [ms].
  /// Real-time safe: yes.
  double watchdogMs() const noexcept { return watchdogMs_; }
  /// How many times the watchdog switched off the outputs of a silent client so far.
  /// Real-time safe: yes.
  std::uint64_t watchdogTrips() const noexcept;
  /// The process id of the last client the watchdog cut off, and how long it had been silent [ms]
  /// (both 0 before the first trip); read after `watchdogTrips()` changed, to log it.
  /// @param[out] silenceMs  how long that client had been silent [ms]
  /// @return its process id
  /// Real-time safe: yes.
  int lastWatchdogTrip(double& silenceMs) const noexcept;

 private:
  void run();
  void cycle(bool writeAll);
  void watchClients(std::int64_t now);
  bool ownsOutputThatIsOn(int slot) const noexcept;
  template <typename T>
  bool forceOffIfOrphaned(std::atomic<T>& value, std::atomic<std::int8_t>& owner, T& v) noexcept;
  void reportWrite(std::atomic<std::uint32_t>& done, std::atomic<std::int32_t>& result, std::uint32_t request,
                   IoStatus status) noexcept;

  IoBoard& board_;
  std::string name_;
  double rateHz_;
  double watchdogMs_;
  internal::HwServerShm* shm_ = nullptr;
  int lockFd_ = -1;  // the segment's descriptor, flock'ed while this server runs
  int counts_[5] = {0, 0, 0, 0, 0};
  bool lastDigitalOut_[64] = {};
  double lastAnalogOut_[64] = {};
  IoStatus lastDigitalResult_[64] = {};  // the board's answer to the last write of each line
  IoStatus lastAnalogResult_[64] = {};
  std::uint64_t finalCycles_ = 0, finalOverruns_ = 0, finalTrips_ = 0;  // kept when the segment is gone
  int finalTripPid_ = 0;
  std::int64_t finalTripSilenceNs_ = 0;
  std::atomic<bool> stopRequested_{false};
  std::thread thread_;
};

}  // namespace rp
