// The thread management of RoboticObject (paper section 3.2): an object asks for additional
// threads (addThread(), addPeriodicThread()); startControlLoop() starts them with the control
// loop, stopControlLoop() and the destructor stop and join them; ObjectManager's factory starts
// them for a class created by name that never calls startControlLoop() itself.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>

#include "WaitFor.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

using test::waitFor;

// Asks for one thread that runs until stopped and one periodic thread, and does not start them.
class Worker : public FunctionalObject {
 public:
  explicit Worker(const std::string& name = "") : FunctionalObject(name) {
    addThread("worker-main", [this](const std::atomic<bool>& stop) {
      running = true;
      while (!stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      running = false;
      finished = true;
    });
    addPeriodicThread("worker-tick", 0.002, [this] { ++ticks; });
  }
  ~Worker() override { stopControlLoop(); }
  std::atomic<bool> running{false}, finished{false};
  std::atomic<int> ticks{0};
};

}  // namespace
}  // namespace rp

RP_REGISTER_CLASS_AS(rp::Worker, "Worker");

namespace rp {
namespace {

TEST(ObjectThreads, StartedWithTheControlLoopAndStoppedWithIt) {
  Worker w;
  EXPECT_EQ(w.getThreadNames(), (std::vector<std::string>{"worker-main", "worker-tick"}));
  EXPECT_FALSE(w.areThreadsRunning()) << "not before startControlLoop()";
  EXPECT_FALSE(w.running.load());
  EXPECT_EQ(w.ticks.load(), 0);
  w.startControlLoop();
  EXPECT_TRUE(w.areThreadsRunning());
  EXPECT_TRUE(waitFor([&] { return w.running.load(); }));
  EXPECT_TRUE(waitFor([&] { return w.ticks.load() >= 5; })) << "ticks: " << w.ticks.load();
  w.startControlLoop();  // again: nothing more is started
  w.stopControlLoop();   // joins both
  EXPECT_FALSE(w.areThreadsRunning());
  EXPECT_TRUE(w.finished.load()) << "the thread saw its stop flag and returned before stopControlLoop() did";
  const int ticks = w.ticks.load();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(w.ticks.load(), ticks) << "no cycle after stopControlLoop()";
}

TEST(ObjectThreads, AThreadAskedForLaterStartsAtOnce) {
  std::atomic<bool> ran{false};  // outlives the thread
  Worker w;
  w.startControlLoop();
  w.addThread("late", [&](const std::atomic<bool>& stop) {
    ran = true;
    while (!stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  });
  EXPECT_TRUE(waitFor([&] { return ran.load(); }));
}

TEST(ObjectThreads, ObjectManagerStartsThemForAClassCreatedByName) {
  RoboticPlatform::setConfiguration(Configuration::parse("[worker]\nclass Worker\n", "cell.cfg"));
  ObjectManager om;
  auto* w = om.createDerivedObject<Worker>("worker");
  ASSERT_NE(w, nullptr);
  EXPECT_TRUE(w->areThreadsRunning());
  EXPECT_TRUE(waitFor([&] { return w->ticks.load() >= 3; }));
  om.deleteObject(w);
  RoboticPlatform::setConfiguration(Configuration());
}

TEST(ObjectThreads, TheDestructorJoinsThreadsLeftRunning) {
  std::atomic<bool> finished{false};
  {
    PhysicalObject o;
    o.addThread("left", [&](const std::atomic<bool>& stop) {
      while (!stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      finished = true;
    });
    o.startControlLoop();
  }  // PhysicalObject never calls stopControlLoop(): ~RoboticObject stops and joins
  EXPECT_TRUE(finished.load());
}

TEST(ObjectThreads, AnExceptionInAThreadSetsTheErrorStatus) {
  PhysicalObject o("thrower");
  o.addThread("bad", [](const std::atomic<bool>&) { throw std::runtime_error("no device"); });
  o.startControlLoop();
  EXPECT_TRUE(waitFor([&] { return o.getErrorCode() != 0; }));
  EXPECT_EQ(o.getErrorStatus().message, "thrower: thread 'bad' failed: no device");
}

TEST(ObjectThreads, BadPeriodsAreRefused) {
  PhysicalObject o;
  EXPECT_THROW(o.addPeriodicThread("t", 0, [] {}), std::invalid_argument);
  EXPECT_THROW(o.addPeriodicThread("t", -1, [] {}), std::invalid_argument);
  EXPECT_THROW(o.addPeriodicThread("t", 1e9, [] {}), std::invalid_argument);
  EXPECT_THROW(o.addPeriodicThread("t", 0.001, nullptr), std::invalid_argument);
  EXPECT_TRUE(o.getThreadNames().empty());
}

}  // namespace
}  // namespace rp
