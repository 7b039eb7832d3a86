// Publication of objects to other threads (RoboticObject::publishObject / withdrawObject and
// ObjectReference): what the Scene Viewer relies on to never read an object being constructed or
// destroyed. Labelled "threads" so ThreadSanitizer checks the ordering too.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "rp/core/ObjectManager.hpp"
#include "rp/core/PhysicalObject.hpp"
#include "rp/effector/DefaultGripper.hpp"

namespace {

// Publishes itself last in its constructor and withdraws first in its destructor; `alive`
// tells whether a reader ever sees it outside that window.
class Probe : public rp::PhysicalObject {
 public:
  explicit Probe(const std::string& name) : rp::PhysicalObject(name) {
    value_ = 42;
    publishObject();
  }
  ~Probe() override {
    withdrawObject();
    value_ = -1;
  }
  int value() const { return value_; }

 private:
  int value_ = 0;
};

bool listed(const std::vector<rp::ObjectReference>& refs, const std::string& name) {
  for (const auto& r : refs)
    if (r->getName() == name) return true;
  return false;
}

TEST(ObjectPublication, OnlyCompleteObjectsArePublished) {
  rp::ObjectManager om;
  rp::PhysicalObject plain("plain");  // a plain object: published by its owner
  EXPECT_FALSE(plain.isObjectPublished());
  EXPECT_FALSE(om.findPublishedObject("plain"));
  EXPECT_FALSE(listed(om.getPublishedObjects(), "plain"));
  plain.publishObject();
  EXPECT_TRUE(plain.isObjectPublished());
  EXPECT_TRUE(listed(om.getPublishedObjects(), "plain"));
  {
    Probe probe("probe");  // publishes itself
    rp::DefaultGripper gripper("gripper");  // library classes publish themselves
    EXPECT_TRUE(probe.isObjectPublished());
    EXPECT_TRUE(gripper.isObjectPublished());
    rp::ObjectReference r = om.findPublishedObject("probe");
    ASSERT_TRUE(r);
    EXPECT_EQ(r.get(), &probe);
    EXPECT_EQ(r.as<Probe>()->value(), 42);
    EXPECT_EQ(r.as<rp::DefaultGripper>(), nullptr);
  }  // the reference is released before the probe goes (else its destructor would wait)
  EXPECT_FALSE(om.findPublishedObject("probe"));
  EXPECT_FALSE(om.findPublishedObject("nothing"));
  plain.withdrawObject();
  EXPECT_FALSE(plain.isObjectPublished());
  EXPECT_FALSE(om.findPublishedObject("plain"));
  // Names are listed whether published or not.
  auto names = om.getObjectNames();
  EXPECT_NE(std::find(names.begin(), names.end(), "plain"), names.end());
}

TEST(ObjectPublication, WithdrawWaitsForReferencesOfOtherThreads) {
  rp::ObjectManager om;
  auto probe = std::make_unique<Probe>("waited");
  std::atomic<bool> taken{false}, release{false}, sawValue{false};
  std::thread reader([&] {
    rp::ObjectReference r = om.findPublishedObject("waited");
    taken = true;
    while (!release) std::this_thread::yield();
    sawValue = r.as<Probe>()->value() == 42;  // the destructor is waiting: still intact
  });
  while (!taken) std::this_thread::yield();
  std::atomic<bool> destroyed{false};
  std::thread destroyer([&] {
    probe.reset();
    destroyed = true;
  });
  // The destructor cannot finish while the reference is held. (No timing is asserted: we only
  // check the order of events.)
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(destroyed.load());
  release = true;
  reader.join();
  destroyer.join();
  EXPECT_TRUE(sawValue.load());
  EXPECT_TRUE(destroyed.load());
}

TEST(ObjectPublication, OwnReferenceDoesNotDeadlockWithdraw) {
  rp::ObjectManager om;
  Probe probe("self");
  rp::ObjectReference r = om.findPublishedObject("self");
  ASSERT_TRUE(r);
  probe.withdrawObject();  // a reference of the calling thread is not waited for
  EXPECT_FALSE(probe.isObjectPublished());
  EXPECT_FALSE(om.findPublishedObject("self"));
  r.reset();
}

TEST(ObjectPublication, ReaderNeverSeesIncompleteObjects) {
  // A reader that keeps looking objects up while another thread creates and destroys them:
  // every object it reaches is complete and alive (ThreadSanitizer checks the ordering).
  rp::ObjectManager om;
  std::atomic<bool> stop{false};
  std::atomic<int> reads{0}, bad{0};
  std::thread reader([&] {
    while (!stop) {
      for (const rp::ObjectReference& r : om.getPublishedObjects())
        if (Probe* p = r.as<Probe>()) {
          if (p->value() != 42) ++bad;
          ++reads;
        }
    }
  });
  for (int i = 0; i < 300; ++i) {
    Probe p("churn_" + std::to_string(i));
    std::this_thread::yield();
  }
  stop = true;
  reader.join();
  EXPECT_EQ(bad.load(), 0);
  RecordProperty("reads", reads.load());
}

}  // namespace
