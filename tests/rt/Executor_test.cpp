// Executors: programs of one clock, rate, priority and CPU stepped by one thread in three phases
// (read, control, write); a thread of its own on request; adding and removing programs while the
// executor runs; lockstep of several executors on a simulated clock; overruns named after the
// program that took the time. No timing thresholds: the simulated clock gives exact cycles.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "rp/rt/Clock.hpp"
#include "rp/rt/ControlProgram.hpp"

namespace rp {
namespace {

// A journal of phase calls, written only by executor threads (preallocated; one entry per call).
struct Journal {
  explicit Journal(std::size_t capacity) { entries.resize(capacity); }
  struct Entry {
    int program = -1;
    char phase = 0;  // 'r', 'c', 'w'
    std::uint64_t cycle = 0;
    std::thread::id thread;
    double time = 0;  // the cycle's clock time
  };
  void add(int program, char phase, std::uint64_t cycle, double time = 0) noexcept {
    const std::size_t i = size.fetch_add(1);
    if (i < entries.size()) entries[i] = Entry{program, phase, cycle, std::this_thread::get_id(), time};
  }
  std::vector<Entry> entries;
  std::atomic<std::size_t> size{0};
};

// Journals its phases; `measured` is its "sensor" (its cycle count, read in the read phase), and
// `seen` what it read of another program's sensor in its control().
class Phased : public ControlProgram {
 public:
  Phased(const std::string& name, int id, Journal* journal) : ControlProgram(name), id_(id), journal_(journal) {
    registerLogVariable("measured", measured);
    registerLogVariable("seen", seen);
  }
  ~Phased() override { stop(); }
  const Phased* watch = nullptr;
  double measured = -1, seen = -1;
  std::atomic<long> mismatches{0};  // cycles in which `seen` was not the watched program's sensor of this cycle
  std::atomic<long> compared{0};

 protected:
  void readInputs() override {
    measured = static_cast<double>(getCycleCount());
    if (journal_ != nullptr) journal_->add(id_, 'r', getCycleCount());
  }
  void control() override {
    if (journal_ != nullptr) journal_->add(id_, 'c', getCycleCount());
    if (watch != nullptr) {
      seen = watch->measured;
      // Both started together: the watched program's cycle k is this one's cycle k.
      if (getCycleCount() >= 1) {
        compared.fetch_add(1);
        if (seen != static_cast<double>(getCycleCount())) mismatches.fetch_add(1);
      }
    }
  }
  void writeOutputs() override {
    if (journal_ != nullptr) journal_->add(id_, 'w', getCycleCount());
  }

 private:
  int id_;
  Journal* journal_;
};

std::size_t executorsWith(const std::string& program) {
  std::size_t n = 0;
  for (const auto& e : ControlProgram::getExecutorStatistics())
    for (const auto& p : e.programs) n += p == program;
  return n;
}

TEST(Executor, ProgramsOfOneRateShareOneThreadAndRunInPhases) {
  SimulatedClock clock(1e-3, true);
  Journal journal(3 * 3 * 20);
  Phased a("a", 0, &journal), b("b", 1, &journal), c("c", 2, &journal);
  for (Phased* p : {&a, &b, &c}) {
    EXPECT_EQ(p->getThreadMode(), ThreadMode::Shared);
    p->setClock(clock);
    p->setCycleLimit(20);
    p->start();
  }
  // One executor steps all three, in the order they were started.
  const auto stats = ControlProgram::getExecutorStatistics();
  const ExecutorStatistics* shared = nullptr;
  for (const auto& e : stats)
    if (!e.programs.empty() && e.programs[0] == "a") shared = &e;
  ASSERT_NE(shared, nullptr);
  EXPECT_EQ(shared->programs, (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_FALSE(shared->ownThread);
  EXPECT_TRUE(shared->simulatedClock);
  // Paused: not even the current tick runs yet (give a wrongly eager executor time to run it).
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(journal.size.load(), 0u);
  EXPECT_EQ(a.getCycleCount(), 0u);
  clock.resume();
  for (Phased* p : {&a, &b, &c}) p->waitUntilStopped();
  EXPECT_EQ(a.getStatistics().executorPrograms, 1u);  // when each joined
  EXPECT_EQ(c.getStatistics().executorPrograms, 3u);

  ASSERT_EQ(journal.size.load(), 3u * 3u * 20u);
  const std::thread::id thread = journal.entries[0].thread;
  EXPECT_NE(thread, std::this_thread::get_id());
  // Started on a paused clock, the three begin together after resume(): every tick, the first
  // one too, steps all three in phases, in the order they were started, in the executor's thread.
  std::size_t i = 0;
  for (std::uint64_t cycle = 0; cycle < 20; ++cycle)
    for (char phase : {'r', 'c', 'w'})
      for (int program = 0; program < 3; ++program, ++i) {
        const auto& e = journal.entries[i];
        EXPECT_EQ(e.program, program) << "entry " << i;
        EXPECT_EQ(e.phase, phase) << "entry " << i;
        EXPECT_EQ(e.cycle, cycle) << "entry " << i;
        EXPECT_EQ(e.thread, thread) << "entry " << i;
      }
  EXPECT_EQ(clock.getTick(), 19u);  // the clock stops with the last program
}

TEST(Executor, ThreadOwnGivesEachProgramItsOwnThread) {
  SimulatedClock clock(1e-3, true);
  Journal journal(2 * 3 * 10);
  Phased a("own_a", 0, &journal), b("own_b", 1, &journal);
  for (Phased* p : {&a, &b}) {
    p->setThreadMode(ThreadMode::Own);
    p->setClock(clock);
    p->setCycleLimit(10);
    p->start();
  }
  EXPECT_THROW(a.setThreadMode(ThreadMode::Shared), std::logic_error);
  std::size_t own = 0;
  for (const auto& e : ControlProgram::getExecutorStatistics())
    if (e.ownThread && e.programs.size() == 1 && (e.programs[0] == "own_a" || e.programs[0] == "own_b")) ++own;
  EXPECT_EQ(own, 2u);
  clock.resume();
  a.waitUntilStopped();
  b.waitUntilStopped();
  EXPECT_TRUE(a.getStatistics().ownThread);
  ASSERT_EQ(journal.size.load(), 2u * 3u * 10u);
  std::thread::id threads[2];
  for (std::size_t i = 0; i < journal.size.load(); ++i) threads[journal.entries[i].program] = journal.entries[i].thread;
  EXPECT_NE(threads[0], threads[1]);
  EXPECT_EQ(a.getCycleCount(), 10u);
  EXPECT_EQ(b.getCycleCount(), 10u);
  EXPECT_EQ(executorsWith("own_a"), 0u);  // stopped: no executor steps it any more
}

TEST(Executor, DefaultThreadModeAppliesToNewPrograms) {
  const ThreadMode before = ControlProgram::getDefaultThreadMode();
  ControlProgram::setDefaultThreadMode(ThreadMode::Own);
  Phased a("default_own", 0, nullptr);
  ControlProgram::setDefaultThreadMode(ThreadMode::Shared);
  Phased b("default_shared", 1, nullptr);
  ControlProgram::setDefaultThreadMode(before);
  EXPECT_EQ(a.getThreadMode(), ThreadMode::Own);
  EXPECT_EQ(b.getThreadMode(), ThreadMode::Shared);
}

// The same-cycle guarantee: the reader, started first (stepped first in every phase), sees in its
// control() the sensor the other program read in the same cycle. Without the phases (each
// program's read, control and write in turn) it would see the previous cycle's. (Compared from
// cycle 1 on, where the previous cycle's sensor reading would differ.)
TEST(Executor, ControlSeesEveryInputOfTheSameCycleWhateverTheOrder) {
  SimulatedClock clock(1e-3, true);
  Phased reader("reader", 0, nullptr), sensor("sensor", 1, nullptr);
  reader.watch = &sensor;
  for (Phased* p : {&reader, &sensor}) {
    p->setClock(clock);
    p->setCycleLimit(200);
    p->start();
  }
  clock.resume();
  reader.waitUntilStopped();
  sensor.waitUntilStopped();
  EXPECT_EQ(reader.compared.load(), 199);
  EXPECT_EQ(reader.mismatches.load(), 0);
  EXPECT_EQ(reader.seen, 199);
}

// A thread of its own gives no such guarantee (the two threads run concurrently); this only
// checks that both ran every cycle in lockstep on the simulated clock.
TEST(Executor, ExecutorsOfOneSimulatedClockRunInLockstep) {
  SimulatedClock clock(1e-3, true);
  Phased fast("fast", 0, nullptr), slow("slow", 1, nullptr), own("alone", 2, nullptr);
  fast.setRate(1000);
  slow.setRate(250);
  own.setRate(1000);
  own.setThreadMode(ThreadMode::Own);
  for (Phased* p : {&fast, &slow, &own}) p->setClock(clock);
  fast.setCycleLimit(100);
  slow.setCycleLimit(25);
  own.setCycleLimit(100);
  for (Phased* p : {&fast, &slow, &own}) p->start();
  clock.resume();
  for (Phased* p : {&fast, &slow, &own}) p->waitUntilStopped();
  EXPECT_EQ(fast.getCycleCount(), 100u);
  EXPECT_EQ(slow.getCycleCount(), 25u);
  EXPECT_EQ(own.getCycleCount(), 100u);
  EXPECT_DOUBLE_EQ(fast.getTime(), 0.099);
  EXPECT_DOUBLE_EQ(slow.getTime(), 0.096);
  EXPECT_DOUBLE_EQ(own.getTime(), 0.099);
}

// Programs join and leave a running executor; the others go on without missing a cycle.
TEST(Executor, ProgramsJoinAndLeaveARunningExecutor) {
  SimulatedClock clock(1e-3);
  Phased first("first", 0, nullptr);
  first.setClock(clock);
  first.start();
  std::vector<std::unique_ptr<Phased>> others;
  for (int i = 0; i < 8; ++i) {
    others.push_back(std::make_unique<Phased>("joiner" + std::to_string(i), i + 1, nullptr));
    others.back()->setClock(clock);
    others.back()->start();
  }
  EXPECT_EQ(executorsWith("first"), 1u);
  for (int round = 0; round < 20; ++round) {
    // Remove one, start it again, while the executor keeps stepping the rest.
    Phased& p = *others[static_cast<std::size_t>(round) % others.size()];
    const std::uint64_t before = first.getCycleCount();
    p.stop();
    EXPECT_FALSE(p.isRunning());
    p.start();
    while (first.getCycleCount() < before + 3) std::this_thread::yield();
  }
  for (auto& p : others) {
    const std::uint64_t k = p->getCycleCount();
    while (p->getCycleCount() < k + 2) std::this_thread::yield();
  }
  // `first` never left: its cycles are consecutive ticks (the clock only advances when it ran).
  others.clear();
  first.stop();
  EXPECT_EQ(first.getStatistics().missedCycles, 0u);
  EXPECT_NEAR(first.getTime(), static_cast<double>(first.getCycleCount() - 1) * 1e-3, 1e-9);
  EXPECT_EQ(executorsWith("first"), 0u);
}

// A program stopped from another program's cycle (its executor's thread) ends after the cycle;
// the others go on.
class Stopper : public ControlProgram {
 public:
  Stopper(ControlProgram& victim, std::uint64_t at) : ControlProgram("stopper"), victim_(victim), at_(at) {}
  ~Stopper() override { stop(); }

 protected:
  void control() override {
    if (getCycleCount() == at_) victim_.stop();  // from the executor's thread: only asks
  }

 private:
  ControlProgram& victim_;
  std::uint64_t at_;
};

TEST(Executor, StopFromTheExecutorsThreadOnlyAsks) {
  SimulatedClock clock(1e-3, true);
  Phased victim("victim", 0, nullptr);
  Stopper stopper(victim, 10);
  victim.setClock(clock);
  stopper.setClock(clock);
  stopper.setCycleLimit(30);
  victim.start();
  stopper.start();
  clock.resume();
  stopper.waitUntilStopped();
  victim.waitUntilStopped();
  EXPECT_EQ(victim.getCycleCount(), 11u);  // cycle 10 completed, then it ended
  EXPECT_EQ(stopper.getCycleCount(), 30u);
}

// On the real clock a cycle that overruns is counted for the executor and named after the program
// that took the time (from cycle 5 on, a busy wait of 20 periods in every cycle: an overrun
// however fast the machine is, and the other program's few microseconds never the larger).
class Busy : public ControlProgram {
 public:
  Busy(const std::string& name, std::uint64_t busyCycle) : ControlProgram(name), busyCycle_(busyCycle) {}
  ~Busy() override { stop(); }

 protected:
  void control() override {
    if (getCycleCount() < busyCycle_) return;
    const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(static_cast<long>(20e6 / getRate()));
    while (std::chrono::steady_clock::now() < until) {
    }
  }

 private:
  std::uint64_t busyCycle_;
};

TEST(Executor, AnOverrunIsNamedAfterTheProgramThatTookTheTime) {
  Busy idle("idle", ~std::uint64_t{0}), hog("hog", 5);
  for (Busy* p : {&idle, &hog}) {
    p->setClock(RealClock::instance());
    p->setRate(500);
    p->setPriority(11);  // an executor of its own among the tests' (rate and priority)
    p->setCycleLimit(10);
    p->start();
  }
  bool found = false;
  ExecutorStatistics seen;
  while (hog.getCycleCount() < 7) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  for (const auto& e : ControlProgram::getExecutorStatistics())
    if (e.programs == std::vector<std::string>{"idle", "hog"}) {
      found = true;
      seen = e;
    }
  idle.waitUntilStopped();
  hog.waitUntilStopped();
  ASSERT_TRUE(found);
  EXPECT_GE(seen.overruns, 1u);
  EXPECT_GE(seen.missedCycles, 1u);
  EXPECT_EQ(seen.lastOverrunProgram, "hog");
  EXPECT_GT(seen.lastOverrunProgramTime, 0);
  EXPECT_GE(seen.wakeupLatency.count, 1u);
  EXPECT_GE(hog.getStatistics().overruns, 1u);
  EXPECT_GE(idle.getStatistics().overruns, 1u);  // every program of the executor missed the deadline
  EXPECT_GE(hog.getStatistics().computationTime.max, idle.getStatistics().computationTime.max);
  // The busy wait alone is 20 periods (40,000 us) of the monotonic clock: the program's time in
  // that cycle (timed in ticks, src/rt/Ticks.hpp, and converted) is at least that.
  EXPECT_GE(seen.lastOverrunProgramTime, 0.999 * 20e6 / 500);
  EXPECT_GE(hog.getStatistics().computationTime.max, 0.999 * 20e6 / 500);
}


// A program started from inside a cycle of an executor while another program of the same executor
// is being stopped from outside: stop() waits for the loop to let go of the list that still holds
// the stopped program, and the loop's start() needs the executors' registry. Neither may wait for
// the other while holding what the other needs (this hung before stop() waited outside the
// registry's lock). A watchdog ends the process with a message if the scenario does not finish.
class Notifier : public ControlProgram {
 public:
  explicit Notifier(const std::string& name) : ControlProgram(name) {}
  ~Notifier() override { stop(); }
  std::atomic<bool> exited{false};

 protected:
  void control() override {}
  void exitControl() override { exited.store(true); }  // in the executor's thread, in the cycle that ends it
};

class Launcher : public ControlProgram {
 public:
  Launcher(const std::string& name, Notifier& victim, ControlProgram& late)
      : ControlProgram(name), victim_(victim), late_(late) {}
  ~Launcher() override { stop(); }
  std::atomic<bool> launched{false};

 protected:
  void control() override {
    if (launched.load() || !victim_.exited.load()) return;
    // The victim ended at the start of this cycle; its stop() is now taking it out of the list and
    // waits for this cycle to end. Give it time to get there, then start a program.
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    late_.start();
    launched.store(true);
  }

 private:
  Notifier& victim_;
  ControlProgram& late_;
};

TEST(Executor, StartingAProgramInACycleWhileAnotherStopsDoesNotDeadlock) {
  std::atomic<bool> done{false};
  std::thread watchdog([&] {
    for (int i = 0; i < 300 && !done.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (!done.load()) {
      std::fprintf(stderr, "Executor deadlock: stop() and a start() from the loop wait for each other\n");
      std::_Exit(3);
    }
  });
  Notifier victim("victim"), late("late");
  Launcher launcher("launcher", victim, late);
  for (ControlProgram* p : {static_cast<ControlProgram*>(&victim), static_cast<ControlProgram*>(&late),
                            static_cast<ControlProgram*>(&launcher)}) {
    p->setClock(RealClock::instance());
    p->setRate(250);
    p->setPriority(12);  // an executor of its own among the tests' (rate and priority)
  }
  launcher.start();
  victim.start();
  while (launcher.getCycleCount() < 3) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  victim.stop();
  while (!launcher.launched.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const std::uint64_t lateCycles = late.getCycleCount();
  while (late.getCycleCount() < lateCycles + 3) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(executorsWith("late"), 1u);
  EXPECT_EQ(executorsWith("victim"), 0u);
  late.stop();
  launcher.stop();
  done.store(true);
  watchdog.join();
  EXPECT_FALSE(victim.isRunning());
}


// A spread executor (setExecutorCpus()): the programs of one rate are dealt to a thread on each
// CPU in turn, and the threads meet between the phases: every read of a cycle comes before every
// control of that cycle, every control before every write, and a control law reads another
// thread's program's input of the same cycle.
class Stamped : public ControlProgram {
 public:
  Stamped(const std::string& name, int id, Journal& journal) : ControlProgram(name), id_(id), journal_(journal) {}
  ~Stamped() override { stop(); }
  const Stamped* watch = nullptr;
  std::atomic<double> measured{-1};  // the clock time of the cycle of its last read
  std::atomic<long> compared{0}, mismatches{0};

 protected:
  void readInputs() override {
    measured.store(getTime());
    journal_.add(id_, 'r', getCycleCount(), getTime());
  }
  void control() override {
    journal_.add(id_, 'c', getCycleCount(), getTime());
    if (watch != nullptr && getCycleCount() >= 1 && watch->getCycleCount() >= 1) {
      compared.fetch_add(1);
      if (watch->measured.load() != getTime()) mismatches.fetch_add(1);
    }
  }
  void writeOutputs() override { journal_.add(id_, 'w', getCycleCount(), getTime()); }

 private:
  int id_;
  Journal& journal_;
};

TEST(Executor, ASpreadExecutorKeepsThePhasesAcrossItsThreads) {
  EXPECT_THROW(ControlProgram::setExecutorCpus({1}), std::invalid_argument);
  EXPECT_THROW(ControlProgram::setExecutorCpus({0, 0}), std::invalid_argument);
  EXPECT_THROW(ControlProgram::setExecutorCpus({-1, 1}), std::invalid_argument);
  ControlProgram::setExecutorCpus({0, 1});
  EXPECT_EQ(ControlProgram::getExecutorCpus(), (std::vector<int>{0, 1}));
  constexpr int kPrograms = 4, kCycles = 40;
  Journal journal(kPrograms * 3 * kCycles);
  std::vector<std::unique_ptr<Stamped>> programs;
  for (int i = 0; i < kPrograms; ++i) {
    programs.push_back(std::make_unique<Stamped>("spread" + std::to_string(i), i, journal));
    programs.back()->setClock(RealClock::instance());
    programs.back()->setRate(200);
    programs.back()->setPriority(13);  // an executor of its own among the tests' (rate and priority)
    programs.back()->setCycleLimit(kCycles);
  }
  programs[0]->watch = programs[1].get();  // stepped by the other thread
  programs[3]->watch = programs[2].get();
  for (auto& p : programs) p->start();
  ControlProgram::setExecutorCpus({});  // for executors started later
  bool found = false;
  for (const auto& e : ControlProgram::getExecutorStatistics())
    if (!e.programs.empty() && e.programs[0] == "spread0") {
      found = true;
      EXPECT_EQ(e.programs.size(), 4u);
      EXPECT_EQ(e.cpus, (std::vector<int>{0, 1}));
    }
  EXPECT_TRUE(found);
  for (auto& p : programs) p->waitUntilStopped();

  const std::size_t n = journal.size.load();
  ASSERT_EQ(n, static_cast<std::size_t>(kPrograms * 3 * kCycles));
  // Within each cycle (one clock time), the phases in order across both threads.
  std::map<double, std::string> phasesOfCycle;
  for (std::size_t i = 0; i < n; ++i) phasesOfCycle[journal.entries[i].time] += journal.entries[i].phase;
  // In the cycles all four programs ran, each program in one thread: programs 0 and 2 in one, 1
  // and 3 in another (program i of the executor's list in thread i mod 2). (On a loaded machine
  // the programs may join in different cycles and so reach their cycle limit in different ones: a
  // program that ended leaves the list, and the ones after it move up, to the other thread.)
  auto allRan = [&](std::size_t i) { return phasesOfCycle[journal.entries[i].time].size() == 3u * kPrograms; };
  std::vector<std::thread::id> thread(kPrograms);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (allRan(i)) thread[journal.entries[i].program] = journal.entries[i].thread;
  for (std::size_t i = 0; i < n; ++i) {
    if (!allRan(i)) continue;
    ++checked;
    EXPECT_EQ(journal.entries[i].thread, thread[journal.entries[i].program]) << i;
  }
  EXPECT_GE(checked, static_cast<std::size_t>(kPrograms * 3 * (kCycles - 10)));
  EXPECT_EQ(thread[0], thread[2]);
  EXPECT_EQ(thread[1], thread[3]);
  EXPECT_NE(thread[0], thread[1]);
  for (const auto& [time, phases] : phasesOfCycle) {
    std::string sorted = phases;
    std::sort(sorted.begin(), sorted.end(), [](char a, char b) {
      auto rank = [](char c) { return c == 'r' ? 0 : c == 'c' ? 1 : 2; };
      return rank(a) < rank(b);
    });
    EXPECT_EQ(phases, sorted) << "cycle at " << time;
  }
  for (int i : {0, 3}) {
    EXPECT_GE(programs[i]->compared.load(), kCycles - 2);
    EXPECT_EQ(programs[i]->mismatches.load(), 0) << "program " << i;
  }
}

}  // namespace
}  // namespace rp
