// The single-producer ring buffer that carries one control program's log samples to a LogWriter.
#pragma once
#include <atomic>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rp/rt/LogWriter.hpp"

namespace rp {

namespace internal {
// Appends `v` to a CSV line as the shortest text that reads back to the same double (the log
// file's format; QMotor's log download uses it too).
inline void appendNumber(std::string& out, double v) {
  char buf[32];
  auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, ec == std::errc() ? ptr : buf);
}
}  // namespace internal

struct LogWriter::Channel {
  Channel(std::string programName, std::vector<std::string> columnNames, std::size_t capacitySamples)
      : program(std::move(programName)),
        columns(std::move(columnNames)),
        width(columns.size()),
        capacity(capacitySamples < 2 ? 2 : capacitySamples),
        data(new double[capacity * (width + 1)]) {}

  // Producer (the control program's thread): a slot of 1 + width doubles, or nullptr when full.
  double* beginPush() noexcept {
    const std::size_t h = head.load(std::memory_order_relaxed);
    if (h - tail.load(std::memory_order_acquire) >= capacity) {
      lost.fetch_add(1, std::memory_order_relaxed);
      return nullptr;
    }
    return &data[(h % capacity) * (width + 1)];
  }
  void commitPush() noexcept { head.store(head.load(std::memory_order_relaxed) + 1, std::memory_order_release); }

  // Consumer (the writer's thread): the oldest sample, or nullptr.
  const double* front() const noexcept {
    const std::size_t t = tail.load(std::memory_order_relaxed);
    if (t == head.load(std::memory_order_acquire)) return nullptr;
    return &data[(t % capacity) * (width + 1)];
  }
  void pop() noexcept { tail.store(tail.load(std::memory_order_relaxed) + 1, std::memory_order_release); }

  std::string program;               // renamed by the writer if another program has the name
  std::vector<std::string> columns;  // full column names, e.g. "leader.q[0]"
  const std::size_t width;
  const std::size_t capacity;
  std::unique_ptr<double[]> data;
  std::atomic<std::size_t> head{0}, tail{0};
  std::atomic<std::uint64_t> lost{0};
  std::atomic<bool> finished{false};

  // Writer-side bookkeeping.
  std::size_t firstColumn = 0;
  double lastTime = 0;
  bool any = false;
};

}  // namespace rp
