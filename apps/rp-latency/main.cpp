// rp-latency: runs an empty ControlProgram on the real clock and prints its wake-up latency in
// cyclictest's terms, so the two can be compared on one machine.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>

#include "rp/core/RoboticPlatform.hpp"
#include "rp/rt/Clock.hpp"
#include "rp/rt/ControlProgram.hpp"

namespace {

class Empty : public rp::ControlProgram {
 public:
  Empty() : rp::ControlProgram("latency") {}
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
  int priority = 27, cpu = -1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* value = i + 1 < argc ? argv[i + 1] : nullptr;
    if (a == "--rate") rate = number(a, value), ++i;
    else if (a == "--duration") duration = number(a, value), ++i;
    else if (a == "--priority") priority = static_cast<int>(number(a, value)), ++i;
    else if (a == "--affinity") cpu = static_cast<int>(number(a, value, true)), ++i;
    else {
      std::cerr << "rp-latency: unknown option '" << a << "'\n" << kUsage;
      return 2;
    }
  }
  Empty loop;
  try {
    loop.setRate(rate);
    loop.setPriority(priority);
    loop.setCpuAffinity(cpu);
  } catch (const std::exception& e) {
    std::cerr << "rp-latency: " << e.what() << "\n";
    return 2;
  }
  loop.setClock(rp::RealClock::instance());
  const auto cycles = static_cast<std::uint64_t>(std::llround(rate * duration));
  loop.setCycleLimit(cycles < 1 ? 1 : cycles);
  std::printf("rp-latency: %g Hz (interval %.0f us) for %g s, %llu cycles\n", rate, 1e6 / rate, duration,
              static_cast<unsigned long long>(cycles));
  std::fflush(stdout);
  loop.start();
  loop.waitUntilStopped();
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
  return 0;
}
