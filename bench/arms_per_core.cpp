// How many simulated Puma 560 arms one core runs at 1 kHz in real time, in both thread modes:
// `shared` (the default: one executor thread steps every arm in its read, control and write
// phases) and `own` (a thread per arm, rp.cfg `thread own`); --mode shared|own|both (default both)
// chooses, each mode searched in turn in the same run.
//
// The whole process is pinned to one CPU (--cpu, default 1), so every servo thread shares that
// core. Each arm is a Puma560 in simulation mode on the real clock: its ControlProgram (SCHED_FIFO
// priority 27 when permitted) runs the full servo cycle every 1 ms - a
// setpoint from a trajectory generator (a slow sinusoid on joints 1-3), DefaultPositionControl
// with gravity compensation, the limit checks, the forward dynamics and integration of the
// simulation step, the lock-free state publication. For a number of arms N the program runs all
// N for --seconds (default 5) after a one-second warm-up and counts the deadlines missed
// (a cycle that ended after its next deadline) in that window. N doubles from --start (default
// 16) until a deadline is missed, then a bisection finds the largest N with zero overruns (to
// within --resolution arms, default 4). A count passes when one of --tries trials (default 3)
// has no overrun (a shared machine stalls now and then; a count beyond capacity fails every
// trial). Output: one line per trial, then the result
//   arms_per_core N  cycle_p50_us A  cycle_p99_us X  wakeup_p99_us Y  wakeup_max_us Z
//   cpu_us_per_arm_cycle C  scheduling S
// where cycle_p50/p99 are the largest of the arms' median / 99th-percentile computation times
// (one servo cycle, timed by its ControlProgram), the wake-up figures how late the threads ran
// after their deadlines (the last arm of a period waits for the others: this is what runs out at
// the limit), and cpu_us_per_arm_cycle the process's CPU time per arm cycle (cycle, thread
// switch and timer wake-up).
//
// Each mode's result line begins `arms_per_core MODE N ...`.
//
// --criterion strict|cpu (default strict) is what a count must meet. strict: no overrun in the
// window, as above. cpu: the arms' CPU fits the period, whatever the machine does to the wake-ups:
// the process's CPU time per period (N x cpu_us_per_arm_cycle) is at most 90 % of the period and
// the 99th percentile of the executors' cycle time (from the wake-up to the end of the cycle's last
// phase) is under the period, with no arm error. On a virtual machine whose timer wake-ups are
// late by milliseconds now and then (rp-latency shows it without any arm), strict finds no count
// at all, and cpu says what one core computes at 1 kHz; on a machine fit for real time they agree.
// Each trial line also gives exec_cycle_p99_us, that percentile.
//
// --mode spread (not part of `both`): one executor spread over CPUs 0 and 1
// (ControlProgram::setExecutorCpus()), the process not pinned: arms per two cores, in one cycle.
//
// --integrator rk4|euler (default rk4, the simulation's default) chooses how each simulated arm
// integrates its dynamics (rp.cfg's `integrator`, written for the arms into a configuration file
// in /tmp as the section of class Puma560): RK4 takes four forward-dynamics evaluations per step,
// semi-implicit Euler one.
//
// --mode cost (not part of `both`): the CPU per arm-cycle as the count grows, without wake-ups or
// deadlines: the arms on the simulated clock (one executor stepping them as fast as it can), each
// count from --start doubling to --max (default 512) for --seconds, one line each
//   cost N  cpu_us_per_arm_cycle C  heap_huge_mb H
// What grows with N here is the memory the arms' cycles touch outgrowing the caches and the TLB.
//
// --huge-pages: the heap in transparent 2 MB pages. The program runs itself again with glibc's
// tunable GLIBC_TUNABLES=glibc.malloc.hugetlb=1 (glibc 2.35 or later; the kernel's
// /sys/kernel/mm/transparent_hugepage/enabled must be `madvise` or `always`), the setting a
// deployment with hundreds of arms would make: hundreds of arms' objects span thousands of 4 KB
// pages, more than the data TLB holds (docs/realtime.md, "Hundreds of arms in 2 MB pages").
// Each trial and cost line also gives heap_huge_mb, the process's anonymous memory in 2 MB pages
// (/proc/self/smaps_rollup, AnonHugePages) at the end of its window: 0 without the setting.
//
// Usage: arms_per_core [--mode M] [--integrator I] [--criterion C] [--cpu C] [--seconds S] [--start N] [--max N] [--resolution R] [--tries T] [--huge-pages]
#include <sched.h>
#include <unistd.h>
#include <sys/resource.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "rp/RoboticPlatform.hpp"

namespace {

using namespace rp;

// A slow sinusoid (0.1 rad, 0.5 Hz) about the home position on joints 1-3, with its velocity.
class Sinusoid : public TrajectoryGenerator {
 public:
  explicit Sinusoid(const JointVector& home) : home_(home) {}
  ~Sinusoid() override { releaseFromManipulators(); }
  bool getCurrentSetpoint(double time, Setpoint& sp) override {
    if (t0_ < 0) t0_ = time;
    const double w = 2 * 3.14159265358979 * 0.5, t = time - t0_;
    sp.position = home_;
    sp.velocity.setZero();
    for (int i = 0; i < 3; ++i) {
      sp.position(i) += 0.1 * std::sin(w * t);
      sp.velocity(i) = 0.1 * w * std::cos(w * t);
    }
    return true;
  }

 private:
  JointVector home_;
  double t0_ = -1;
};

struct Trial {
  int arms = 0;
  std::uint64_t overruns = 0, cycles = 0;
  double cycleP50 = 0, cycleP99 = 0, wakeupP99 = 0, wakeupMax = 0;
  double executorCycleP99 = 0;  // the largest of the executors' cycle-time p99 [us]
  double cpuPerCycle = 0;  // process CPU time (user + system) per arm cycle in the window [us]
  bool realTime = false;
  bool errors = false;
  long hugeMb = 0;  // anonymous memory in 2 MB pages at the end of the window [MB]
};

// The process's anonymous memory in transparent huge pages [MB] (0 if it cannot be read).
long hugePagesMb() {
  std::FILE* f = std::fopen("/proc/self/smaps_rollup", "r");
  if (f == nullptr) return 0;
  char line[256];
  long kb = 0;
  while (std::fgets(line, sizeof line, f) != nullptr)
    if (std::sscanf(line, "AnonHugePages: %ld kB", &kb) == 1) break;
  std::fclose(f);
  return kb / 1024;
}

double cpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

Trial run(int n, double seconds) {
  Trial result;
  result.arms = n;
  std::vector<std::unique_ptr<Puma560>> arms;
  std::vector<std::unique_ptr<Sinusoid>> generators;
  arms.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    arms.push_back(std::make_unique<Puma560>("arm" + std::to_string(i)));
    generators.push_back(std::make_unique<Sinusoid>(arms.back()->getModel().getHomePosition()));
    arms.back()->setTrajectoryGenerator(*generators.back());
  }
  std::this_thread::sleep_for(std::chrono::seconds(1));  // warm-up, not counted
  std::vector<std::uint64_t> overruns0, cycles0;
  for (const auto& a : arms) {
    const ControlStatistics s = a->getStatistics();
    overruns0.push_back(s.overruns);
    cycles0.push_back(s.cycles);
  }
  const double cpu0 = cpuSeconds();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  const double cpu1 = cpuSeconds();
  result.hugeMb = hugePagesMb();
  for (std::size_t i = 0; i < arms.size(); ++i) {
    const ControlStatistics s = arms[i]->getStatistics();
    result.overruns += s.overruns - overruns0[i];
    result.cycles += s.cycles - cycles0[i];
    result.cycleP50 = std::max(result.cycleP50, s.computationTime.p50);
    result.cycleP99 = std::max(result.cycleP99, s.computationTime.p99);
    result.wakeupP99 = std::max(result.wakeupP99, s.wakeupLatency.p99);
    result.wakeupMax = std::max(result.wakeupMax, s.wakeupLatency.max);
    result.realTime = s.realTimeScheduling;
    if (arms[i]->getErrorCode() != 0) {
      result.errors = true;
      std::fprintf(stderr, "arm %zu: %s\n", i, arms[i]->getErrorStatus().message.c_str());
    }
  }
  result.cpuPerCycle = result.cycles > 0 ? 1e6 * (cpu1 - cpu0) / static_cast<double>(result.cycles) : 0;
  for (const ExecutorStatistics& e : ControlProgram::getExecutorStatistics())
    if (!e.programs.empty()) result.executorCycleP99 = std::max(result.executorCycleP99, e.cycleTime.p99);
  generators.clear();
  arms.clear();
  return result;
}

void print(const Trial& t, double seconds) {
  const double expected = t.arms * seconds * 1000.0;
  std::printf("N %4d  overruns %6llu  cycles %.1f %%  cycle_p50_us %5.1f  cycle_p99_us %6.1f  wakeup_p99_us %7.1f  "
              "wakeup_max_us %8.1f  exec_cycle_p99_us %7.1f  cpu_us_per_arm_cycle %5.2f  heap_huge_mb %ld%s\n",
              t.arms, static_cast<unsigned long long>(t.overruns), 100.0 * static_cast<double>(t.cycles) / expected,
              t.cycleP50, t.cycleP99, t.wakeupP99, t.wakeupMax, t.executorCycleP99, t.cpuPerCycle, t.hugeMb,
              t.errors ? "  (arm errors)" : "");
  std::fflush(stdout);
}

bool cpuCriterion = false;  // --criterion cpu

bool good(const Trial& t) {
  if (t.errors) return false;
  if (!cpuCriterion) return t.overruns == 0;
  constexpr double kPeriodUs = 1000.0;
  return t.arms * t.cpuPerCycle <= 0.9 * kPeriodUs && t.executorCycleP99 < kPeriodUs;
}

// A count passes if one of `tries` trials has no overrun: on a shared machine a single trial can
// miss a deadline from a stall outside the process (the host, another process's interrupt), while
// a count beyond the core's capacity misses deadlines every time.
Trial attempt(int n, double seconds, int tries) {
  Trial t;
  for (int k = 0; k < tries; ++k) {
    t = run(n, seconds);
    print(t, seconds);
    if (good(t)) break;
  }
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  int cpu = 1, start = 16, max = 4096, resolution = 4, tries = 3;
  bool maxGiven = false, hugePages = false;
  double seconds = 5;
  std::string mode = "both", integrator = "rk4";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "arms_per_core: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--mode") {
      mode = value();
      if (mode != "shared" && mode != "own" && mode != "both" && mode != "spread" && mode != "cost") {
        std::fprintf(stderr, "arms_per_core: --mode must be shared, own, both, spread or cost\n");
        return 2;
      }
    } else if (a == "--integrator") {
      integrator = value();
      if (integrator != "rk4" && integrator != "euler") {
        std::fprintf(stderr, "arms_per_core: --integrator must be rk4 or euler\n");
        return 2;
      }
    } else if (a == "--criterion") {
      const std::string c = value();
      if (c != "strict" && c != "cpu") {
        std::fprintf(stderr, "arms_per_core: --criterion must be strict or cpu\n");
        return 2;
      }
      cpuCriterion = c == "cpu";
    } else if (a == "--cpu") {
      cpu = std::atoi(value());
    } else if (a == "--seconds") {
      seconds = std::atof(value());
    } else if (a == "--start") {
      start = std::atoi(value());
    } else if (a == "--max") {
      max = std::atoi(value());
      maxGiven = true;
    } else if (a == "--tries") {
      tries = std::max(1, std::atoi(value()));
    } else if (a == "--resolution") {
      resolution = std::max(1, std::atoi(value()));
    } else if (a == "--huge-pages") {
      hugePages = true;
    } else {
      std::fprintf(stderr,
                   "usage: arms_per_core [--mode shared|own|both|spread|cost] [--integrator rk4|euler] [--criterion strict|cpu] [--cpu C] [--seconds S] [--start N] [--max N] [--resolution R] [--tries T] [--huge-pages]\n");
      return 2;
    }
  }
  // --huge-pages: glibc reads its tunables when the program starts, so the program starts again
  // with the tunable added (once: the second run finds it set).
  if (const char* t = std::getenv("GLIBC_TUNABLES"); hugePages && (t == nullptr || std::strstr(t, "glibc.malloc.hugetlb") == nullptr)) {
    const std::string tunables = (t != nullptr && *t != '\0' ? std::string(t) + ":" : std::string()) + "glibc.malloc.hugetlb=1";
    setenv("GLIBC_TUNABLES", tunables.c_str(), 1);
    execv("/proc/self/exe", argv);
    std::fprintf(stderr, "arms_per_core: cannot run again with GLIBC_TUNABLES=%s: %s\n", tunables.c_str(), std::strerror(errno));
    return 1;
  }
  if (start < 1 || seconds <= 0) {
    std::fprintf(stderr, "arms_per_core: --start must be >= 1 and --seconds > 0\n");
    return 2;
  }
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (sched_setaffinity(0, sizeof set, &set) != 0) {
    std::fprintf(stderr, "arms_per_core: cannot pin to CPU %d: %s\n", cpu, std::strerror(errno));
    return 1;
  }
  RoboticPlatform::setSimulationModeOn();  // real clock (the default), simulated arms
  // The arms' class section: every Puma 560 without a section of its own (arm0, arm1, ...) takes
  // the chosen integrator from it.
  const std::string config = "/tmp/arms_per_core_" + std::to_string(getpid()) + ".cfg";
  if (FILE* f = std::fopen(config.c_str(), "w")) {
    std::fprintf(f, "[Puma560]\nclass Puma560\nintegrator %s\n", integrator.c_str());
    std::fclose(f);
  } else {
    std::fprintf(stderr, "arms_per_core: cannot write %s: %s\n", config.c_str(), std::strerror(errno));
    return 1;
  }
  RoboticPlatform::setConfigurationFileName(config);
  RoboticPlatform::loadConfiguration();

  if (mode == "cost") {
    RoboticPlatform::useSimulatedClock();
    if (!maxGiven) max = 512;
    std::printf("mode cost: simulated Puma 560 arms (integrator %s) on the simulated clock on CPU %d, %.1f s each\n",
                integrator.c_str(), cpu, seconds);
    for (int n = start; n <= max; n *= 2) {
      const Trial t = run(n, seconds);
      std::printf("cost %4d  cpu_us_per_arm_cycle %6.2f  heap_huge_mb %ld%s\n", n, t.cpuPerCycle, t.hugeMb,
                  t.errors ? "  (arm errors)" : "");
      std::fflush(stdout);
    }
    std::remove(config.c_str());
    return 0;
  }
  std::vector<std::string> modes;
  if (mode == "both" || mode == "shared") modes.push_back("shared");
  if (mode == "both" || mode == "own") modes.push_back("own");
  if (mode == "spread") {
    modes.push_back("spread");
    CPU_ZERO(&set);
    CPU_SET(0, &set);
    CPU_SET(1, &set);
    if (sched_setaffinity(0, sizeof set, &set) != 0) {
      std::fprintf(stderr, "arms_per_core: cannot use CPUs 0 and 1: %s\n", std::strerror(errno));
      return 1;
    }
    ControlProgram::setExecutorCpus({0, 1});
  }
  for (const std::string& m : modes) {
    ControlProgram::setDefaultThreadMode(m == "own" ? ThreadMode::Own : ThreadMode::Shared);  // spread: shared
    if (m == "spread")
      std::printf("mode spread: simulated Puma 560 arms (integrator %s) at 1 kHz, one executor on CPUs 0 and 1, %.1f s per trial\n",
                  integrator.c_str(), seconds);
    else
      std::printf("mode %s: simulated Puma 560 arms (integrator %s) at 1 kHz on CPU %d, %.1f s per trial\n", m.c_str(),
                  integrator.c_str(), cpu, seconds);
    Trial best;
    int bad = 0;
    for (int n = start; n <= max; n *= 2) {
      const Trial t = attempt(n, seconds, tries);
      if (!good(t)) {
        bad = n;
        break;
      }
      best = t;
    }
    int hi = bad;  // the smallest count that failed
    if (bad == 0) {
      std::printf("every count up to --max %d passed\n", max);
    } else {
      int lo = best.arms;  // lo good (0: none), hi bad
      while (hi - lo > resolution) {
        const int mid = lo + (hi - lo) / 2;
        const Trial t = attempt(mid, seconds, tries);
        if (good(t)) {
          lo = mid;
          best = t;
        } else {
          hi = mid;
        }
      }
    }
    if (best.arms == 0) {
      std::printf("arms_per_core %s 0 (even %d arms failed: %s)\n", m.c_str(), hi,
                  cpuCriterion ? "their CPU does not fit the period" : "they missed deadlines");
      continue;
    }
    std::printf("arms_per_core %s %d  cycle_p50_us %.1f  cycle_p99_us %.1f  wakeup_p99_us %.1f  wakeup_max_us %.1f  "
                "exec_cycle_p99_us %.1f  cpu_us_per_arm_cycle %.2f  scheduling %s  criterion %s\n",
                m.c_str(), best.arms, best.cycleP50, best.cycleP99, best.wakeupP99, best.wakeupMax,
                best.executorCycleP99, best.cpuPerCycle, best.realTime ? "SCHED_FIFO" : "normal",
                cpuCriterion ? "cpu" : "strict");
  }
  std::remove(config.c_str());
  return 0;
}
