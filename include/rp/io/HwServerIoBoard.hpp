#pragma once
/// @file
/// The client side of a hardware server: an `IoBoard` whose lines live in the server's shared memory.

#include <cstdint>
#include <string>

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
class HwServerIoBoard : public IoBoard {
 public:
  /// Attaches to the running server `name`.
  /// @param[in] name  the server's name (`rp-hwserver -name NAME`)
  /// @param[in] staleTimeoutMs  a heartbeat older than this means the server is gone [ms]
  /// @throws IoException if no server of that name exists or its segment is not a hardware-server segment
  /// Real-time safe: no.
  explicit HwServerIoBoard(const std::string& name, int staleTimeoutMs = 500);
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

  /// Checks that the server runs and its board works.
  /// @return `kOk`, `kNotConnected` (server stopped or not responding) or `kDeviceError` (board failure)
  /// Real-time safe: yes.
  IoStatus checkServer() noexcept;
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

  std::string name_;
  int staleTimeoutMs_;
  internal::HwServerShm* shm_ = nullptr;
};

}  // namespace rp
