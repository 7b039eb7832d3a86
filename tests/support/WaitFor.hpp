// Shared by the threaded tests: polls a condition another thread makes true.
#pragma once

#include <chrono>
#include <thread>

namespace rp::test {

// Polls `done` every millisecond for up to `seconds` (a loaded machine is slow, never wrong);
// returns whether it became true.
template <typename F>
bool waitFor(F done, double seconds = 10) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

}  // namespace rp::test
