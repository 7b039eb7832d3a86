// ControlProgram on the simulated clock (exact cycle counts, times and log rows) and on the real
// clock (runs and reports statistics; no timing thresholds), tunable parameters, control files.
#include "rp/rt/ControlProgram.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "rp/core/Configuration.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/core/PhysicalObject.hpp"
#include "rp/rt/Clock.hpp"
#include "rp/rt/LogWriter.hpp"
#include "ScratchDirectory.hpp"

namespace rp {
namespace {

test::ScratchDirectory scratch(const std::string& name) { return test::ScratchDirectory("rp_rt_test_", name); }

std::vector<std::string> lines(const std::filesystem::path& path) {
  std::vector<std::string> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

// Records the clock time of every cycle and, optionally, another program's cycle count.
class Recorder : public ControlProgram {
 public:
  explicit Recorder(const std::string& name, std::size_t capacity = 10000) : ControlProgram(name) {
    times.reserve(capacity);
    other.reserve(capacity);
    gains.reserve(capacity);
    registerLogVariable("x", x, "m");
    registerLogVariable("q", q, "rad");
    registerParameter("gain", gain, 0, 10, "N/m", "stiffness");
    registerParameter("kp", kp, 0, 1000, "", "per joint");
  }
  ~Recorder() override { stop(); }
  std::vector<double> times, gains;
  std::vector<std::uint64_t> other;
  const ControlProgram* watch = nullptr;
  double x = 0;
  Vector<3> q;
  double gain = 1;
  Vector<3> kp = Vector<3>::Constant(100);
  std::function<void(std::uint64_t)> hook;

 protected:
  void control() override {
    const std::uint64_t k = getCycleCount();
    times.push_back(getTime());
    gains.push_back(gain);
    if (watch) other.push_back(watch->getCycleCount());
    x = static_cast<double>(k);
    q = x, 10 * x, 100 * x;
    if (hook) hook(k);
  }
};

TEST(ControlProgram, Defaults) {
  Recorder r("r");
  EXPECT_EQ(r.getRate(), 1000.0);
  EXPECT_EQ(r.getPeriod(), 0.001);
  EXPECT_EQ(r.getPriority(), 27);
  EXPECT_EQ(r.getLogEvery(), 1u);
  EXPECT_FALSE(r.isRunning());
  EXPECT_THROW(r.setRate(0), std::invalid_argument);
  EXPECT_THROW(r.setRate(0.5), std::invalid_argument);    // a period over a second
  EXPECT_THROW(r.setRate(1e-11), std::invalid_argument);  // (its period overflowed in nanoseconds)
  r.setRate(1);
  EXPECT_THROW(r.setRate(20001), std::invalid_argument);  // every cycle would overrun
  EXPECT_THROW(r.setRate(std::nan("")), std::invalid_argument);
  EXPECT_THROW(r.setLogBufferSize(1), std::invalid_argument);
  // 498560650640798720 samples from a qmotorConfig wrapped the ring's size and overflowed the heap.
  EXPECT_THROW(r.setLogBufferSize(498560650640798720ULL), std::invalid_argument);
  EXPECT_THROW(r.setLogBufferSize(ControlProgram::kMaxLogBufferSize + 1), std::invalid_argument);
  EXPECT_THROW(r.setPriority(100), std::invalid_argument);
  EXPECT_THROW(r.registerLogVariable("x", r.x), std::invalid_argument);
  EXPECT_THROW(r.registerLogVariable("a.b", r.x), std::invalid_argument);
  auto vars = r.getLogVariables();
  ASSERT_EQ(vars.size(), 2u);
  EXPECT_EQ(vars[1].size, 3u);
  EXPECT_TRUE(vars[1].vector);
  EXPECT_FALSE(vars[0].vector);
}

TEST(ControlProgram, SimulatedClockRunsExactCycles) {
  SimulatedClock clock(1e-3);
  Recorder r("r");
  r.setClock(clock);
  r.setRate(500);
  r.setCycleLimit(250);
  r.start();
  r.waitUntilStopped();
  EXPECT_FALSE(r.isRunning());
  ASSERT_EQ(r.getCycleCount(), 250u);
  ASSERT_EQ(r.times.size(), 250u);
  for (std::size_t k = 0; k < 250; ++k) EXPECT_EQ(r.times[k], static_cast<double>(2 * k) / 1000.0) << k;
  ControlStatistics s = r.getStatistics();
  EXPECT_EQ(s.cycles, 250u);
  EXPECT_EQ(s.overruns, 0u);
  EXPECT_TRUE(s.simulatedClock);
  EXPECT_EQ(s.wakeupLatency.count, 0u);
  EXPECT_EQ(s.computationTime.count, 250u);
}

// Two programs on one simulated clock run in lockstep: whenever one runs cycle k, the other has
// finished k-1 or k of its own (never further apart), and the slower one runs on every 4th tick.
TEST(ControlProgramThreads, ProgramsOnOneSimulatedClockRunInLockstep) {
  SimulatedClock clock(1e-3, true);
  Recorder a("a"), b("b"), slow("slow");
  a.setClock(clock);
  b.setClock(clock);
  slow.setClock(clock);
  slow.setRate(250);
  a.watch = &b;
  b.watch = &a;
  a.setCycleLimit(2000);
  b.setCycleLimit(2000);
  slow.setCycleLimit(500);
  a.start();
  b.start();
  slow.start();
  EXPECT_EQ(clock.getNumberOfPrograms(), 3);
  clock.resume();
  a.waitUntilStopped();
  b.waitUntilStopped();
  slow.waitUntilStopped();
  ASSERT_EQ(a.other.size(), 2000u);
  for (std::size_t k = 0; k < 2000; ++k) {
    EXPECT_TRUE(a.other[k] == k || a.other[k] == k + 1) << k << " " << a.other[k];
    EXPECT_TRUE(b.other[k] == k || b.other[k] == k + 1) << k << " " << b.other[k];
    EXPECT_EQ(a.times[k], b.times[k]);
  }
  for (std::size_t k = 0; k < 500; ++k) EXPECT_EQ(slow.times[k], static_cast<double>(4 * k) / 1000.0);
  EXPECT_EQ(clock.getNumberOfPrograms(), 0);
}

// Started again after a stop (QMotor's Start), a program goes on in its own columns of the log
// file (not as a second program 'a_2'), and its rows follow the earlier ones (on the simulated
// clock its first cycle is the tick after its last, not the tick of the last again: that row
// was overwritten).
TEST(ControlProgramThreads, ARestartedProgramGoesOnInItsOwnLogColumns) {
  auto dir = scratch("restart");
  const auto file = dir / "log.csv";
  {
    LogWriter writer(file.string());
    SimulatedClock clock(1e-3);
    Recorder a("a");
    a.setClock(clock);
    a.setLogWriter(&writer);
    a.setCycleLimit(100);
    a.start();
    a.waitUntilStopped();
    a.start();
    a.waitUntilStopped();
    writer.close();
  }
  auto rows = lines(file);
  ASSERT_EQ(rows.size(), 201u);
  EXPECT_EQ(rows[0], "t,a.x,a.q[0],a.q[1],a.q[2]");
  double last = -1;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const double t = std::stod(rows[i].substr(0, rows[i].find(',')));
    EXPECT_GT(t, last) << rows[i];
    last = t;
  }
  std::filesystem::remove_all(dir);
}

TEST(ControlProgramThreads, LogRowsOnTheSimulatedClock) {
  auto dir = scratch("log");
  const auto file = dir / "log.csv";
  {
    LogWriter writer(file.string());
    SimulatedClock clock(1e-3, true);
    Recorder a("a"), b("b");
    for (Recorder* r : {&a, &b}) {
      r->setClock(clock);
      r->setLogWriter(&writer);
      r->setLogBufferSize(2048);  // room for the whole run: nothing can be lost
      r->setCycleLimit(1000);
    }
    b.setLogEvery(2);
    a.start();
    b.start();
    clock.resume();
    a.waitUntilStopped();
    b.waitUntilStopped();
    const std::uint64_t lostA = a.getStatistics().lostLogSamples, lostB = b.getStatistics().lostLogSamples;
    writer.close();
    EXPECT_EQ(writer.getLostSamples(), lostA + lostB);
    EXPECT_EQ(a.getStatistics().logSamples, 1000u);
    EXPECT_EQ(b.getStatistics().logSamples, 500u);
    EXPECT_EQ(lostA + lostB, 0u);
  }
  auto rows = lines(file);
  std::string firstRows;
  for (std::size_t i = 0; i < rows.size() && i < 80; ++i) firstRows += rows[i] + "\n";
  ASSERT_EQ(rows.size(), 1001u) << firstRows;
  EXPECT_EQ(rows[0], "t,a.x,a.q[0],a.q[1],a.q[2],b.x,b.q[0],b.q[1],b.q[2]");
  EXPECT_EQ(rows[1], "0,0,0,0,0,0,0,0,0");
  EXPECT_EQ(rows[2], "0.001,1,1,10,100,,,,");
  EXPECT_EQ(rows[3], "0.002,2,2,20,200,2,2,20,200");
  EXPECT_EQ(rows[1000], "0.999,999,999,9990,99900,,,,");
}

TEST(ControlProgramThreads, ProgramsWithTheSameNameGetDistinctColumns) {
  auto dir = scratch("samename");
  const auto file = dir / "log.csv";
  {
    LogWriter writer(file.string());
    SimulatedClock clock(1e-3, true);
    Recorder a("arm"), b("arm");
    for (Recorder* r : {&a, &b}) {
      r->setClock(clock);
      r->setLogWriter(&writer);
      r->setCycleLimit(3);
      r->start();
    }
    clock.resume();
    a.waitUntilStopped();
    b.waitUntilStopped();
  }
  auto rows = lines(file);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0], "t,arm.x,arm.q[0],arm.q[1],arm.q[2],arm_2.x,arm_2.q[0],arm_2.q[1],arm_2.q[2]");
  EXPECT_EQ(rows[3], "0.002,2,2,20,200,2,2,20,200");
}

TEST(ControlProgramThreads, OnTheSimulatedClockTheLogLosesNothing) {
  auto dir = scratch("simwait");
  LogWriter writer((dir / "log.csv").string());
  SimulatedClock clock(1e-3);
  // A program that would outrun the writer: its ring holds 2 samples. On the simulated clock it
  // waits for the writer to drain the ring, so every sample reaches the file.
  Recorder r("r", 5000);
  r.setClock(clock);
  r.setLogWriter(&writer);
  r.setLogBufferSize(2);
  r.setCycleLimit(5000);
  r.start();
  r.waitUntilStopped();
  writer.close();
  const ControlStatistics s = r.getStatistics();
  EXPECT_EQ(s.logSamples, 5000u);
  EXPECT_EQ(s.lostLogSamples, 0u);
  EXPECT_EQ(writer.getLostSamples(), 0u);
  EXPECT_EQ(lines(dir / "log.csv").size(), 1u + 5000u);
}

TEST(ControlProgramThreads, LogRingOverflowIsCountedOnTheRealClock) {
  auto dir = scratch("overflow");
  LogWriter writer((dir / "log.csv").string());
  // On the real clock the loop never waits for the writer: with a ring of 2 samples at 10 kHz
  // samples are lost, and every lost one is counted (the file has exactly the others).
  Recorder r("r", 2000);
  r.setClock(RealClock::instance());
  r.setRate(10000);
  r.setLogWriter(&writer);
  r.setLogBufferSize(2);
  r.setCycleLimit(2000);
  r.start();
  r.waitUntilStopped();
  writer.close();
  const ControlStatistics s = r.getStatistics();
  EXPECT_EQ(s.logSamples, 2000u);
  EXPECT_EQ(writer.getLostSamples(), s.lostLogSamples);
  EXPECT_EQ(lines(dir / "log.csv").size(), 1 + 2000 - s.lostLogSamples);
}

TEST(ControlProgramThreads, RealClockRunsAndReportsStatistics) {
  Recorder r("real");
  r.setClock(RealClock::instance());
  r.setRate(2000);
  r.setCycleLimit(100);
  r.start();
  r.waitUntilStopped();
  const ControlStatistics s = r.getStatistics();
  EXPECT_EQ(s.cycles, 100u);
  EXPECT_FALSE(s.simulatedClock);
  EXPECT_EQ(s.wakeupLatency.count, 100u);
  EXPECT_LE(s.wakeupLatency.min, s.wakeupLatency.p50);
  EXPECT_LE(s.wakeupLatency.p50, s.wakeupLatency.p99);
  EXPECT_LE(s.wakeupLatency.p99, s.wakeupLatency.max);
  EXPECT_LE(s.wakeupLatency.min, s.wakeupLatency.mean);
  EXPECT_LE(s.wakeupLatency.mean, s.wakeupLatency.max);
  EXPECT_EQ(s.computationTime.count, 100u);
  // Deadlines are absolute: cycle times are whole periods after the first.
  for (std::size_t k = 1; k < r.times.size(); ++k) {
    const double periods = (r.times[k] - r.times[0]) / 0.0005;
    EXPECT_NEAR(periods, std::round(periods), 1e-6);
  }
}

TEST(ControlProgramThreads, StopEndsAnUnlimitedLoop) {
  Recorder r("forever");
  r.setClock(RealClock::instance());
  r.start();
  EXPECT_TRUE(r.isRunning());
  EXPECT_THROW(r.start(), std::logic_error);
  EXPECT_THROW(r.setRate(10), std::logic_error);
  while (r.getCycleCount() < 5) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  r.stop();
  EXPECT_FALSE(r.isRunning());
  r.stop();  // idempotent
}

// A parameter set from another thread is applied at the start of the next cycle, not earlier.
TEST(ControlProgramThreads, TunedParameterIsSeenOnTheNextCycle) {
  SimulatedClock clock(1e-3);
  Recorder r("tune");
  r.setClock(clock);
  r.setCycleLimit(20);
  std::atomic<int> phase{0};
  r.hook = [&](std::uint64_t k) {
    if (k == 10) {
      phase = 1;  // ask the test thread to tune, and wait until it has
      while (phase != 2) std::this_thread::yield();
    }
  };
  r.start();
  while (phase != 1) std::this_thread::yield();
  r.setParameter("gain", 5.0);
  r.setParameter("kp", 2, 7.0);
  EXPECT_EQ(r.getParameter("gain"), std::vector<double>{5.0});
  EXPECT_EQ(r.getParameter("kp"), (std::vector<double>{100, 100, 7}));
  phase = 2;
  r.waitUntilStopped();
  for (std::size_t k = 0; k <= 10; ++k) EXPECT_EQ(r.gains[k], 1.0) << k;
  for (std::size_t k = 11; k < 20; ++k) EXPECT_EQ(r.gains[k], 5.0) << k;
  EXPECT_EQ(r.kp(2), 7.0);
  EXPECT_EQ(r.kp(0), 100.0);
}

TEST(ControlProgram, ParameterErrors) {
  Recorder r("p");
  try {
    r.setParameter("gain", 11.0);
    FAIL();
  } catch (const std::out_of_range& e) {
    EXPECT_STREQ(e.what(), "ControlProgram p: parameter 'gain' = 11 is outside [0, 10] N/m");
  }
  EXPECT_EQ(r.gain, 1.0);
  try {
    r.setParameter("gian", 1.0);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "ControlProgram p: no parameter 'gian' (known: gain, kp)");
  }
  EXPECT_THROW(r.setParameter("kp", 3, 1.0), std::out_of_range);
  EXPECT_THROW(r.setParameter("kp", std::vector<double>{1, 2}), std::invalid_argument);
  EXPECT_THROW(r.setParameter("kp", std::nan("")), std::out_of_range);
  r.setParameter("gain", 2.5);  // not running: applied at once
  EXPECT_EQ(r.gain, 2.5);
  double bad = 20;
  EXPECT_THROW(r.registerParameter("bad", bad, 0, 10), std::invalid_argument);
  EXPECT_THROW(r.registerParameter("gain", bad, 0, 100), std::invalid_argument);
  ASSERT_EQ(r.getParameters().size(), 2u);
  EXPECT_EQ(r.getParameters()[0].unit, "N/m");
}

TEST(ControlProgram, QMotorConfigFile) {
  Recorder r("leader");
  r.applyQMotorConfig(ParameterFile::parse("rate 500\nlogEvery 5\ngain 3\nkp 1 2 3\nlog q\n", "leader.cfg"));
  EXPECT_EQ(r.getRate(), 500.0);
  EXPECT_EQ(r.getLogEvery(), 5u);
  EXPECT_EQ(r.gain, 3.0);
  EXPECT_EQ(r.kp(1), 2.0);
  auto message = [&](const std::string& text) {
    try {
      r.applyQMotorConfig(ParameterFile::parse(text, "leader.cfg"));
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message("gain 1\nkx 1\n"),
            "leader.cfg:2: 'kx' is not a parameter of leader (known: rate, priority, logEvery, logBufferSize, log, gain, kp)");
  EXPECT_EQ(message("gain 12\n"),
            "leader.cfg:1: ControlProgram leader: parameter 'gain' = 12 is outside [0, 10] N/m");
  EXPECT_EQ(message("kp 1 2\n"), "leader.cfg:1: ControlProgram leader: parameter 'kp' needs 3 values, got 2");
  EXPECT_EQ(message("rate 1 2\n"), "leader.cfg:1: 'rate' needs 1 value, got 2");
  EXPECT_EQ(message("log q tau\n"), "leader.cfg:1: 'log': 'tau' is not a log variable of leader (known: x, q)");
  EXPECT_EQ(message("rate -5\n"), "leader.cfg:1: 'rate' must be a number in [1, 20000] Hz, got '-5'");
  EXPECT_EQ(message("kp 7\n"), "no error");  // one value for every element
  EXPECT_EQ(r.kp(2), 7.0);

  // Saved and read back, the file reproduces the settings.
  auto dir = scratch("qmotor");
  r.setParameter("gain", 0.1);
  r.saveQMotorConfig((dir / "saved.cfg").string());
  Recorder copy("leader");
  copy.applyQMotorConfig(ParameterFile::read((dir / "saved.cfg").string()));
  EXPECT_EQ(copy.gain, 0.1);
  EXPECT_EQ(copy.kp(2), 7.0);
  EXPECT_EQ(copy.getRate(), 500.0);
  EXPECT_EQ(copy.getLogEvery(), 5u);
}

// Every size and count a control-program file gives is bounded and checked as a whole number
// before any conversion; each refusal names the file, the line and the setting (issue 19).
TEST(ControlProgram, QMotorConfigValuesAreBounded) {
  Recorder r("leader");
  auto message = [&](const std::string& text) {
    try {
      r.applyQMotorConfig(ParameterFile::parse(text, "leader.cfg"));
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // The size product of this one wrapped and overflowed the log buffer in the servo thread.
  EXPECT_EQ(message("gain 1\nlogBufferSize 498560650640798720\n"),
            "leader.cfg:2: 'logBufferSize' must be an integer in 2..1000000, got '498560650640798720'");
  EXPECT_EQ(message("logBufferSize 1e9\n"), "leader.cfg:1: 'logBufferSize' must be an integer in 2..1000000, got '1e9'");
  EXPECT_EQ(message("logBufferSize 1\n"), "leader.cfg:1: 'logBufferSize' must be an integer in 2..1000000, got '1'");
  EXPECT_EQ(message("logBufferSize 100.5\n"),
            "leader.cfg:1: 'logBufferSize' must be an integer in 2..1000000, got '100.5'");
  EXPECT_EQ(message("rate 1e9\n"), "leader.cfg:1: 'rate' must be a number in [1, 20000] Hz, got '1e9'");
  EXPECT_EQ(message("rate 0\n"), "leader.cfg:1: 'rate' must be a number in [1, 20000] Hz, got '0'");
  // A period over a second: rate 1e-11 overflowed the period in nanoseconds (the simulated arm's
  // joints became NaN), 1e-3 left a shutdown waiting 1000 s for the cycle.
  EXPECT_EQ(message("rate 0.5\n"), "leader.cfg:1: 'rate' must be a number in [1, 20000] Hz, got '0.5'");
  EXPECT_EQ(message("rate 1e-11\n"), "leader.cfg:1: 'rate' must be a number in [1, 20000] Hz, got '1e-11'");
  EXPECT_EQ(message("logEvery 4294967297\n"),
            "leader.cfg:1: 'logEvery' must be an integer in 1..1000000, got '4294967297'");
  EXPECT_EQ(message("logEvery 0\n"), "leader.cfg:1: 'logEvery' must be an integer in 1..1000000, got '0'");
  EXPECT_EQ(message("logEvery 2.5\n"), "leader.cfg:1: 'logEvery' must be an integer in 1..1000000, got '2.5'");
  EXPECT_EQ(message("priority 1.5\n"), "leader.cfg:1: 'priority' must be an integer in 1..99, got '1.5'");
  EXPECT_EQ(message("priority 100\n"), "leader.cfg:1: 'priority' must be an integer in 1..99, got '100'");
  EXPECT_EQ(r.getLogEvery(), 1u) << "nothing of a refused line is applied";
  // The largest values accepted.
  EXPECT_EQ(message("rate 20000\nlogEvery 1000000\nlogBufferSize 1000000\npriority 99\n"), "no error");
  EXPECT_EQ(r.getRate(), 20000.0);
  EXPECT_EQ(r.getLogEvery(), 1000000u);
  EXPECT_EQ(r.getPriority(), 99);
  EXPECT_EQ(message("rate 1e0\nlogEvery 1e3\nlogBufferSize +2\npriority 1\n"), "no error");
  EXPECT_EQ(r.getRate(), 1.0);
  EXPECT_EQ(r.getLogEvery(), 1000u);
  // A huge word is quoted as a short excerpt only.
  const std::string huge(10 << 20, 'q');
  const std::string m = message("log " + huge + "\n");
  EXPECT_LT(m.size(), 200u) << m.substr(0, 200);
  EXPECT_EQ(m.rfind("leader.cfg:1: 'log': 'qqqq", 0), 0u) << m.substr(0, 200);
  EXPECT_NE(m.find("...' is not a log variable of leader"), std::string::npos) << m.substr(0, 200);
}

// An object with a control loop asks for a system shutdown from inside its cycle; the request
// reaches every object, and the loops stop.
class LoopObject : public PhysicalObject, public ControlProgram {
 public:
  explicit LoopObject(SimulatedClock& clock, std::uint64_t failAt) : failAt_(failAt) {
    setClock(clock);
    startControlLoop();
  }
  ~LoopObject() override { stopControlLoop(); }
  ControlProgram* getControlProgram() override { return this; }

 protected:
  void control() override {
    if (getCycleCount() == failAt_) {
      setError(3, "torque limit exceeded");
      requestSystemShutdown("torque limit exceeded on joint 3");
    }
  }

 private:
  std::uint64_t failAt_;
};

class TunableObject : public FunctionalObject, public ControlProgram {
 public:
  TunableObject() : FunctionalObject("tunable") {
    registerParameter("kp", kp_, 0, 500, "N m/rad", "proportional gain");
    registerParameter("limit", limit_, 0, 10, "rad");
  }
  ControlProgram* getControlProgram() override { return this; }

 protected:
  void control() override {}

 private:
  Vector<6> kp_ = Vector<6>::Constant(10);
  double limit_ = 1;
};

TEST(ControlProgram, ControlPanelListsTheTunableParameters) {
  TunableObject o;
  ControlPanel panel = o.getControlPanel();
  EXPECT_EQ(panel.title, "tunable (TunableObject)");
  ASSERT_EQ(panel.fields.size(), 3u);
  EXPECT_EQ(panel.fields[0].name, "errorCode");
  EXPECT_FALSE(panel.fields[0].tunable);
  const ControlPanelField& kp = panel.fields[1];
  EXPECT_EQ(kp.name, "kp");
  EXPECT_EQ(kp.label, "proportional gain");
  EXPECT_EQ(kp.kind, FieldKind::Vector);
  EXPECT_EQ(kp.size, 6);
  EXPECT_EQ(kp.unit, "N m/rad");
  EXPECT_EQ(kp.max, 500.0);
  EXPECT_TRUE(kp.tunable);
  EXPECT_EQ(panel.fields[2].kind, FieldKind::Number);
  EXPECT_EQ(panel.fields[2].label, "limit");
}

TEST(ControlProgramThreads, ShutdownRequestedInsideALoopReachesEveryObject) {
  ObjectManager::resetShutdown();
  SimulatedClock clock(1e-3, true);  // paused until every object exists
  LoopObject failing(clock, 50), other(clock, 1u << 30);
  PhysicalObject passive;
  EXPECT_TRUE(failing.needsControlLoop());
  EXPECT_TRUE(failing.getInfo().hasControlLoop);
  EXPECT_EQ(failing.getProgramName(), failing.getName());
  clock.resume();
  ASSERT_TRUE(ObjectManager::waitForShutdown(60));
  EXPECT_EQ(ObjectManager::getShutdownReason(), "torque limit exceeded on joint 3");
  EXPECT_EQ(failing.getErrorStatus().message, "torque limit exceeded");
  for (RoboticObject* o : std::initializer_list<RoboticObject*>{&failing, &other, &passive}) {
    EXPECT_TRUE(o->isShuttingDown()) << o->getName();
    EXPECT_TRUE(o->isShutdownComplete()) << o->getName();
  }
  EXPECT_FALSE(failing.isRunning());
  EXPECT_FALSE(other.isRunning());
  EXPECT_GE(failing.getCycleCount(), 51u);
  ObjectManager::resetShutdown();
}

}  // namespace
}  // namespace rp
