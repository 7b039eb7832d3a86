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
class HwServer {
 public:
  /// Creates the server for a board (not yet started).
  /// @param[in] board  the board to serve; must outlive the server; at most 64 lines of each kind are served
  /// @param[in] name  server name: letters, digits, '-', '_' and '.', 1 to 64 characters
  /// @param[in] rateHz  I/O rate [Hz], 1 .. 10000
  /// @throws IoException if the name or rate is invalid
  /// Real-time safe: no.
  HwServer(IoBoard& board, const std::string& name, double rateHz);
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

 private:
  void run();
  void cycle(bool writeAll);

  IoBoard& board_;
  std::string name_;
  double rateHz_;
  internal::HwServerShm* shm_ = nullptr;
  int counts_[5] = {0, 0, 0, 0, 0};
  bool lastDigitalOut_[64] = {};
  double lastAnalogOut_[64] = {};
  std::uint64_t finalCycles_ = 0, finalOverruns_ = 0;  // kept when the segment is gone
  std::atomic<bool> stopRequested_{false};
  std::thread thread_;
};

}  // namespace rp
