#pragma once
// Layout of the shared-memory segment between rp-hwserver (HwServer) and its clients
// (HwServerIoBoard). Only lock-free atomics cross the process boundary.

#include <atomic>
#include <cstdint>
#include <string>

#include <time.h>

namespace rp::internal {

constexpr std::uint64_t kHwServerMagic = 0x52504857'53525631ULL;  // "RPHWSRV1"
constexpr std::uint32_t kHwServerVersion = 1;
constexpr int kHwServerMaxLines = 64;  // per kind of line

enum class HwServerState : std::int32_t { kStarting = 0, kRunning = 1, kStopped = 2 };

struct HwServerShm {
  std::uint64_t magic;
  std::uint32_t version;
  std::uint32_t size;
  std::int32_t numDigitalInputs, numDigitalOutputs, numAnalogInputs, numAnalogOutputs, numEncoders;
  double rateHz;
  std::atomic<std::int32_t> serverPid;
  std::atomic<std::int32_t> state;
  std::atomic<std::uint64_t> cycle;         // completed I/O cycles
  std::atomic<std::int64_t> heartbeatNs;    // CLOCK_MONOTONIC at the end of the last cycle
  std::atomic<std::uint64_t> overruns;      // cycles that missed their deadline
  // Board status of the last cycle; the message is published with a sequence lock.
  std::atomic<std::int32_t> boardStatus;    // an rp::IoStatus
  std::atomic<std::uint32_t> messageSeq;
  char message[256];
  std::atomic<std::uint8_t> digitalIn[kHwServerMaxLines];
  std::atomic<std::uint8_t> digitalOut[kHwServerMaxLines];
  std::atomic<double> analogIn[kHwServerMaxLines];
  std::atomic<double> analogOut[kHwServerMaxLines];
  std::atomic<std::int64_t> encoders[kHwServerMaxLines];
};

static_assert(std::atomic<double>::is_always_lock_free && std::atomic<std::int64_t>::is_always_lock_free,
              "the shared-memory protocol needs lock-free atomics");

// CLOCK_MONOTONIC in nanoseconds: the same clock in every process of the machine.
inline std::int64_t monotonicNs() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

inline std::string hwServerShmName(const std::string& name) { return "/rp-hwserver-" + name; }

}  // namespace rp::internal
