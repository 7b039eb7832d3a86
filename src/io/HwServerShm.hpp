#pragma once
// Layout of the shared-memory segment between rp-hwserver (HwServer) and its clients
// (HwServerIoBoard). Only lock-free atomics cross the process boundary.

#include <atomic>
#include <cstdint>
#include <string>

#include <time.h>

namespace rp::internal {

constexpr std::uint64_t kHwServerMagic = 0x52504857'53525631ULL;  // "RPHWSRV1"
constexpr std::uint32_t kHwServerVersion = 3;
constexpr int kHwServerMaxLines = 64;    // per kind of line
constexpr int kHwServerMaxClients = 16;  // attached HwServerIoBoard objects at a time

enum class HwServerState : std::int32_t { kStarting = 0, kRunning = 1, kStopped = 2 };

// Life of a client slot. A client claims a free slot (kFree -> kClaiming, fills pid and
// heartbeat, -> kAttached). Its destructor sets kClosed; the server's watchdog sets kExpired when
// the client fell silent while one of its outputs was on. The server switches off every output a
// closed or expired slot owns, then frees a closed slot at once and an expired one when its
// process is gone (until then the silent client's writes are refused).
enum class HwClientState : std::int32_t { kFree = 0, kClaiming = 1, kAttached = 2, kClosed = 3, kExpired = 4 };

struct HwClientSlot {
  std::atomic<std::int32_t> state;        // an HwClientState
  std::atomic<std::int32_t> pid;          // the client's process
  std::atomic<std::int64_t> heartbeatNs;  // CLOCK_MONOTONIC of the client's last operation (or keep-alive)
};

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
  // Client watchdog: every output line is owned by the client that wrote it last (slot + 1, 0 =
  // nobody); a silent, closed or dead owner's lines are switched off by the server.
  std::atomic<std::int64_t> watchdogNs;   // a client silent for longer than this is cut off
  std::atomic<std::uint64_t> watchdogTrips;  // clients cut off so far
  std::atomic<std::int32_t> lastTripPid;     // the last one's process and silence
  std::atomic<std::int64_t> lastTripSilenceNs;
  HwClientSlot clients[kHwServerMaxClients];
  std::atomic<std::int8_t> digitalOutOwner[kHwServerMaxLines];
  std::atomic<std::int8_t> analogOutOwner[kHwServerMaxLines];
  // What the server last wrote to the board and the board accepted (the real output state).
  std::atomic<std::uint8_t> digitalOutApplied[kHwServerMaxLines];
  std::atomic<double> analogOutApplied[kHwServerMaxLines];
  // Acknowledgement of writes: a client counts up a line's request number after storing the value;
  // the server, after handling that request, stores its number in ...Done and the board's answer
  // (an rp::IoStatus) in ...Result.
  std::atomic<std::uint32_t> digitalOutRequest[kHwServerMaxLines];
  std::atomic<std::uint32_t> digitalOutDone[kHwServerMaxLines];
  std::atomic<std::int32_t> digitalOutResult[kHwServerMaxLines];
  std::atomic<std::uint32_t> analogOutRequest[kHwServerMaxLines];
  std::atomic<std::uint32_t> analogOutDone[kHwServerMaxLines];
  std::atomic<std::int32_t> analogOutResult[kHwServerMaxLines];
  std::atomic<std::uint32_t> writeMessageSeq;  // the board's message for the last refused write (sequence lock)
  char writeMessage[256];
  // The inputs of one cycle are one sample: inputSeq is odd while the server stores them, and
  // inputTimeNs (CLOCK_MONOTONIC) says when the board's reads for them had returned.
  std::atomic<std::uint32_t> inputSeq;
  std::atomic<std::int64_t> inputTimeNs;
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
