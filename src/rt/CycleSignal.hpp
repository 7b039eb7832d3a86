#pragma once
// The end of every executor's cycle as an event for threads outside the servo loops (the ROS 2
// bridge publishing at the servo rate): a process-wide count of cycles ended, and a futex on it.
// The executors call cycleEnded() after each cycle's phases, before its bookkeeping (logs,
// statistics), so that a waiting thread goes as soon as the state is published; it costs an atomic increment,
// plus one FUTEX_WAKE system call (which never blocks) only while some thread waits.

#include <cstdint>

namespace rp::internal {

/// Loop threads: one executor cycle ended (its programs' state of that cycle is published).
/// Real-time safe: yes (no lock, no allocation; a non-blocking system call while a thread waits).
void cycleEnded() noexcept;

/// The number of executor cycles ended in the process so far.
std::uint64_t cyclesEnded() noexcept;

/// Waits until cyclesEnded() differs from `seen` or `timeoutSeconds` have passed; returns
/// cyclesEnded(). Not for loop threads.
std::uint64_t waitForCycleEnd(std::uint64_t seen, double timeoutSeconds) noexcept;

}  // namespace rp::internal
