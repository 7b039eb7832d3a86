// Many arms in one executor: a follower whose setpoint is the leader's measured position uses the
// leader's reading of the same cycle (row k of the leader's log in row k of its own, never k-1),
// whatever the order in which they were made, also with other threads loading the machine; and a
// hundred arms' servo cycles in one executor do not allocate.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "AllocationCounter.hpp"
#include "SimulatedArmTest.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

using test::simClock;
using SameCycleTest = test::SimulatedArmTest;

// The follower's trajectory: the leader's measured joint positions, read from the servo thread
// (DefaultManipulator::getJointPosition() there returns the current cycle's reading, no lock).
class FollowMeasured : public TrajectoryGenerator {
 public:
  explicit FollowMeasured(Manipulator& leader) : leader_(leader) {}
  ~FollowMeasured() override { releaseFromManipulators(); }
  bool getCurrentSetpoint(double, Setpoint& sp) override {
    sp.position = leader_.getJointPosition();
    sp.velocity.setZero();
    sp.acceleration.setZero();
    return true;
  }

 private:
  Manipulator& leader_;
};

// Column `column` of QMotor's log CSV, by time.
std::map<double, double> column(const std::string& csv, const std::string& column) {
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  {
    std::istringstream h(line);
    std::string cell;
    while (std::getline(h, cell, ',')) header.push_back(cell);
  }
  std::size_t index = 0;
  while (index < header.size() && header[index] != column) ++index;
  EXPECT_LT(index, header.size()) << column << " in " << line;
  std::map<double, double> out;
  while (std::getline(in, line)) {
    std::istringstream r(line);
    std::string cell;
    std::vector<double> row;
    while (std::getline(r, cell, ',')) row.push_back(std::stod(cell));
    if (index < row.size()) out[row[0]] = row[index];
  }
  return out;
}

// Drives the leader along a ramp, the follower to the leader's measured position, under load (two
// threads spinning on the machine's two cores), and checks in their logs that the follower's
// setpoint of every cycle is the leader's reading of that cycle. `pause`/`resume` hold the clock
// while the captures are set up (nothing on the real clock).
void checkFollowerUsesTheSameCycle(Puma560& follower, Puma560& leader, void (*pause)(), void (*resume)()) {
  pause();
  test::JointRamp ramp(0, 0.3);
  FollowMeasured follow(leader);
  leader.setTrajectoryGenerator(ramp);
  follower.setTrajectoryGenerator(follow);
  constexpr std::size_t kRows = 400;
  leader.setLogCapture(LogCaptureSettings{{"q"}, 1, kRows, "", 0, true});
  follower.setLogCapture(LogCaptureSettings{{"qdes"}, 1, kRows, "", 0, true});
  std::atomic<bool> loaded{true};
  std::vector<std::thread> load;
  for (int i = 0; i < 2; ++i)
    load.emplace_back([&] {
      volatile double x = 0;
      while (loaded.load(std::memory_order_relaxed)) x = x + 1;
    });
  resume();
  while (leader.getLogCaptureStatus().rows < kRows || follower.getLogCaptureStatus().rows < kRows)
    ASSERT_TRUE(leader.waitForCycles(10));
  loaded = false;
  for (auto& t : load) t.join();
  pause();

  const auto measured = column(leader.getLogCaptureCsv(), "leader.q[0]");
  const auto setpoint = column(follower.getLogCaptureCsv(), "follower.qdes[0]");
  ASSERT_EQ(measured.size(), kRows);
  std::size_t same = 0, previous = 0, rows = 0;
  double last = std::numeric_limits<double>::quiet_NaN();
  for (const auto& [t, q] : measured) {
    auto it = setpoint.find(t);
    if (it == setpoint.end()) {
      last = q;
      continue;
    }
    ++rows;
    same += it->second == q;
    previous += it->second == last && last != q;
    last = q;
  }
  EXPECT_GE(rows, kRows - 10);  // the two captures began in the same cycle or a few apart
  EXPECT_EQ(same, rows);
  EXPECT_EQ(previous, 0u);
  // The leader moved in (nearly) every row, so the previous row's reading would not do.
  EXPECT_GT(measured.rbegin()->second - measured.begin()->second, 0.05);
  EXPECT_EQ(leader.getErrorCode(), 0) << leader.getErrorStatus().message;
  EXPECT_EQ(follower.getErrorCode(), 0) << follower.getErrorStatus().message;
}

TEST_F(SameCycleTest, FollowerUsesTheLeadersMeasurementOfTheSameCycle) {
  // The follower is made (and started) first: it is stepped first in every phase.
  Puma560 follower("follower"), leader("leader");
  ASSERT_EQ(follower.getThreadMode(), ThreadMode::Shared);
  ASSERT_TRUE(leader.waitForCycles(5));
  checkFollowerUsesTheSameCycle(
      follower, leader, [] { simClock().pause(); }, [] { simClock().resume(); });
}

// The same on the real clock with the executor spread over both CPUs (setExecutorCpus()): the
// follower is stepped by the loop's thread, the leader by the worker on the other CPU, and the
// threads meet between the phases.
TEST_F(SameCycleTest, FollowerOnAnotherCpuOfASpreadExecutorUsesTheSameCycle) {
  RoboticPlatform::useRealClock();
  ControlProgram::setExecutorCpus({0, 1});
  {
    Puma560 follower("follower"), leader("leader");
    ControlProgram::setExecutorCpus({});
    bool spread = false;
    for (const auto& e : ControlProgram::getExecutorStatistics())
      if (e.programs == std::vector<std::string>{"follower", "leader"}) spread = e.cpus == std::vector<int>{0, 1};
    EXPECT_TRUE(spread);
    ASSERT_TRUE(leader.waitForCycles(5));
    checkFollowerUsesTheSameCycle(follower, leader, [] {}, [] {});
  }
  simClock();  // back to the simulated clock for the other tests
}

// A servo control that throws in its `at`-th call; counts the other arm's cycles it has seen.
class ThrowsAt : public ServoControl {
 public:
  ThrowsAt(int at, const ControlProgram& other) : at_(at), other_(other) {}
  ~ThrowsAt() override { releaseFromManipulator(); }
  void calculate() override {
    if (calls == 0) otherCyclesAtFirst = other_.getCycleCount();
    if (++calls == at_) {
      otherCyclesAtFault = other_.getCycleCount();
      throw std::runtime_error("encoder cable cut");
    }
    dynamic_cast<DefaultManipulator&>(*d_manipulator).getDefaultPositionControl().calculate();
  }
  std::atomic<int> calls{0};
  std::atomic<std::uint64_t> otherCyclesAtFirst{0}, otherCyclesAtFault{0};

 private:
  int at_;
  const ControlProgram& other_;
};

// A fault in one arm of an executor: that arm holds from the cycle of the fault, the other
// completes that cycle and is then held by the system shutdown; both end powered off.
TEST_F(SameCycleTest, AFaultInOneArmShutsDownSafelyAndTheOtherCompletesTheCycle) {
  Puma560 faulty("faulty"), other("other");
  ASSERT_TRUE(other.waitForCycles(5));
  simClock().pause();
  ThrowsAt control(50, other);
  faulty.setServoControl(control);
  simClock().resume();
  ASSERT_TRUE(ObjectManager::waitForShutdown(10));
  for (int i = 0; i < 10000 && !(faulty.isShutdownComplete() && other.isShutdownComplete()); ++i)
    other.waitForCycles(1, 1);
  EXPECT_TRUE(faulty.isShutdownComplete());
  EXPECT_TRUE(other.isShutdownComplete());
  EXPECT_FALSE(faulty.isArmPowerOn());
  EXPECT_FALSE(other.isArmPowerOn());
  EXPECT_EQ(control.calls.load(), 50) << "the control ran no cycle after the one that failed";
  EXPECT_NE(faulty.getErrorStatus().message.find("the servo control threw: encoder cable cut"), std::string::npos)
      << faulty.getErrorStatus().message;
  EXPECT_EQ(other.getErrorCode(), 0) << other.getErrorStatus().message;
  // `faulty` was made first: in the fault's cycle `other` had not yet completed it, and did so.
  EXPECT_EQ(control.otherCyclesAtFault.load(), control.otherCyclesAtFirst.load() + 49);
  EXPECT_GT(other.getCycleCount(), control.otherCyclesAtFault.load());
  for (Puma560* arm : {&faulty, &other}) {
    const JointVector q = arm->getJointPosition();
    for (int i = 0; i < 6; ++i) EXPECT_TRUE(std::isfinite(q(i))) << arm->getName() << " joint " << i + 1;
  }
}

// Counts the allocations of its executor's thread from its 50th cycle on (readInputs() runs first
// in the cycle, so a count from one read phase to the next covers a whole cycle of every program
// of the executor).
class ExecutorProbe : public ControlProgram {
 public:
  ExecutorProbe() : ControlProgram("probe") {}
  ~ExecutorProbe() override { stop(); }
  std::atomic<std::size_t> allocations{0};
  std::atomic<std::uint64_t> counted{0};

 protected:
  void readInputs() override {
    const std::size_t now = test::allocationCount();
    if (getCycleCount() > 50) {
      allocations.store(allocations.load() + (now - last_));
      counted.store(counted.load() + 1);
    }
    last_ = now;
  }
  void control() override {}

 private:
  std::size_t last_ = 0;
};

TEST_F(SameCycleTest, AHundredArmsInOneExecutorDoNotAllocate) {
  constexpr int kArms = 100;
  std::vector<std::unique_ptr<Puma560>> arms;
  std::vector<std::unique_ptr<test::JointRamp>> ramps;
  for (int i = 0; i < kArms; ++i) {
    arms.push_back(std::make_unique<Puma560>("arm" + std::to_string(i)));
    ramps.push_back(std::make_unique<test::JointRamp>(i % 6, 0.05, 0.2));
    arms.back()->setTrajectoryGenerator(*ramps.back());
  }
  ExecutorProbe probe;
  probe.setClock(simClock());
  probe.setRate(arms[0]->getRate());
  probe.setPriority(arms[0]->getPriority());
  probe.start();
  while (probe.counted.load() < 400) ASSERT_TRUE(arms[0]->waitForCycles(50));
  // One executor steps the hundred arms and the probe.
  std::size_t together = 0;
  for (const auto& e : ControlProgram::getExecutorStatistics())
    if (!e.programs.empty() && e.programs.back() == "probe") together = e.programs.size();
  EXPECT_EQ(together, static_cast<std::size_t>(kArms) + 1);
  simClock().pause();
  EXPECT_EQ(probe.allocations.load(), 0u);
  for (auto& arm : arms) EXPECT_EQ(arm->getErrorCode(), 0) << arm->getErrorStatus().message;
  simClock().resume();
}

}  // namespace
}  // namespace rp
