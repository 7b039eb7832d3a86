// rp-latency: runs an empty ControlProgram on the real clock and prints its wake-up latency in
// cyclictest's terms, so the two can be compared on one machine.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <chrono>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "rp/core/RoboticPlatform.hpp"
#include "rp/rt/Clock.hpp"
#include "rp/rt/ControlProgram.hpp"

namespace {

class Empty : public rp::ControlProgram {
 public:
  explicit Empty(const std::string& name) : rp::ControlProgram(name) {}
  ~Empty() override { stop(); }

 protected:
  void control() override {}
};

const char* kUsage =
    "rp-latency options:\n"
    "  --rate HZ        loop rate (default 1000)\n"
    "  --duration S     how long to run (default 10)\n"
    "  --priority P     SCHED_FIFO priority 1..99 (default 27, as in the paper; cyclictest -p P)\n"
    "  --affinity CPU   pin the loop thread to CPU (cyclictest -a CPU; default: not pinned)\n"
    "  --programs N     N empty programs stepped by one executor thread (default 1); prints the\n"
    "                   executor's cycle time and each program's computation time\n"
    "  --own            with --programs: a thread of its own for each program instead\n"
    "Compare with: cyclictest -m -p P -i 1000000/HZ -l HZ*S [-a CPU] (interval in us), or run\n"
    "bench/latency_vs_cyclictest.sh, which runs both and prints their p50, p99 and ratio\n";

double number(const std::string& option, const char* text, bool zeroAllowed = false) {
  char* end = nullptr;
  const double v = text ? std::strtod(text, &end) : NAN;
  if (!text || *end != '\0' || !std::isfinite(v) || v < 0 || (v == 0 && !zeroAllowed)) {
    std::cerr << "rp-latency: " << option << (zeroAllowed ? " needs a number >= 0\n" : " needs a positive number\n")
              << kUsage;
    std::exit(2);
  }
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  rp::RoboticPlatform::setGuiOff();
  rp::RoboticPlatform::init(argc, argv, kUsage);
  double rate = 1000, duration = 10;
  int priority = 27, cpu = -1, programs = 1;
  bool own = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* value = i + 1 < argc ? argv[i + 1] : nullptr;
    if (a == "--rate") rate = number(a, value), ++i;
    else if (a == "--duration") duration = number(a, value), ++i;
    else if (a == "--priority") priority = static_cast<int>(number(a, value)), ++i;
    else if (a == "--affinity") cpu = static_cast<int>(number(a, value, true)), ++i;
    else if (a == "--programs") programs = static_cast<int>(number(a, value)), ++i;
    else if (a == "--own") own = true;
    else {
      std::cerr << "rp-latency: unknown option '" << a << "'\n" << kUsage;
      return 2;
    }
  }
  if (programs > 10000) {
    std::cerr << "rp-latency: --programs must be 1..10000\n";
    return 2;
  }
  std::vector<std::unique_ptr<Empty>> loops;
  const auto cycles = static_cast<std::uint64_t>(std::llround(rate * duration));
  for (int k = 0; k < programs; ++k) {
    loops.push_back(std::make_unique<Empty>(k == 0 ? "latency" : "latency" + std::to_string(k)));
    Empty& loop = *loops.back();
    try {
      loop.setRate(rate);
      loop.setPriority(priority);
      loop.setCpuAffinity(cpu);
    } catch (const std::exception& e) {
      std::cerr << "rp-latency: " << e.what() << "\n";
      return 2;
    }
    loop.setThreadMode(own ? rp::ThreadMode::Own : rp::ThreadMode::Shared);
    loop.setClock(rp::RealClock::instance());
    loop.setCycleLimit(cycles < 1 ? 1 : cycles);
  }
  Empty& loop = *loops.front();
  std::printf("rp-latency: %g Hz (interval %.0f us) for %g s, %llu cycles\n", rate, 1e6 / rate, duration,
              static_cast<unsigned long long>(cycles));
  std::fflush(stdout);
  for (auto& l : loops) l->start();
  // The executors' statistics while they run (an executor is gone once its programs have stopped).
  std::vector<rp::ExecutorStatistics> executors;
  while (loop.getCycleCount() + 2 < cycles) {
    executors = rp::ControlProgram::getExecutorStatistics();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (auto& l : loops) l->waitUntilStopped();
  const rp::ControlStatistics s = loop.getStatistics();
  const rp::LatencyStatistics& l = s.wakeupLatency;
  std::printf("scheduling: %s\n", s.realTimeScheduling ? "SCHED_FIFO" : "normal (no permission for SCHED_FIFO)");
  // cyclictest's summary line: T: thread (pid) P: priority I: interval [us] C: cycles, then
  // Min, Avg, Max [us] (cyclictest's "Act", the latest value, has no meaning after the run).
  std::printf("T: 0 (%5d) P:%2d I:%.0f C:%8llu Min:%7.0f Avg:%5.0f Max:%8.0f\n", static_cast<int>(getpid()),
              s.realTimeScheduling ? priority : 0, 1e6 / rate, static_cast<unsigned long long>(s.cycles), l.min,
              l.mean, l.max);
  std::printf("wake-up latency [us]: min %.1f  p50 %.1f  p99 %.1f  max %.1f  mean %.2f\n", l.min, l.p50, l.p99, l.max,
              l.mean);
  std::printf("overruns: %llu\n", static_cast<unsigned long long>(s.overruns));
  std::printf("computation [us]: mean %.2f  max %.1f\n", s.computationTime.mean, s.computationTime.max);
  if (programs > 1) {
    for (const auto& e : executors) {
      if (e.programs.empty() || e.programs.front().rfind("latency", 0) != 0) continue;
      std::printf("executor (%zu program%s%s): cycles %llu  overruns %llu  wake-up p99 %.1f us  cycle time [us]: p50 %.1f  "
                  "p99 %.1f  max %.1f%s%s\n",
                  e.programs.size(), e.programs.size() == 1 ? "" : "s", e.ownThread ? ", own thread" : "",
                  static_cast<unsigned long long>(e.cycles), static_cast<unsigned long long>(e.overruns),
                  e.wakeupLatency.p99, e.cycleTime.p50, e.cycleTime.p99, e.cycleTime.max,
                  e.lastOverrunProgram.empty() ? "" : "  last overrun: ", e.lastOverrunProgram.c_str());
    }
    for (const auto& l : loops) {
      const rp::ControlStatistics p = l->getStatistics();
      std::printf("program %s: computation [us]: p50 %.2f  p99 %.2f  max %.1f  overruns %llu\n", l->getProgramName().c_str(),
                  p.computationTime.p50, p.computationTime.p99, p.computationTime.max,
                  static_cast<unsigned long long>(p.overruns));
    }
  }
  return 0;
}
