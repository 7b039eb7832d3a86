// ControlProgram: the periodic loop, its statistics, log sampling and tunable parameters.
#include "rp/rt/ControlProgram.hpp"

#include <pthread.h>
#include <fcntl.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "../core/ShortNumber.hpp"
#include "CycleSignal.hpp"
#include "LogChannel.hpp"
#include "Ticks.hpp"
#include "rp/core/Configuration.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/core/RoboticPlatform.hpp"
#include "rp/rt/Clock.hpp"
#include "rp/rt/LogWriter.hpp"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define RP_UNDER_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define RP_UNDER_SANITIZER 1
#endif
#endif

namespace rp {

namespace internal {

void ensureShutdownWatcher();

namespace {

constexpr double kMinRate = 1;  // Hz: the lowest rate setRate() accepts

constexpr std::size_t kBins = 10000;  // 1 µs histogram bins; the last one holds everything above

// Durations in nanoseconds: min, max, sum and a 1 µs histogram, written by one thread.
struct DurationStats {
  std::atomic<std::uint64_t> count{0}, sum{0}, min{std::numeric_limits<std::uint64_t>::max()}, max{0};
  std::unique_ptr<std::atomic<std::uint32_t>[]> bins{new std::atomic<std::uint32_t>[kBins + 1]};
  DurationStats() { reset(); }
  void reset() {
    count = 0;
    sum = 0;
    min = std::numeric_limits<std::uint64_t>::max();
    max = 0;
    for (std::size_t i = 0; i <= kBins; ++i) bins[i].store(0, std::memory_order_relaxed);
  }
  void add(std::int64_t ns) noexcept {
    const auto v = static_cast<std::uint64_t>(ns < 0 ? 0 : ns);
    count.store(count.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    sum.store(sum.load(std::memory_order_relaxed) + v, std::memory_order_relaxed);
    if (v < min.load(std::memory_order_relaxed)) min.store(v, std::memory_order_relaxed);
    if (v > max.load(std::memory_order_relaxed)) max.store(v, std::memory_order_relaxed);
    const std::size_t bin = std::min<std::uint64_t>(v / 1000, kBins);
    bins[bin].store(bins[bin].load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }
  LatencyStatistics summary() const {
    LatencyStatistics s;
    s.count = count.load();
    if (s.count == 0) return s;
    s.min = static_cast<double>(min.load()) / 1000.0;
    s.max = static_cast<double>(max.load()) / 1000.0;
    s.mean = static_cast<double>(sum.load()) / static_cast<double>(s.count) / 1000.0;
    auto percentile = [&](double p) {
      const auto target = static_cast<std::uint64_t>(std::ceil(p * static_cast<double>(s.count)));
      std::uint64_t seen = 0;
      for (std::size_t i = 0; i <= kBins; ++i) {
        seen += bins[i].load(std::memory_order_relaxed);
        if (seen >= target) return std::clamp(static_cast<double>(i) + 0.5, s.min, s.max);  // bin middle
      }
      return s.max;
    };
    s.p50 = percentile(0.50);
    s.p99 = percentile(0.99);
    return s;
  }
};

std::mutex& programsMutex() {
  static std::mutex* m = new std::mutex;
  return *m;
}
std::vector<ControlProgram*>& programs() {
  static auto* v = new std::vector<ControlProgram*>;
  return *v;
}

std::atomic<bool> schedulingWarned{false}, affinityWarned{false};
thread_local const void* currentLoop = nullptr;  // the program whose loop runs in this thread
std::once_flag memoryLocked, cpuLatencySet;

}  // namespace

// What cyclictest does for its measuring thread, each when allowed, each refusal said once per
// process: lock all memory (MCL_FUTURE: the heap and stacks to come as well), keep the CPUs out
// of deep idle states (0 us in /dev/cpu_dma_latency, held while the process lives), SCHED_FIFO at
// the priority, the CPU affinity if one was set; and always: a timer slack of 1 ns (a thread with
// normal scheduling would otherwise wake up to 50 us late) and a touched stack.
bool setUpRealTime(int priority, int cpu) {
#ifndef RP_UNDER_SANITIZER
  std::call_once(internal::memoryLocked, [] {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
      std::fprintf(stderr, "rp: mlockall failed (%s): memory may be paged out\n", std::strerror(errno));
  });
#endif
  std::call_once(internal::cpuLatencySet, [] {
    // The PM QoS request lasts as long as the file stays open: never closed.
    const int fd = open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
    const std::int32_t zero = 0;
    if (fd < 0 || write(fd, &zero, sizeof zero) != static_cast<ssize_t>(sizeof zero)) {
      std::fprintf(stderr, "rp: cannot set /dev/cpu_dma_latency to 0 (%s): CPUs may wake slowly from idle\n",
                   std::strerror(errno));
      if (fd >= 0) close(fd);
    }
  });
  prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  if (cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(static_cast<unsigned>(cpu), &set);
    const int err = cpu < CPU_SETSIZE ? pthread_setaffinity_np(pthread_self(), sizeof set, &set) : EINVAL;
    if (err != 0 && !internal::affinityWarned.exchange(true))
      std::fprintf(stderr, "rp: cannot pin the control loop to CPU %d (%s): it runs unpinned\n", cpu,
                   std::strerror(err));
  }
  sched_param sp{};
  sp.sched_priority = priority;
  const int err = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  if (err != 0 && !internal::schedulingWarned.exchange(true))
    std::fprintf(stderr,
                 "rp: cannot use SCHED_FIFO priority %d (%s): control loops run with normal scheduling\n",
                 priority, std::strerror(err));
  // Touch the stack the loop will use so the first cycles do not page-fault.
  volatile char stack[64 * 1024];
  for (std::size_t i = 0; i < sizeof stack; i += 4096) stack[i] = 0;
  return err == 0;
}

}  // namespace internal

// The name of value `i` of log variable `v`: `program.name` or `program.name[i]` (the log's
// column), or without the program `name` / `name[i]`.
namespace {
std::string valueName(const std::string& program, const LogVariableInfo& v, std::size_t i) {
  std::string column = program;
  if (!column.empty()) column += '.';
  column += v.name;
  if (v.vector) {
    column += '[';
    column += std::to_string(i);
    column += ']';
  }
  return column;
}
}  // namespace

struct ControlProgram::Impl {
  explicit Impl(ControlProgram& p) : self(p) {}
  ControlProgram& self;

  // What the executor reads and writes of the program every cycle, together in the first cache
  // lines: one executor steps hundreds of programs, and each line of a program it touches is one
  // more to fetch per program and cycle.
  // Loop thread only:
  bool entered = false;          // enterControl() ran
  bool joining = false;          // entered in the current cycle
  std::uint64_t startTick = 0;   // simulated clock: the first tick it may run
  std::uint64_t k = 0;           // cycles run in this run
  std::int64_t cycleTicks = 0;   // computation time in the current cycle [internal::ticks()]
  std::uint64_t nextTick = 0;    // simulated clock: the tick after the last one run (see firstSimulatedTick())
  std::uint64_t cycleLimit = 0;
  // Cycle state, read by other threads too.
  std::atomic<bool> stopRequested{false};
  std::atomic<bool> loopEnded{false};  // exitControl() ran (the executor no longer steps it)
  std::atomic<bool> parametersChanged{false};  // a parameter's dirty flag may be set
  std::atomic<double> time{0};
  std::atomic<std::uint64_t> cycles{0};
  std::atomic<std::uint64_t> overruns{0};
  std::atomic<std::uint64_t> missed{0};  // deadlines skipped after overruns
  std::atomic<std::uint64_t> logSamples{0};
  internal::DurationStats latency, computation;
  unsigned logEvery = 1;

  std::string name;
  double rate = 1000.0;
  int priority = 27;
  int cpu = -1;
  Clock* clock = nullptr;

  // Lifecycle.
  std::mutex lifecycle;
  std::atomic<bool> running{false};
  std::mutex endMutex;
  std::condition_variable endCv;
  bool ended = true;

  std::atomic<bool> realTime{false};

  // Log variables.
  struct LogVar {
    LogVariableInfo info;
    const double* data;
    bool selected = true;
  };
  std::vector<LogVar> logVars;
  std::size_t logBufferSize = 4096;
  LogWriter* writer = nullptr;
  bool writerSet = false;
  std::shared_ptr<LogWriter::Channel> channel;
  std::vector<const double*> logSources;  // flattened, one per column (built in start())

  // QMotor's log (setLogCapture()): built and freed outside the loop; the loop only reads the
  // pointer `capture` and writes rows into the preallocated buffer.
  struct Capture {
    std::vector<const double*> sources;  // one per column
    std::vector<std::string> columns;    // full CSV names
    LogCaptureSettings settings;
    std::size_t width = 0;               // 1 + columns
    std::unique_ptr<double[]> rows;      // capacity × width
    const double* trigger = nullptr;     // the trigger column's value, or none
    std::atomic<std::size_t> count{0};   // rows written (release: a row is complete)
    std::atomic<bool> triggered{false};
    std::atomic<double> triggerTime{0};
    double previous = std::numeric_limits<double>::quiet_NaN();  // loop only
    std::uint64_t sinceTrigger = 0;                              // loop only

    // Real-time: one cycle's sample (no allocation, no lock).
    void sample(double t) noexcept {
      if (!triggered.load(std::memory_order_relaxed)) {
        if (trigger != nullptr) {
          const double v = *trigger, level = settings.triggerLevel;
          const bool crossed = settings.triggerRising ? (previous < level && v >= level) : (previous > level && v <= level);
          previous = v;
          if (!crossed) return;
        }
        triggerTime.store(t, std::memory_order_relaxed);
        triggered.store(true, std::memory_order_release);
        sinceTrigger = 0;
      }
      if (sinceTrigger++ % settings.every != 0) return;
      const std::size_t n = count.load(std::memory_order_relaxed);
      if (n >= settings.samples) return;
      double* row = rows.get() + n * width;
      row[0] = t;
      for (std::size_t i = 0; i + 1 < width; ++i) row[i + 1] = *sources[i];
      count.store(n + 1, std::memory_order_release);
    }
  };
  mutable std::mutex captureMutex;        // setLogCapture() and the readers (never the loop)
  std::shared_ptr<Capture> captureOwner;  // with captureMutex
  std::atomic<Capture*> capture{nullptr};
  std::atomic<bool> captureInUse{false};  // the loop holds `capture` (a one-slot hazard pointer)

  // Real-time: QMotor's log sample of this cycle.
  void sampleCapture(double t) noexcept {
    captureInUse.store(true);  // sequentially consistent with the swap in setLogCapture()
    if (Capture* c = capture.load()) c->sample(t);
    captureInUse.store(false, std::memory_order_release);
  }

  // Replaces the capture the loop sees by `next` and returns once the loop has let go of the old one.
  void swapCapture(std::shared_ptr<Capture> next) {
    std::lock_guard<std::mutex> lock(captureMutex);
    capture.exchange(next.get());
    while (captureInUse.load()) std::this_thread::yield();
    captureOwner = std::move(next);  // the old one is freed here, by this thread
  }

  // Parameters.
  struct Param {
    ParameterInfo info;
    double* target;
    std::unique_ptr<std::atomic<double>[]> pending;
    std::vector<double> requested;       // guarded by paramMutex
    std::atomic<std::uint64_t> seq{0};   // odd while a writer fills `pending`
    std::atomic<bool> dirty{false};
  };
  std::mutex paramMutex;
  std::vector<std::unique_ptr<Param>> params;

  Param& findParam(const std::string& pname) {
    for (auto& p : params)
      if (p->info.name == pname) return *p;
    std::string known;
    for (auto& p : params) known += (known.empty() ? "" : ", ") + p->info.name;
    throw std::invalid_argument("ControlProgram " + name + ": no parameter '" + pname + "' (known: " +
                                (known.empty() ? "none" : known) + ")");
  }

  void checkNotRunning(const char* what) const {
    if (running.load()) throw std::logic_error(std::string("ControlProgram::") + what + ": the program is running");
  }

  // Real-time: applies parameter changes requested since the last cycle, tear-free.
  // A cycle without a change reads one flag (parametersChanged), not each parameter's.
  void applyParameters() noexcept {
    if (!parametersChanged.load(std::memory_order_relaxed)) return;
    (void)parametersChanged.exchange(false, std::memory_order_acq_rel);
    bool again = false;  // a change left for the next cycle
    for (auto& p : params) {
      if (!p->dirty.load(std::memory_order_acquire)) continue;
      const std::uint64_t s1 = p->seq.load(std::memory_order_acquire);
      if (s1 & 1) {  // a writer is busy; try next cycle
        again = true;
        continue;
      }
      p->dirty.store(false, std::memory_order_relaxed);
      // Acquire loads keep the second sequence read after the element reads (no fence: GCC
      // rejects atomic_thread_fence under ThreadSanitizer).
      for (std::size_t i = 0; i < p->info.size; ++i) p->target[i] = p->pending[i].load(std::memory_order_acquire);
      if (p->seq.load(std::memory_order_relaxed) != s1) {
        p->dirty.store(true, std::memory_order_relaxed);
        again = true;
      }
    }
    if (again) parametersChanged.store(true, std::memory_order_release);
  }

  // Throws std::out_of_range if a value is outside the parameter's range.
  void checkRange(const Param& p, const std::vector<double>& values) const {
    for (double v : values)
      if (!(v >= p.info.min && v <= p.info.max))
        throw std::out_of_range("ControlProgram " + name + ": parameter '" + p.info.name + "' = " + internal::shortNumber(v) +
                                " is outside [" + internal::shortNumber(p.info.min) + ", " + internal::shortNumber(p.info.max) + "]" +
                                (p.info.unit.empty() ? "" : " " + p.info.unit));
  }

  void request(Param& p, const std::vector<double>& values) {
    checkRange(p, values);
    std::lock_guard<std::mutex> lock(paramMutex);
    p.requested = values;
    if (!running.load()) {
      for (std::size_t i = 0; i < values.size(); ++i) {
        p.target[i] = values[i];
        p.pending[i].store(values[i], std::memory_order_relaxed);
      }
      return;
    }
    p.seq.fetch_add(1, std::memory_order_acq_rel);
    for (std::size_t i = 0; i < values.size(); ++i) p.pending[i].store(values[i], std::memory_order_relaxed);
    p.seq.fetch_add(1, std::memory_order_release);
    p.dirty.store(true, std::memory_order_release);
    parametersChanged.store(true, std::memory_order_release);  // after the parameter's own flag
  }

  // Real-time: the bookkeeping after a program's phases (QMotor's log, the log file's sample,
  // the cycle count), at clock time t in its cycle k.
  void finishCycle(double t, std::uint64_t k) noexcept {
    sampleCapture(t);
    if (channel && k % logEvery == 0) {
      if (double* slot = channel->beginPush()) {
        slot[0] = t;
        for (std::size_t i = 0; i < logSources.size(); ++i) slot[i + 1] = *logSources[i];
        channel->commitPush();
      }
      bump(logSamples);
    }
    bump(cycles);
  }
  // The loop's thread is the counts' only writer while the program runs (start() resets them
  // before): a load and a store, not a locked read-modify-write (a full barrier on x86, per
  // program and cycle).
  static void bump(std::atomic<std::uint64_t>& count) noexcept {
    count.store(count.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }

  // On the simulated clock time waits for every program, so a program may also wait for the log
  // writer: when its ring buffer is half full it lets the writer drain it to a quarter, and no
  // sample is lost however fast the simulation runs. (The real-time loop never waits; its buffer
  // is sized by logBufferSize.) Gives up after about two seconds, or if the writer is closed.
  void waitForLogRoom() {
    if (!channel || writer == nullptr) return;
    auto used = [this] {
      return channel->head.load(std::memory_order_acquire) - channel->tail.load(std::memory_order_acquire);
    };
    if (used() * 2 < channel->capacity) return;
    for (int i = 0; i < 20000 && !stopRequested.load(std::memory_order_relaxed) && !writer->isClosed(); ++i) {
      writer->notify();
      std::this_thread::sleep_for(std::chrono::microseconds(100));
      if (used() * 4 < channel->capacity) return;
    }
  }

  // The first tick of a run on the simulated clock: the next multiple of the period, and after
  // the ticks of an earlier run (started again after a stop, the clock may not have moved on: its
  // first cycle would have the time of the last one).
  std::uint64_t firstSimulatedTick(const SimulatedClock& sim, std::uint64_t ticksPerCycle) const {
    const std::uint64_t now = (sim.getTick() + ticksPerCycle - 1) / ticksPerCycle * ticksPerCycle;
    return std::max(now, (nextTick + ticksPerCycle - 1) / ticksPerCycle * ticksPerCycle);
  }

  // Executor: which thread steps the program, and its state in that thread.
  ThreadMode threadMode = ThreadMode::Shared;
  std::atomic<Executor*> executor{nullptr};  // set by start(), cleared by stop() (lifecycle mutex)
  std::size_t executorPrograms = 0;           // programs of the executor when it was last started

  // Loop thread: before the first cycle.
  void enter() {
    entered = true;
    internal::currentLoop = this;
    self.enterControl();
  }

  // Loop thread: after the last cycle (cycle limit or stop request).
  void finish();
};

namespace internal {
namespace {
std::atomic<int>& defaultThreadMode() {
  static std::atomic<int> mode{[] {
    const char* e = std::getenv("RP_CONTROL_THREADS");
    return e != nullptr && std::string(e) == "own" ? static_cast<int>(ThreadMode::Own) : static_cast<int>(ThreadMode::Shared);
  }()};
  return mode;
}
thread_local const void* currentExecutor = nullptr;  // the executor whose loop runs in this thread

// The CPUs a shared executor on the real clock spreads its programs over (setExecutorCpus()):
// empty for one thread. Initially from RP_EXECUTOR_CPUS ("0,1"); a malformed value is ignored
// with a message.
struct ExecutorCpus {
  std::mutex mutex;
  std::vector<int> cpus;
};
ExecutorCpus& executorCpus() {
  static auto* c = [] {
    auto* x = new ExecutorCpus;
    if (const char* e = std::getenv("RP_EXECUTOR_CPUS"); e != nullptr && *e != '\0') {
      std::vector<int> cpus;
      const std::string text = e;
      std::size_t at = 0;
      bool good = true;
      while (good && at <= text.size()) {
        const std::size_t comma = std::min(text.find(',', at), text.size());
        const std::string item = text.substr(at, comma - at);
        good = !item.empty() && item.size() < 5 && item.find_first_not_of("0123456789") == std::string::npos;
        if (good) cpus.push_back(std::stoi(item));
        at = comma + 1;
      }
      if (good && cpus.size() >= 2)
        x->cpus = std::move(cpus);
      else
        std::fprintf(stderr, "rp: RP_EXECUTOR_CPUS='%s' is not a list of two or more CPU numbers (e.g. 0,1): ignored\n", e);
    }
    return x;
  }();
  return *c;
}

// A meeting point of an executor's threads between phases: spins (the threads run on CPUs of
// their own), yielding after a while so that a machine without real-time scheduling still makes
// progress. Real-time safe: yes (no lock, no system call while the others arrive in time).
struct SpinBarrier {
  unsigned count = 1;
  std::atomic<unsigned> arrived{0};
  std::atomic<std::uint64_t> round{0};
  void wait() noexcept {
    const std::uint64_t r = round.load(std::memory_order_acquire);
    if (arrived.fetch_add(1, std::memory_order_acq_rel) + 1 == count) {
      arrived.store(0, std::memory_order_relaxed);
      round.fetch_add(1, std::memory_order_release);
      return;
    }
    for (unsigned spins = 0; round.load(std::memory_order_acquire) == r; ++spins) {
      if (spins < 20000)
        cpuRelax();
      else
        std::this_thread::yield();
    }
  }
  static void cpuRelax() noexcept {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#else
    std::atomic_signal_fence(std::memory_order_seq_cst);
#endif
  }
};
}  // namespace
}  // namespace internal

// One periodic thread stepping the programs of one clock, rate, priority and CPU (or one program
// with a thread of its own) in three phases: every program's readInputs(), then every control(),
// then every writeOutputs(), each in the order the programs were started.
//
// The list of programs is a vector built outside the loop (start(), stop(), under the registry's
// mutex) and published through an atomic pointer; the loop announces the list it holds during a
// cycle in a hazard pointer (`inUse`), and replaced lists are freed only once the loop does not
// hold them. start() never waits for the loop (a program's cycle may wait for a lock its caller
// holds); stop() waits until the loop holds no list with the program in it. So adding or removing
// a program never allocates, locks or waits in the loop.
struct ControlProgram::Executor {
  using Impl = ControlProgram::Impl;
  using List = std::vector<Impl*>;

  // Settings (fixed while the executor is in the registry).
  Clock* clock = nullptr;
  std::atomic<SimulatedClock*> sim{nullptr};  // while the thread runs on a simulated clock
  double rate = 1000;
  int priority = 27;
  int cpu = -1;
  bool own = false;
  std::uint64_t ticksPerCycle = 1;
  std::uint64_t firstTick = 0;

  // Lifecycle (registry mutex), and the flags the loop reads.
  std::thread thread;
  bool exited = false;                  // the loop has ended or is ending: no program may join
  std::atomic<bool> quit{false};        // end the loop (its list is empty)
  std::atomic<bool> attention{false};   // a program asked to stop
  std::unique_ptr<List> owned;          // the list the loop sees
  std::vector<std::unique_ptr<List>> retired;  // lists replaced from the loop's own thread
  std::atomic<List*> list{nullptr};
  std::atomic<List*> inUse{nullptr};
  std::atomic<std::uint64_t> releases{0};  // lists the loop has let go of
  SimulatedClock::Participant participant;

  // A spread executor (real clock, setExecutorCpus()): the loop's thread on spread[0] and a worker
  // thread on each further CPU; program i of the list is stepped by thread i mod spread.size(),
  // and the threads meet between the phases. The loop hands each cycle to the workers by `go`
  // after writing the cycle's list and the time they sleep until next (`nextWake`).
  std::vector<int> spread;
  std::vector<std::thread> workers;
  std::atomic<bool> workersQuit{false};
  std::atomic<std::uint64_t> go{0};
  std::atomic<std::int64_t> nextWake{0};
  List* cycleList = nullptr;
  internal::SpinBarrier barrier;

  // The cycle being run (written by the loop before the phases, read by every thread of it).
  bool cycleSimulated = false, cycleCatchUp = false;
  double cycleClock = 0;  // the clock time of the cycle [s]
  std::uint64_t cycleTick = 0;

  // Statistics.
  std::atomic<std::uint64_t> cycles{0}, overruns{0}, missed{0};
  internal::DurationStats latency, cycleTime;
  std::atomic<bool> realTime{false};
  std::atomic<const Impl*> overrunProgram{nullptr};
  std::atomic<std::int64_t> overrunNs{0};
  std::string overrunName;  // registry mutex: the name of overrunProgram once it is removed

  static std::mutex& registryMutex() {
    static auto* m = new std::mutex;
    return *m;
  }
  // Executors in the order they were created; ended ones are kept for reuse (a late
  // requestStop() may still touch one, so they are never freed).
  static std::vector<Executor*>& registry() {
    static auto* v = new std::vector<Executor*>;
    return *v;
  }
  static std::vector<Executor*>& pool() {
    static auto* v = new std::vector<Executor*>;
    return *v;
  }

  // Wakes the loop to look at stop requests. Real-time safe: yes (the simulated clock's
  // interrupt() takes its mutex; only the simulated clock needs the wake-up).
  void wake() noexcept {
    attention.store(true);
    if (SimulatedClock* s = sim.load()) s->interrupt();
  }

  // Registry mutex held: publishes `next` to the loop and frees the replaced lists the loop does
  // not hold. Returns a ticket for waitUntilReleased().
  std::uint64_t replaceList(std::unique_ptr<List> next) {
    List* raw = next.get();
    int live = 0;
    if (raw != nullptr)
      for (const Impl* p : *raw) live += !p->loopEnded.load();
    participant.programs.store(live);
    list.exchange(raw);  // sequentially consistent with the loop's acquire()
    const std::uint64_t ticket = releases.load();
    if (owned) retired.push_back(std::move(owned));
    owned = std::move(next);
    freeRetired();
    return ticket;
  }

  // Registry mutex held: frees every replaced list but the one the loop holds now (the loop can
  // only take the current list from now on).
  void freeRetired() {
    List* const held = inUse.load();
    retired.erase(std::remove_if(retired.begin(), retired.end(), [&](const auto& l) { return l.get() != held; }),
                  retired.end());
  }

  // Without the registry mutex (the loop may need it in this very cycle, to start a program), and
  // not from the loop's own thread: returns once the loop holds no list published before the
  // replaceList() that gave `ticket` (it holds none, or it has let go of a list since).
  void waitUntilReleased(std::uint64_t ticket) const {
    while (inUse.load() != nullptr && releases.load() == ticket) std::this_thread::yield();
  }

  // Loop: takes the current list (announced in `inUse`, then checked to be still current).
  List* acquire() noexcept {
    List* l = list.load();
    for (;;) {
      inUse.store(l);
      List* now = list.load();
      if (now == l) return l;
      l = now;
    }
  }
  void release() noexcept {
    inUse.store(nullptr);
    releases.fetch_add(1);
  }

  // Loop: stops the programs that asked to, between cycles.
  void handleStopRequests() {
    if (List* l = acquire())
      for (Impl* p : *l)
        if (!p->loopEnded.load(std::memory_order_relaxed) && p->stopRequested.load(std::memory_order_relaxed))
          p->finish();
    release();
  }

  // Loop: true if no program is left to step; then the executor is marked ended (no program
  // joins it any more) and the loop must end.
  bool endIfIdle() {
    std::lock_guard<std::mutex> lock(registryMutex());
    if (const List* l = owned.get())
      for (const Impl* p : *l)
        if (!p->loopEnded.load()) return false;
    exited = true;
    return true;
  }

  // Loop threads: whether program p takes part in the cycle being run.
  bool active(const Impl* p) const noexcept {
    return p->entered && !p->loopEnded.load(std::memory_order_relaxed) && (!cycleSimulated || cycleTick >= p->startTick) &&
           (!cycleCatchUp || p->joining);
  }

  // Loop threads: the three phases of programs first, first + stride, ... of l, each program's
  // time charged to it in ticks (Ticks.hpp: a reading of the time-stamp counter between two
  // programs, where a clock_gettime() cost as much as a tenth of a simulated arm's cycle). With a
  // stride (a spread executor) the threads meet after each phase, so that every control() sees
  // every program's inputs of this cycle and every write follows every control(); the wait at a
  // meeting is charged to no program. Returns when this thread's phases ended [ns] (with a
  // stride, when every thread's have).
  std::int64_t phases(List& l, std::size_t first, std::size_t stride) noexcept {
    std::int64_t last = internal::ticks();
    auto charge = [&](Impl* p) {
      const std::int64_t now = internal::ticks();
      p->cycleTicks += now - last;
      last = now;
    };
    auto meet = [&] {
      if (stride == 1) return;
      barrier.wait();
      last = internal::ticks();
    };
    // Each phase: this thread's programs in their order, each one's time charged to it.
    auto each = [&](auto&& phase) {
      for (std::size_t i = first; i < l.size(); i += stride) {
        Impl* p = l[i];
        if (!active(p)) continue;
        internal::currentLoop = p;
        phase(*p);
        charge(p);
      }
    };
    // Phase 1: parameters and inputs.
    each([&](Impl& p) {
      p.cycleTicks = 0;
      p.time.store(cycleClock, std::memory_order_relaxed);
      p.applyParameters();
      p.self.readInputs();
    });
    meet();
    // Phase 2: control laws, each seeing every program's inputs of this cycle.
    each([](Impl& p) { p.self.control(); });
    meet();
    // Phase 3: outputs.
    each([](Impl& p) { p.self.writeOutputs(); });
    meet();
    internal::currentLoop = nullptr;
    return internal::monotonicNanoseconds();
  }

  // A worker thread of a spread executor: sleeps until the loop's next deadline, takes the cycle
  // the loop hands over and steps its share of the programs.
  void workerMain(std::size_t w) {
    internal::currentExecutor = this;
    (void)internal::setUpRealTime(priority, spread[w]);
    std::uint64_t seen = 0;
    while (!workersQuit.load(std::memory_order_relaxed)) {
      const std::int64_t until = nextWake.load(std::memory_order_relaxed);
      for (std::int64_t now = internal::monotonicNanoseconds(); now < until && !workersQuit.load(std::memory_order_relaxed);
           now = internal::monotonicNanoseconds()) {
        const std::int64_t t = std::min<std::int64_t>(until, now + 10000000LL);
        timespec ts{static_cast<time_t>(t / 1000000000LL), static_cast<long>(t % 1000000000LL)};
        clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
      }
      // The loop hands the cycle over a few microseconds after the deadline; after an overrun of
      // its own or while it has no program it may be later: spin a while, then sleep in slices.
      for (unsigned spins = 0; go.load(std::memory_order_acquire) == seen && !workersQuit.load(std::memory_order_relaxed);
           ++spins) {
        if (spins < 20000) {
          internal::SpinBarrier::cpuRelax();
        } else {
          timespec ts{0, 50000};
          nanosleep(&ts, nullptr);
        }
      }
      if (workersQuit.load(std::memory_order_relaxed)) break;
      seen = go.load(std::memory_order_acquire);
      phases(*cycleList, w, spread.size());
    }
    internal::currentExecutor = nullptr;
  }

  void startWorkers(std::int64_t firstDeadline) {
    barrier.count = static_cast<unsigned>(spread.size());
    go.store(0);
    nextWake.store(firstDeadline);
    workersQuit.store(false);
    for (std::size_t w = 1; w < spread.size(); ++w) workers.emplace_back([this, w] { workerMain(w); });
  }

  void stopWorkers() {
    workersQuit.store(true);
    for (std::thread& t : workers) t.join();
    workers.clear();
  }

  // Loop: one cycle at clock time t (tick: the simulated clock's, latencyNs: how late the thread
  // woke [ns], or -1 on the simulated clock). Returns the number of programs still to step.
  //
  // catchUp (simulated clock): a cycle of only the programs that joined after the executor had
  // run their first tick `tick` (a program started on a clock that has just run that tick, or
  // that was paused after it): they run that tick as they would have in a thread of their own.
  std::size_t step(double t, std::uint64_t tick, std::int64_t latencyNs, std::int64_t deadline, std::int64_t period,
                   bool catchUp = false) noexcept {
    const bool simulated = latencyNs < 0;
    std::size_t live = 0;
    List* l = acquire();
    if (l != nullptr) {
      // Programs that start or stop: between cycles (enterControl() and exitControl() are not
      // time-critical).
      for (Impl* p : *l) {
        if (p->loopEnded.load(std::memory_order_relaxed)) continue;
        if (p->stopRequested.load(std::memory_order_relaxed)) {
          p->finish();
          continue;
        }
        ++live;
        p->joining = false;
        if (!p->entered && (!simulated || tick >= p->startTick)) {
          p->realTime.store(realTime.load(std::memory_order_relaxed));
          p->enter();
          p->joining = true;
        }
      }
      cycleSimulated = simulated;
      cycleClock = t;
      cycleTick = tick;
      cycleCatchUp = catchUp;
      std::int64_t done = 0;
      if (spread.size() > 1) {
        cycleList = l;
        nextWake.store(deadline + period, std::memory_order_relaxed);
        go.fetch_add(1, std::memory_order_release);
        done = phases(*l, 0, spread.size());
      } else {
        done = phases(*l, 0, 1);
      }
      // The programs' state of this cycle is published (in their phases): threads that publish
      // each cycle's state (CycleSignal.hpp) go now, not after the bookkeeping below.
      internal::cycleEnded();
      // Bookkeeping: logs, statistics, cycle limits.
      const bool overrun = !simulated && done > deadline + period;
      const Impl* slowest = nullptr;
      std::int64_t skipped = 0;
      if (overrun) skipped = (done - deadline - period) / period + 1;
      const double nsPerTick = internal::nanosecondsPerTick();
      for (Impl* p : *l) {
        if (!active(p)) continue;
        internal::currentLoop = p;
        p->finishCycle(t, p->k++);
        p->computation.add(std::llround(static_cast<double>(p->cycleTicks) * nsPerTick));
        if (!simulated) p->latency.add(latencyNs);
        if (overrun) {
          p->overruns.fetch_add(1, std::memory_order_relaxed);
          p->missed.fetch_add(static_cast<std::uint64_t>(skipped), std::memory_order_relaxed);
          if (slowest == nullptr || p->cycleTicks > slowest->cycleTicks) slowest = p;
        }
        if (simulated) {
          p->nextTick = tick + ticksPerCycle;
          p->waitForLogRoom();
        }
        if (p->cycleLimit && p->k >= p->cycleLimit) {
          p->finish();
          --live;
        }
      }
      if (slowest != nullptr) {
        overrunProgram.store(slowest, std::memory_order_relaxed);
        overrunNs.store(std::llround(static_cast<double>(slowest->cycleTicks) * nsPerTick), std::memory_order_relaxed);
      }
      internal::currentLoop = nullptr;
    }
    release();
    return live;
  }

  void runReal() {
    realTime = internal::setUpRealTime(priority, spread.size() > 1 ? spread[0] : cpu);
    const auto period = static_cast<std::int64_t>(std::llround(1e9 / rate));
    const std::int64_t epoch = RealClock::instance().epochNanoseconds();
    // The first deadline is one period away (as in cyclictest), so every wake-up is a real one.
    std::int64_t deadline = internal::monotonicNanoseconds() + period;
    if (spread.size() > 1) startWorkers(deadline);
    while (!quit.load(std::memory_order_relaxed)) {
      // Sleep until the absolute deadline, in slices so that a stop is never kept waiting long.
      // The clock is read first thing after each wake-up: that reading is the one timed.
      std::int64_t woke = internal::monotonicNanoseconds();
      while (woke < deadline && !quit.load(std::memory_order_relaxed)) {
        if (attention.load(std::memory_order_relaxed)) {
          attention.store(false);
          handleStopRequests();
          if (endIfIdle()) return;
        }
        const std::int64_t until = std::min<std::int64_t>(deadline, woke + 10000000LL);
        timespec ts{static_cast<time_t>(until / 1000000000LL), static_cast<long>(until % 1000000000LL)};
        clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
        woke = internal::monotonicNanoseconds();
      }
      if (quit.load(std::memory_order_relaxed)) break;
      latency.add(woke - deadline);
      const std::size_t live = step(static_cast<double>(deadline - epoch) * 1e-9, 0, woke - deadline, deadline, period);
      const std::int64_t done = internal::monotonicNanoseconds();
      cycleTime.add(done - woke);
      cycles.fetch_add(1, std::memory_order_relaxed);
      deadline += period;
      if (done > deadline) {  // overrun: skip the deadlines already missed
        overruns.fetch_add(1, std::memory_order_relaxed);
        const std::int64_t skipped = (done - deadline) / period + 1;
        missed.fetch_add(static_cast<std::uint64_t>(skipped), std::memory_order_relaxed);
        deadline += skipped * period;
      }
      if (live == 0 && endIfIdle()) return;
    }
  }

  void runSimulated(SimulatedClock& clk) {
    std::uint64_t tick = firstTick;
    bool ran = false;  // a tick has run (tick - ticksPerCycle)
    while (!quit.load()) {
      if (!clk.waitForTick(participant, tick, attention)) {
        attention.store(false);
        if (quit.load()) break;
        handleStopRequests();
        if (ran) {
          // Programs that joined too late for the tick just run: they run it on their own.
          const std::uint64_t last = tick - ticksPerCycle;
          step(clk.tickTime(last), last, -1, 0, 0, true);
        }
        if (endIfIdle()) break;
        continue;
      }
      const std::int64_t start = internal::monotonicNanoseconds();
      const std::size_t live = step(clk.tickTime(tick), tick, -1, 0, 0);
      cycleTime.add(internal::monotonicNanoseconds() - start);
      cycles.fetch_add(1, std::memory_order_relaxed);
      ran = true;
      tick += ticksPerCycle;
      if (live == 0 && endIfIdle()) break;
    }
  }

  void threadMain() {
    internal::currentExecutor = this;
    if (SimulatedClock* s = sim.load()) {
      runSimulated(*s);
      sim.store(nullptr);
      s->detach(participant);
    } else {
      runReal();
      stopWorkers();
    }
    // Programs whose stop request came with the end (stop() waits for them).
    handleStopRequests();
    internal::currentExecutor = nullptr;
  }
};

// Loop thread: after the last cycle (cycle limit or stop request).
void ControlProgram::Impl::finish() {
  if (!entered) enter();
  internal::currentLoop = this;
  self.exitControl();
  internal::currentLoop = nullptr;
  // Missed cycles are reported when the loop ends (the cycle statistics and the log have them
  // too), so that rows missing from a log never go unexplained.
  if (const std::uint64_t m = missed.load())
    std::fprintf(stderr, "rp: %s: %llu servo cycles missed in %llu overruns (of %llu cycles run)\n", name.c_str(),
                 static_cast<unsigned long long>(m), static_cast<unsigned long long>(overruns.load()),
                 static_cast<unsigned long long>(cycles.load()));
  loopEnded.store(true, std::memory_order_release);
  if (Executor* e = executor.load()) e->participant.programs.fetch_sub(1);
  {
    std::lock_guard<std::mutex> lock(endMutex);
    ended = true;
  }
  endCv.notify_all();
}

ControlProgram::ControlProgram(const std::string& programName) : impl_(std::make_unique<Impl>(*this)) {
  impl_->name = programName;
  impl_->threadMode = getDefaultThreadMode();
  std::lock_guard<std::mutex> lock(internal::programsMutex());
  internal::programs().push_back(this);
}

ControlProgram::~ControlProgram() {
  stop();
  std::lock_guard<std::mutex> lock(internal::programsMutex());
  auto& v = internal::programs();
  v.erase(std::remove(v.begin(), v.end(), this), v.end());
}

void ControlProgram::setProgramName(const std::string& name) {
  impl_->checkNotRunning("setProgramName");
  impl_->name = name;
}
const std::string& ControlProgram::getProgramName() const { return impl_->name; }

void ControlProgram::setRate(double hz) {
  impl_->checkNotRunning("setRate");
  // At least 1 Hz: a period over a second is no control loop, and 1e-11 Hz overflowed the period
  // in nanoseconds (qmotorConfig's 'rate' has the same range).
  if (!(hz >= internal::kMinRate) || !(hz <= kMaxRate))
    throw std::invalid_argument("ControlProgram::setRate: the rate must be in [1, 20000] Hz, got " + internal::shortNumber(hz));
  impl_->rate = hz;
}
double ControlProgram::getRate() const { return impl_->rate; }
double ControlProgram::getPeriod() const { return 1.0 / impl_->rate; }

void ControlProgram::setPriority(int priority) {
  impl_->checkNotRunning("setPriority");
  if (priority < 1 || priority > 99)
    throw std::invalid_argument("ControlProgram::setPriority: the priority must be 1..99, got " + std::to_string(priority));
  impl_->priority = priority;
}
int ControlProgram::getPriority() const { return impl_->priority; }

void ControlProgram::setCpuAffinity(int cpu) {
  impl_->checkNotRunning("setCpuAffinity");
  if (cpu < -1)
    throw std::invalid_argument("ControlProgram::setCpuAffinity: the CPU must be -1 (none) or >= 0, got " +
                                std::to_string(cpu));
  impl_->cpu = cpu;
}
int ControlProgram::getCpuAffinity() const { return impl_->cpu; }

void ControlProgram::setClock(Clock& clock) {
  impl_->checkNotRunning("setClock");
  impl_->clock = &clock;
  impl_->nextTick = 0;  // another clock: its own ticks
}
Clock& ControlProgram::getClock() const { return impl_->clock ? *impl_->clock : RoboticPlatform::getDefaultClock(); }

void ControlProgram::setCycleLimit(std::uint64_t cycles) {
  impl_->checkNotRunning("setCycleLimit");
  impl_->cycleLimit = cycles;
}

void ControlProgram::setThreadMode(ThreadMode mode) {
  impl_->checkNotRunning("setThreadMode");
  impl_->threadMode = mode;
}
ThreadMode ControlProgram::getThreadMode() const { return impl_->threadMode; }
void ControlProgram::setExecutorCpus(const std::vector<int>& cpus) {
  if (cpus.size() == 1)
    throw std::invalid_argument("ControlProgram::setExecutorCpus: one CPU is no spread; pin the programs with setCpuAffinity()");
  for (std::size_t i = 0; i < cpus.size(); ++i) {
    if (cpus[i] < 0 || cpus[i] >= CPU_SETSIZE)
      throw std::invalid_argument("ControlProgram::setExecutorCpus: CPU " + std::to_string(cpus[i]) + " is not in 0.." +
                                  std::to_string(CPU_SETSIZE - 1));
    for (std::size_t j = 0; j < i; ++j)
      if (cpus[j] == cpus[i])
        throw std::invalid_argument("ControlProgram::setExecutorCpus: CPU " + std::to_string(cpus[i]) + " is listed twice");
  }
  std::lock_guard<std::mutex> lock(internal::executorCpus().mutex);
  internal::executorCpus().cpus = cpus;
}

std::vector<int> ControlProgram::getExecutorCpus() {
  std::lock_guard<std::mutex> lock(internal::executorCpus().mutex);
  return internal::executorCpus().cpus;
}

void ControlProgram::setDefaultThreadMode(ThreadMode mode) { internal::defaultThreadMode().store(static_cast<int>(mode)); }
ThreadMode ControlProgram::getDefaultThreadMode() { return static_cast<ThreadMode>(internal::defaultThreadMode().load()); }

void ControlProgram::start() {
  std::lock_guard<std::mutex> lock(impl_->lifecycle);
  Impl& d = *impl_;
  if (d.running.load() || d.executor.load() != nullptr)
    throw std::logic_error("ControlProgram::start: " + d.name + " is already running");
  internal::ensureShutdownWatcher();
  if (!d.clock) d.clock = &RoboticPlatform::getDefaultClock();
  d.stopRequested = false;
  d.cycles = 0;
  d.overruns = 0;
  d.missed = 0;
  d.logSamples = 0;
  d.latency.reset();
  d.computation.reset();
  // Log channel: one column per value of every selected variable. A program started again (QMotor's
  // Start after Stop) with the same writer and columns goes on in its own columns.
  std::shared_ptr<LogWriter::Channel> previous = std::move(d.channel);
  const std::vector<const double*> previousSources = std::move(d.logSources);
  LogWriter* const previousWriter = d.writer;
  d.channel.reset();
  d.logSources.clear();
  LogWriter* writer = d.writerSet ? d.writer : LogWriter::getPlatformWriter();
  if (writer && !writer->isClosed()) {
    std::vector<std::string> columns;
    for (auto& v : d.logVars) {
      if (!v.selected) continue;
      for (std::size_t i = 0; i < v.info.size; ++i) {
        columns.push_back(valueName(d.name, v.info, i));
        d.logSources.push_back(v.data + i);
      }
    }
    // The ring holds logBufferSize rows of (time + columns) doubles: at most 1 GiB.
    constexpr std::size_t kMaxRingDoubles = (std::size_t{1} << 30) / sizeof(double);
    if (!columns.empty() && d.logBufferSize > kMaxRingDoubles / (columns.size() + 1))
      throw std::invalid_argument("ControlProgram " + d.name + ": a log buffer of " + std::to_string(d.logBufferSize) +
                                  " samples of " + std::to_string(columns.size()) +
                                  " columns needs more than 1 GiB; set a smaller logBufferSize");
    if (!columns.empty()) {
      if (previous && previousWriter == writer && previousSources == d.logSources &&
          previous->capacity == std::max<std::size_t>(2, d.logBufferSize))
        d.channel = previous;
      else
        d.channel = std::make_shared<LogWriter::Channel>(d.name, std::move(columns), d.logBufferSize);
    }
  }
  d.writer = writer;
  {
    std::lock_guard<std::mutex> elock(d.endMutex);
    d.ended = false;
  }
  d.entered = false;
  d.loopEnded = false;
  d.k = 0;
  // The first cycle: on the simulated clock the next multiple of the period (the executor the
  // program joins runs on such ticks, and the clock cannot pass an executor's next tick before it
  // has run), so the time of the first sample is known now: the writer holds back rows from that
  // time on until it arrives.
  auto* sim = dynamic_cast<SimulatedClock*>(d.clock);
  std::uint64_t ticksPerCycle = 1;
  double firstTime;
  if (sim != nullptr) {
    ticksPerCycle = static_cast<std::uint64_t>(std::max<long long>(1, std::llround(1.0 / d.rate / sim->getStep())));
    d.startTick = d.firstSimulatedTick(*sim, ticksPerCycle);
    firstTime = sim->tickTime(d.startTick);
  } else {
    firstTime = RealClock::instance().getTime();
  }
  if (d.channel && d.channel == previous) {
    // The writer has it: rows of other programs wait for its next sample again (its last time
    // is before this run's first; the writer thread owns that field).
    d.channel->finished.store(false);
  } else if (d.channel) {
    d.channel->lastTime = std::nextafter(firstTime, -std::numeric_limits<double>::infinity());
    d.channel->any = true;
    writer->addChannel(d.channel);
  }
  d.running = true;

  // The executor: the running one of this clock, rate, priority and CPU, or a new one.
  const bool own = d.threadMode == ThreadMode::Own;
  std::lock_guard<std::mutex> rlock(Executor::registryMutex());
  Executor* e = nullptr;
  if (!own)
    for (Executor* x : Executor::registry())
      if (!x->own && !x->exited && x->clock == d.clock && x->rate == d.rate && x->priority == d.priority && x->cpu == d.cpu) {
        e = x;
        break;
      }
  const bool fresh = e == nullptr;
  if (fresh) {
    if (!Executor::pool().empty()) {
      e = Executor::pool().back();
      Executor::pool().pop_back();
    } else {
      e = new Executor;  // never freed (see registry())
    }
    e->clock = d.clock;
    e->rate = d.rate;
    e->priority = d.priority;
    e->cpu = d.cpu;
    e->own = own;
    e->ticksPerCycle = ticksPerCycle;
    e->firstTick = d.startTick;
    e->spread.clear();
    if (!own && d.cpu < 0 && sim == nullptr) {
      std::lock_guard<std::mutex> cpusLock(internal::executorCpus().mutex);
      e->spread = internal::executorCpus().cpus;
    }
    e->exited = false;
    e->quit = false;
    e->attention = false;
    e->cycles = 0;
    e->overruns = 0;
    e->missed = 0;
    e->latency.reset();
    e->cycleTime.reset();
    e->realTime = false;
    e->overrunProgram = nullptr;
    e->overrunNs = 0;
    e->overrunName.clear();
    e->retired.clear();
    Executor::registry().push_back(e);
  }
  auto next = std::make_unique<Executor::List>();
  if (e->owned) *next = *e->owned;
  next->push_back(&d);
  d.executorPrograms = next->size();
  (void)e->replaceList(std::move(next));
  d.executor.store(e);
  // On the simulated clock a program whose first tick the executor has already run runs it in a
  // catch-up cycle: wake the executor to look.
  if (!fresh && sim != nullptr) e->wake();
  if (fresh) {
    if (sim != nullptr) {
      // Attached now: the clock cannot pass the first tick before the loop has run it.
      e->sim.store(sim);
      sim->attach(e->participant);
    } else {
      e->sim.store(nullptr);
    }
    e->thread = std::thread([e] { e->threadMain(); });
  }
}

void ControlProgram::requestStop() noexcept {
  impl_->stopRequested.store(true);
  if (Executor* e = impl_->executor.load()) e->wake();
}

void ControlProgram::stop() {
  Impl& d = *impl_;
  Executor* const e = d.executor.load();
  if (e != nullptr && internal::currentExecutor == e) {  // called from the loop itself: only ask
    requestStop();
    return;
  }
  std::lock_guard<std::mutex> lock(d.lifecycle);
  if (d.executor.load() == nullptr) return;
  requestStop();
  {
    std::unique_lock<std::mutex> elock(d.endMutex);
    d.endCv.wait(elock, [&] { return d.ended; });
  }
  std::thread finished;
  std::uint64_t ticket = 0;
  {
    std::lock_guard<std::mutex> rlock(Executor::registryMutex());
    auto next = std::make_unique<Executor::List>();
    for (Impl* p : *e->owned)
      if (p != &d) next->push_back(p);
    if (e->overrunProgram.load() == &d) {
      e->overrunName = d.name;
      e->overrunProgram.store(nullptr);
    }
    const bool empty = next->empty();
    ticket = e->replaceList(empty ? nullptr : std::move(next));
    d.executor.store(nullptr);
    if (empty) {
      e->exited = true;
      e->quit = true;
      e->wake();
      finished = std::move(e->thread);
    }
  }
  // This program's Impl may be freed once stop() returns: wait until the loop holds no list that
  // names it, outside the registry's lock (a program in the current cycle may be starting another).
  e->waitUntilReleased(ticket);
  {
    std::lock_guard<std::mutex> rlock(Executor::registryMutex());
    e->freeRetired();
  }
  if (finished.joinable()) {
    finished.join();
    std::lock_guard<std::mutex> rlock(Executor::registryMutex());
    auto& r = Executor::registry();
    r.erase(std::remove(r.begin(), r.end(), e), r.end());
    Executor::pool().push_back(e);
  }
  d.running = false;
  if (d.channel) {
    d.channel->finished.store(true);
    if (d.writer) d.writer->notify();
  }
}

void ControlProgram::waitUntilStopped() {
  {
    std::unique_lock<std::mutex> lock(impl_->endMutex);
    impl_->endCv.wait(lock, [&] { return impl_->ended; });
  }
  stop();
}

bool ControlProgram::isLoopThread() noexcept {
  return internal::currentLoop != nullptr || internal::currentExecutor != nullptr;
}

bool ControlProgram::isRunning() const noexcept { return impl_->running.load(); }
double ControlProgram::getTime() const noexcept { return impl_->time.load(std::memory_order_relaxed); }
std::uint64_t ControlProgram::getCycleCount() const noexcept { return impl_->cycles.load(std::memory_order_relaxed); }
std::uint64_t ControlProgram::getMissedCycleCount() const noexcept {
  return impl_->missed.load(std::memory_order_relaxed);
}

ControlStatistics ControlProgram::getStatistics() const {
  ControlStatistics s;
  s.cycles = impl_->cycles.load();
  s.overruns = impl_->overruns.load();
  s.missedCycles = impl_->missed.load();
  s.wakeupLatency = impl_->latency.summary();
  s.computationTime = impl_->computation.summary();
  s.logSamples = impl_->logSamples.load();
  s.lostLogSamples = impl_->channel ? impl_->channel->lost.load() : 0;
  s.realTimeScheduling = impl_->realTime.load();
  s.simulatedClock = impl_->clock && impl_->clock->isSimulated();
  s.ownThread = impl_->threadMode == ThreadMode::Own;
  s.executorPrograms = impl_->executorPrograms;
  return s;
}

std::vector<ExecutorStatistics> ControlProgram::getExecutorStatistics() {
  std::vector<ExecutorStatistics> out;
  std::lock_guard<std::mutex> lock(Executor::registryMutex());
  for (const Executor* e : Executor::registry()) {
    ExecutorStatistics s;
    s.rate = e->rate;
    s.priority = e->priority;
    s.cpu = e->cpu;
    s.cpus = e->spread;
    s.ownThread = e->own;
    s.simulatedClock = e->clock != nullptr && e->clock->isSimulated();
    s.realTimeScheduling = e->realTime.load();
    if (e->owned)
      for (const Impl* p : *e->owned) s.programs.push_back(p->name);
    s.cycles = e->cycles.load();
    s.overruns = e->overruns.load();
    s.missedCycles = e->missed.load();
    s.wakeupLatency = e->latency.summary();
    s.cycleTime = e->cycleTime.summary();
    const Impl* slowest = e->overrunProgram.load();
    s.lastOverrunProgram = slowest != nullptr ? slowest->name : e->overrunName;
    s.lastOverrunProgramTime = static_cast<double>(e->overrunNs.load()) / 1000.0;
    out.push_back(std::move(s));
  }
  return out;
}

void ControlProgram::registerLogVariable(const std::string& name, const double& variable, const std::string& unit) {
  registerLogVariable(name, &variable, 1, unit);
  impl_->logVars.back().info.vector = false;
}

void ControlProgram::registerLogVariable(const std::string& name, const double* data, std::size_t size,
                                         const std::string& unit) {
  impl_->checkNotRunning("registerLogVariable");
  if (name.empty() || name.find_first_of(",.\"\n[] ") != std::string::npos)
    throw std::invalid_argument("registerLogVariable: '" + name + "' is not a valid name (no , . [ ] quotes or spaces)");
  if (!data || size == 0) throw std::invalid_argument("registerLogVariable: '" + name + "' has no data");
  for (auto& v : impl_->logVars)
    if (v.info.name == name) throw std::invalid_argument("registerLogVariable: '" + name + "' is already registered");
  impl_->logVars.push_back({LogVariableInfo{name, size, true, unit}, data, true});
}

std::vector<LogVariableInfo> ControlProgram::getLogVariables() const {
  std::vector<LogVariableInfo> out;
  for (auto& v : impl_->logVars) out.push_back(v.info);
  return out;
}

void ControlProgram::setLogEvery(unsigned n) {
  impl_->checkNotRunning("setLogEvery");
  if (n == 0 || n > kMaxLogEvery)
    throw std::invalid_argument("ControlProgram::setLogEvery: n must be in 1.." + std::to_string(kMaxLogEvery) + ", got " +
                                std::to_string(n));
  impl_->logEvery = n;
}
unsigned ControlProgram::getLogEvery() const { return impl_->logEvery; }

void ControlProgram::setLogBufferSize(std::size_t samples) {
  impl_->checkNotRunning("setLogBufferSize");
  if (samples < 2 || samples > kMaxLogBufferSize)
    throw std::invalid_argument("ControlProgram::setLogBufferSize: 2 .. 1000000 samples, got " + std::to_string(samples));
  impl_->logBufferSize = samples;
}

void ControlProgram::setLogWriter(LogWriter* writer) {
  impl_->checkNotRunning("setLogWriter");
  impl_->writer = writer;
  impl_->writerSet = true;
}

void ControlProgram::setLogCapture(const LogCaptureSettings& settings) {
  Impl& d = *impl_;
  auto known = [&] {
    std::string names;
    for (auto& v : d.logVars) names += (names.empty() ? "" : ", ") + v.info.name;
    return names.empty() ? std::string("none") : names;
  };
  if (settings.every < 1 || settings.every > kMaxLogEvery)
    throw std::invalid_argument("'every' must be an integer in 1.." + std::to_string(kMaxLogEvery) + ", got " +
                                std::to_string(settings.every));
  if (!std::isfinite(settings.triggerLevel)) throw std::invalid_argument("'level' must be a finite number");
  auto c = std::make_shared<Impl::Capture>();
  c->settings = settings;
  for (std::size_t k = 0; k < settings.variables.size(); ++k) {
    const std::string& w = settings.variables[k];
    if (std::find(settings.variables.begin(), settings.variables.begin() + static_cast<std::ptrdiff_t>(k), w) !=
        settings.variables.begin() + static_cast<std::ptrdiff_t>(k))
      throw std::invalid_argument("'variables': '" + w + "' is given twice");
    if (std::none_of(d.logVars.begin(), d.logVars.end(), [&](auto& v) { return v.info.name == w; }))
      throw std::invalid_argument("'variables': '" + w + "' is not a log variable of " + d.name + " (known: " + known() + ")");
  }
  // Columns in registration order, as in the log file.
  for (auto& v : d.logVars) {
    if (!settings.variables.empty() &&
        std::find(settings.variables.begin(), settings.variables.end(), v.info.name) == settings.variables.end())
      continue;
    for (std::size_t i = 0; i < v.info.size; ++i) {
      c->columns.push_back(valueName(d.name, v.info, i));
      c->sources.push_back(v.data + i);
    }
  }
  if (c->columns.empty()) throw std::invalid_argument("'variables': " + d.name + " has no log variables");
  c->width = c->columns.size() + 1;
  const std::size_t maxRows = kMaxLogCaptureValues / c->width;
  if (settings.samples < 1 || settings.samples > maxRows)
    throw std::invalid_argument("'samples' must be in 1.." + std::to_string(maxRows) + " for " +
                                std::to_string(c->columns.size()) + " columns, got " + std::to_string(settings.samples));
  if (!settings.triggerColumn.empty()) {
    const std::string& t = settings.triggerColumn;
    for (auto& v : d.logVars)
      for (std::size_t i = 0; i < v.info.size; ++i)
        if (valueName("", v.info, i) == t) c->trigger = v.data + i;
    if (c->trigger == nullptr)
      throw std::invalid_argument("'trigger': '" + t + "' is not a log value of " + d.name +
                                  " (a scalar's name or a vector's name[i]; variables: " + known() + ")");
  }
  c->rows.reset(new double[settings.samples * c->width]());
  d.swapCapture(std::move(c));
}

void ControlProgram::clearLogCapture() { impl_->swapCapture(nullptr); }

LogCaptureStatus ControlProgram::getLogCaptureStatus() const {
  std::lock_guard<std::mutex> lock(impl_->captureMutex);
  LogCaptureStatus s;
  const Impl::Capture* c = impl_->captureOwner.get();
  if (c == nullptr) return s;
  s.armed = true;
  s.triggered = c->triggered.load(std::memory_order_acquire);
  s.triggerTime = s.triggered ? c->triggerTime.load(std::memory_order_relaxed) : 0;
  s.rows = c->count.load(std::memory_order_acquire);
  s.capacity = c->settings.samples;
  s.every = c->settings.every;
  s.columns = c->columns;
  s.triggerColumn = c->settings.triggerColumn;
  s.triggerLevel = c->settings.triggerLevel;
  s.triggerRising = c->settings.triggerRising;
  return s;
}

std::string ControlProgram::getLogCaptureCsv() const {
  std::lock_guard<std::mutex> lock(impl_->captureMutex);
  const Impl::Capture* c = impl_->captureOwner.get();
  if (c == nullptr) throw std::logic_error("ControlProgram " + impl_->name + ": no QMotor log is set (setLogCapture())");
  const std::size_t n = c->count.load(std::memory_order_acquire);
  std::string out = "t";
  for (const auto& column : c->columns) out += "," + column;
  out += '\n';
  out.reserve(out.size() + n * c->width * 12);
  for (std::size_t r = 0; r < n; ++r) {
    const double* row = c->rows.get() + r * c->width;
    for (std::size_t i = 0; i < c->width; ++i) {
      if (i) out += ',';
      internal::appendNumber(out, row[i]);
    }
    out += '\n';
  }
  return out;
}

void ControlProgram::registerParameter(const std::string& name, double& target, double min, double max,
                                       const std::string& unit, const std::string& description) {
  registerParameter(name, &target, 1, min, max, unit, description);
}

void ControlProgram::registerParameter(const std::string& name, double* target, std::size_t size, double min,
                                       double max, const std::string& unit, const std::string& description) {
  impl_->checkNotRunning("registerParameter");
  if (name.empty() || !target || size == 0)
    throw std::invalid_argument("registerParameter: '" + name + "' needs a name and storage");
  if (!(min <= max)) throw std::invalid_argument("registerParameter: '" + name + "': min > max");
  std::lock_guard<std::mutex> lock(impl_->paramMutex);
  for (auto& p : impl_->params)
    if (p->info.name == name) throw std::invalid_argument("registerParameter: '" + name + "' is already registered");
  auto p = std::make_unique<Impl::Param>();
  p->info = ParameterInfo{name, size, min, max, unit, description};
  p->target = target;
  p->pending.reset(new std::atomic<double>[size]);
  for (std::size_t i = 0; i < size; ++i) {
    if (!(target[i] >= min && target[i] <= max))
      throw std::invalid_argument("registerParameter: '" + name + "': the current value " + internal::shortNumber(target[i]) +
                                  " is outside [" + internal::shortNumber(min) + ", " + internal::shortNumber(max) + "]");
    p->pending[i].store(target[i]);
    p->requested.push_back(target[i]);
  }
  impl_->params.push_back(std::move(p));
}

void ControlProgram::setParameter(const std::string& name, double value) {
  Impl::Param& p = impl_->findParam(name);
  impl_->request(p, std::vector<double>(p.info.size, value));
}

void ControlProgram::setParameter(const std::string& name, std::size_t index, double value) {
  Impl::Param& p = impl_->findParam(name);
  if (index >= p.info.size)
    throw std::out_of_range("ControlProgram " + impl_->name + ": parameter '" + name + "' has " +
                            std::to_string(p.info.size) + " elements, index " + std::to_string(index) + " is too large");
  std::vector<double> values;
  {
    std::lock_guard<std::mutex> lock(impl_->paramMutex);
    values = p.requested;
  }
  values[index] = value;
  impl_->request(p, values);
}

void ControlProgram::setParameter(const std::string& name, const std::vector<double>& values) {
  Impl::Param& p = impl_->findParam(name);
  if (values.size() != p.info.size)
    throw std::invalid_argument("ControlProgram " + impl_->name + ": parameter '" + name + "' needs " +
                                std::to_string(p.info.size) + " values, got " + std::to_string(values.size()));
  impl_->request(p, values);
}

std::vector<double> ControlProgram::getParameter(const std::string& name) const {
  Impl::Param& p = impl_->findParam(name);
  std::lock_guard<std::mutex> lock(impl_->paramMutex);
  return p.requested;
}

std::vector<ParameterInfo> ControlProgram::getParameters() const {
  std::lock_guard<std::mutex> lock(impl_->paramMutex);
  std::vector<ParameterInfo> out;
  for (auto& p : impl_->params) out.push_back(p->info);
  return out;
}

namespace internal {
bool parseNumber(const std::string& token, double& value);  // Configuration.cpp: whole token, finite
}  // namespace internal

namespace {

// Ranges of the control-program settings a qmotorConfig file may give (docs/core.md).
constexpr double kMinQMotorRate = internal::kMinRate;  // Hz: a period of at most 1 s (1e-11 overflowed it)
constexpr double kMaxQMotorRate = ControlProgram::kMaxRate;  // Hz
constexpr long long kMaxQMotorLogEvery = ControlProgram::kMaxLogEvery;  // cycles
constexpr auto kMaxQMotorLogBuffer = static_cast<long long>(ControlProgram::kMaxLogBufferSize);  // samples

// The one value of setting `e` as a number in (low, high] (or [low, high] when `openLow` is
// false); a ConfigError at the setting's line naming it otherwise.
double qmotorNumber(const ParameterFile& file, const ConfigSetting& e, double low, double high, bool openLow,
                    const char* unit) {
  if (e.values.size() != 1)
    throw file.errorAt(e, "'" + e.name + "' needs 1 value, got " + std::to_string(e.values.size()));
  const std::string& v = e.values[0];
  double d = 0;
  const bool ok = internal::parseNumber(v, d) && std::isfinite(d) && (openLow ? d > low : d >= low) && d <= high;
  if (!ok) {
    char range[96];
    std::snprintf(range, sizeof range, "%s%g, %g] %s", openLow ? "(" : "[", low, high, unit);
    throw file.errorAt(e, "'" + e.name + "' must be a number in " + range + ", got '" + ConfigError::excerpt(v) + "'");
  }
  return d;
}

// The one value of setting `e` as a whole number in [low, high]; a ConfigError otherwise.
long long qmotorInteger(const ParameterFile& file, const ConfigSetting& e, long long low, long long high) {
  if (e.values.size() != 1)
    throw file.errorAt(e, "'" + e.name + "' needs 1 value, got " + std::to_string(e.values.size()));
  const std::string& v = e.values[0];
  double d = 0;
  // Compared as doubles before any conversion: a huge value never goes through a narrowing cast.
  const bool ok = internal::parseNumber(v, d) && std::isfinite(d) && d == std::floor(d) &&
                  d >= static_cast<double>(low) && d <= static_cast<double>(high);
  if (!ok)
    throw file.errorAt(e, "'" + e.name + "' must be an integer in " + std::to_string(low) + ".." + std::to_string(high) +
                              ", got '" + ConfigError::excerpt(v) + "'");
  return static_cast<long long>(d);
}

}  // namespace

void ControlProgram::applyQMotorConfig(const ParameterFile& file) {
  Impl& d = *impl_;
  // A setting may change only while the program is stopped; a file giving its current value (as
  // saveQMotorConfig() writes it) is accepted while running.
  auto setting = [&](const ConfigSetting& e, bool same, bool apply, const std::function<void()>& set) {
    if (d.running.load()) {
      if (!same)
        throw file.errorAt(e, "'" + e.name + "' cannot change while " + d.name +
                                  " runs (stop the program, then load the file again)");
      return;
    }
    if (apply) set();
  };
  // Pass 0 checks every line, pass 1 applies them: a bad file changes nothing.
  for (int pass = 0; pass < 2; ++pass) {
    const bool apply = pass == 1;
    for (const auto& e : file.entries()) {
      try {
        if (e.name == "rate") {
          const double v = qmotorNumber(file, e, kMinQMotorRate, kMaxQMotorRate, false, "Hz");
          setting(e, v == d.rate, apply, [&] { setRate(v); });
        } else if (e.name == "priority") {
          const int v = static_cast<int>(qmotorInteger(file, e, 1, 99));
          setting(e, v == d.priority, apply, [&] { setPriority(v); });
        } else if (e.name == "logEvery") {
          const auto v = static_cast<unsigned>(qmotorInteger(file, e, 1, kMaxQMotorLogEvery));
          setting(e, v == d.logEvery, apply, [&] { setLogEvery(v); });
        } else if (e.name == "logBufferSize") {
          const auto v = static_cast<std::size_t>(qmotorInteger(file, e, 2, kMaxQMotorLogBuffer));
          setting(e, v == d.logBufferSize, apply, [&] { setLogBufferSize(v); });
        } else if (e.name == "log") {
          std::vector<bool> selected(d.logVars.size(), false);
          for (const auto& w : e.values) {
            auto it = std::find_if(d.logVars.begin(), d.logVars.end(), [&](auto& v) { return v.info.name == w; });
            if (it == d.logVars.end()) {
              std::string known;
              for (auto& v : d.logVars) known += (known.empty() ? "" : ", ") + v.info.name;
              throw file.errorAt(e, "'log': '" + ConfigError::excerpt(w) + "' is not a log variable of " + d.name +
                                        " (known: " + (known.empty() ? "none" : known) + ")");
            }
            selected[static_cast<std::size_t>(it - d.logVars.begin())] = true;
          }
          bool same = true;
          for (std::size_t i = 0; i < d.logVars.size(); ++i) same = same && selected[i] == d.logVars[i].selected;
          setting(e, same, apply, [&] {
            for (std::size_t i = 0; i < d.logVars.size(); ++i) d.logVars[i].selected = selected[i];
          });
        } else {
          bool known = false;
          for (auto& p : d.params) known = known || p->info.name == e.name;
          if (!known) {
            std::string names = "rate, priority, logEvery, logBufferSize, log";
            for (auto& p : d.params) names += ", " + p->info.name;
            throw file.errorAt(e, "'" + ConfigError::excerpt(e.name) + "' is not a parameter of " + d.name +
                                      " (known: " + names + ")");
          }
          std::vector<double> values;
          for (const auto& v : e.values) {
            double x = 0;
            if (!internal::parseNumber(v, x) || !std::isfinite(x))
              throw file.errorAt(e, "'" + e.name + "': '" + ConfigError::excerpt(v) + "' is not a finite number");
            values.push_back(x);
          }
          Impl::Param& p = d.findParam(e.name);
          if (values.size() == 1 && p.info.size > 1) values.assign(p.info.size, values[0]);
          if (values.size() != p.info.size)
            throw file.errorAt(e, "ControlProgram " + d.name + ": parameter '" + e.name + "' needs " +
                                      std::to_string(p.info.size) + " values, got " + std::to_string(values.size()));
          d.checkRange(p, values);
          if (apply) setParameter(e.name, values);
        }
      } catch (const ConfigError&) {
        throw;
      } catch (const std::exception& ex) {
        throw file.errorAt(e, ex.what());
      }
    }
  }
}

void ControlProgram::saveQMotorConfig(const std::string& fileName) const {
  std::ofstream out(fileName);
  if (!out) throw std::runtime_error("saveQMotorConfig: cannot write '" + fileName + "'");
  auto fmt = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return std::string(buf);
  };
  out << "# control-program file of " << impl_->name << "\n";
  out << "rate " << fmt(impl_->rate) << "\n";
  out << "priority " << impl_->priority << "\n";
  out << "logEvery " << impl_->logEvery << "\n";
  out << "logBufferSize " << impl_->logBufferSize << "\n";
  std::string selected;
  bool all = true;
  for (auto& v : impl_->logVars) {
    if (v.selected) selected += " " + v.info.name;
    all = all && v.selected;
  }
  if (!all && !selected.empty()) out << "log" << selected << "\n";
  std::lock_guard<std::mutex> lock(impl_->paramMutex);
  for (auto& p : impl_->params) {
    out << p->info.name;
    for (double v : p->requested) out << " " << fmt(v);
    out << "\n";
  }
  if (!out) throw std::runtime_error("saveQMotorConfig: error writing '" + fileName + "'");
}

void ControlProgram::stopAll() {
  std::lock_guard<std::mutex> lock(internal::programsMutex());
  for (ControlProgram* p : internal::programs()) p->stop();
}

}  // namespace rp
