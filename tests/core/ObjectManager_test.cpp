// Objects, the object manager and the type database.
#include "rp/core/ObjectManager.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <thread>

#include "TestClasses.hpp"
#include "rp/core/RoboticPlatform.hpp"

namespace rp {
namespace {

using test::SlowShutdown;
using test::TestArm;
using test::TestFunction;

class ObjectManagerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RoboticPlatform::setConfiguration(Configuration::parse(
        "[arm]\nclass TestArm\nposition 300 0 0\norientation 0 0 90\nsimulationMode off\ndisplay wireframe\n"
        "port /dev/ser1\n\n[func]\nclass TestFunction\n\n[slow]\nclass SlowShutdown\n",
        "cell.cfg"));
  }
  void TearDown() override {
    ObjectManager().deleteAllObjects();
    RoboticPlatform::setConfiguration(Configuration());
  }
  ObjectManager om;
};

TEST_F(ObjectManagerTest, CreateDerivedObjectCreatesTheConfiguredClass) {
  PhysicalObject* arm = om.createDerivedObject<PhysicalObject>("arm");
  ASSERT_NE(arm, nullptr);
  EXPECT_EQ(arm->getClassName(), "TestArm");
  EXPECT_EQ(arm->getName(), "arm");
  EXPECT_FALSE(arm->hasAutomaticName());
  EXPECT_EQ(dynamic_cast<TestArm*>(arm)->port, "/dev/ser1");
  // Table 1 settings, in rp.cfg units (mm, degrees).
  Transform expected = translation(0.3, 0, 0) * zRotation(M_PI / 2);
  EXPECT_TRUE(arm->getTransform().isApprox(expected, 1e-12)) << arm->getTransform();
  EXPECT_FALSE(arm->isSimulationModeOn());
  EXPECT_EQ(arm->getDisplayMode(), DisplayMode::Wireframe);
  EXPECT_EQ(om.findObject("arm"), arm);
  EXPECT_EQ(om.findObject<TestArm>("arm"), arm);
  EXPECT_EQ(om.findObject<TestFunction>("arm"), nullptr);
  RoboticObject* f = om.createObject("func");
  EXPECT_EQ(f->getClassName(), "TestFunction");
}

TEST_F(ObjectManagerTest, CreateDerivedObjectErrors) {
  try {
    om.createDerivedObject<PhysicalObject>("leader");
    FAIL();
  } catch (const ObjectError& e) {
    EXPECT_STREQ(e.what(), "cell.cfg: no section [leader] (sections: arm, func, slow)");
  }
  try {
    om.createDerivedObject<PhysicalObject>("func");
    FAIL();
  } catch (const ObjectError& e) {
    EXPECT_STREQ(e.what(), "cell.cfg:10: object 'func' is of class TestFunction, which is not a PhysicalObject");
  }
  try {
    om.createDerivedObject<TestArm>("func");
    FAIL();
  } catch (const ObjectError& e) {
    EXPECT_STREQ(e.what(), "cell.cfg:10: object 'func' is of class TestFunction, which is not a TestArm");
  }
  Configuration::Options lax;
  lax.checkClasses = false;
  RoboticPlatform::setConfiguration(Configuration::parse("[x]\nclass Nope\n", "lax.cfg", lax));
  try {
    om.createObject("x");
    FAIL();
  } catch (const ObjectError& e) {
    EXPECT_EQ(std::string(e.what()),
              "lax.cfg:2: class 'Nope' is not known (known: " + TypeDatabase::instance().knownNames() + ")");
  }
  EXPECT_TRUE(om.getObjects().empty());
}

TEST_F(ObjectManagerTest, TypeDatabase) {
  auto& db = TypeDatabase::instance();
  EXPECT_TRUE(db.contains("TestArm"));
  EXPECT_FALSE(db.contains("Nope"));
  EXPECT_TRUE(db.isDerivedFrom<PhysicalObject>("TestArm"));
  EXPECT_TRUE(db.isDerivedFrom<RoboticObject>("TestFunction"));
  EXPECT_FALSE(db.isDerivedFrom<PhysicalObject>("TestFunction"));
  EXPECT_FALSE(db.isDerivedFrom<PhysicalObject>("Nope"));
  auto names = db.classNames();
  EXPECT_TRUE(std::is_sorted(names.begin(), names.end()));
  EXPECT_THROW(TypeDatabase::registerClass<TestArm>("TestArm"), std::logic_error);
  EXPECT_NE(db.find("TestArm")->schema.find("port"), nullptr);
}

TEST_F(ObjectManagerTest, ObjectsRegisterAndLeave) {
  const std::size_t before = om.getObjects().size();
  {
    TestArm a;
    TestArm b("named");
    TestFunction f;
    EXPECT_EQ(om.getObjects().size(), before + 3);
    EXPECT_EQ(om.getDerivedObjects<PhysicalObject>().size(), 2u);
    EXPECT_EQ(om.getDerivedObjects<TestFunction>().size(), 1u);
    EXPECT_TRUE(a.hasAutomaticName());
    EXPECT_EQ(a.getName().rfind("object_", 0), 0u) << a.getName();
    EXPECT_NE(a.getName(), TestArm().getName());
    EXPECT_EQ(om.findObject(a.getName()), &a);
    EXPECT_EQ(om.findObject("named"), &b);
    EXPECT_THROW(TestArm("named"), std::invalid_argument);
    auto list = om.getObjectList();
    auto it = std::find_if(list.begin(), list.end(), [](const ObjectInfo& i) { return i.name == "named"; });
    ASSERT_NE(it, list.end());
    EXPECT_EQ(it->className, "TestArm");
    EXPECT_TRUE(it->physical);
    EXPECT_FALSE(it->hasControlLoop);
    // Unconfigured objects get defaults.
    EXPECT_EQ(b.configSection(), nullptr);
    EXPECT_TRUE(b.getTransform().isApprox(Transform::unit()));
    EXPECT_EQ(b.getDisplayMode(), DisplayMode::Solid);
  }
  EXPECT_EQ(om.getObjects().size(), before);
  EXPECT_EQ(om.findObject("named"), nullptr);
}

TEST_F(ObjectManagerTest, DeleteObject) {
  RoboticObject* a = om.createObject("arm");
  TestArm stack;
  EXPECT_THROW(om.deleteObject(&stack), std::invalid_argument);
  om.deleteObject(a);
  EXPECT_EQ(om.findObject("arm"), nullptr);
}

TEST(RoboticObject, ErrorStatusCommandsPanelAndMessages) {
  test::TestArm arm("cmd");
  EXPECT_EQ(arm.getErrorCode(), 0);
  arm.setError(7, "torque limit exceeded on joint 2");
  EXPECT_EQ(arm.getErrorCode(), 7);
  EXPECT_EQ(arm.getErrorStatus().message, "torque limit exceeded on joint 2");
  arm.setError(1, std::string(400, 'x').c_str());
  EXPECT_EQ(arm.getErrorStatus().message.size(), 255u);
  arm.clearError();
  EXPECT_EQ(arm.getErrorCode(), 0);
  EXPECT_EQ(arm.getErrorStatus().message, "");

  int opened = 0;
  arm.addCommand("Open Gripper", [&] { ++opened; }, "opens it");
  arm.addCommand("Close Gripper", [] {});
  EXPECT_THROW(arm.addCommand("Open Gripper", [] {}), std::invalid_argument);
  arm.executeCommand("Open Gripper");
  EXPECT_EQ(opened, 1);
  ASSERT_EQ(arm.getCommands().size(), 2u);
  EXPECT_EQ(arm.getCommands()[0].description, "opens it");
  try {
    arm.executeCommand("Relax");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "executeCommand: cmd has no command 'Relax' (known: Open Gripper, Close Gripper)");
  }
  ControlPanel panel = arm.getControlPanel();
  EXPECT_EQ(panel.title, "cmd (TestArm)");
  std::string reply = "x";
  EXPECT_FALSE(arm.handleMessage("ping", "", reply));
  EXPECT_EQ(reply, "");
  StateSnapshot snapshot;
  EXPECT_FALSE(arm.getStateSnapshot(snapshot));
  EXPECT_FALSE(arm.needsControlLoop());
  Model3D model = arm.get3DModel();
  ASSERT_EQ(model.shapes.size(), 1u);
  EXPECT_EQ(model.shapes[0].frame, "base");
}

TEST(PhysicalObject, ConnectionAndModes) {
  test::TestArm arm, gripper;
  gripper.setConnection(arm, "tool");
  EXPECT_EQ(gripper.getConnection(), &arm);
  EXPECT_EQ(gripper.getConnectionFrame(), "tool");
  gripper.clearConnection();
  EXPECT_EQ(gripper.getConnection(), nullptr);
  gripper.setTransform(translation(1, 2, 3));
  EXPECT_TRUE(gripper.getTransform().isApprox(translation(1, 2, 3)));
  gripper.setDisplayOff();
  EXPECT_EQ(gripper.getDisplayMode(), DisplayMode::Off);
  gripper.setDisplayWireframe();
  EXPECT_EQ(gripper.getDisplayMode(), DisplayMode::Wireframe);
  gripper.setDisplaySolid();
  EXPECT_EQ(gripper.getDisplayMode(), DisplayMode::Solid);
  // Simulation: the platform default (on) unless the object says otherwise; -sim forces it on.
  EXPECT_TRUE(gripper.isSimulationModeOn());
  gripper.setSimulationModeOff();
  EXPECT_FALSE(gripper.isSimulationModeOn());
  RoboticPlatform::setSimulationModeOn();
  EXPECT_TRUE(gripper.isSimulationModeOn());
  RoboticPlatform::setSimulationModeOff();
  EXPECT_FALSE(arm.isSimulationModeOn());
  arm.setSimulationModeOn();
  EXPECT_TRUE(arm.isSimulationModeOn());
}

// Objects register and leave from many threads while others list them (run under TSan).
TEST(ObjectManagerThreads, RegistrationFromManyThreads) {
  ObjectManager om;
  const std::size_t before = om.getObjects().size();
  std::atomic<bool> go{false};
  std::vector<std::thread> threads;
  std::atomic<int> created{0};
  for (int t = 0; t < 6; ++t) {
    threads.emplace_back([&, t] {
      while (!go) std::this_thread::yield();
      for (int i = 0; i < 200; ++i) {
        test::TestArm a;
        std::string name = "t";
        name += std::to_string(t);
        name += '_';
        name += std::to_string(i);
        test::TestFunction f(name);
        ++created;
        (void)a.getName();
      }
    });
  }
  threads.emplace_back([&] {
    while (!go) std::this_thread::yield();
    for (int i = 0; i < 200; ++i) {
      // Names are safe to read while other threads construct and destroy objects.
      std::set<std::string> names;
      om.forEachObject([&](RoboticObject& o) { EXPECT_TRUE(names.insert(o.getName()).second) << o.getName(); });
      (void)om.findObject("t0_5");
    }
  });
  go = true;
  for (auto& th : threads) th.join();
  EXPECT_EQ(created.load(), 1200);
  EXPECT_EQ(om.getObjects().size(), before);
}

// A shutdown requested from any thread reaches every object; the manager waits for completion.
TEST(ObjectManagerThreads, SystemShutdownReachesEveryObject) {
  ObjectManager::resetShutdown();
  test::TestArm a;
  test::SlowShutdown s1, s2;
  test::TestFunction f;
  std::thread requester([] { ObjectManager::requestSystemShutdown("torque limit exceeded"); });
  requester.join();
  ObjectManager::requestSystemShutdown("second request is ignored");
  ASSERT_TRUE(ObjectManager::waitForShutdown(60));
  EXPECT_TRUE(ObjectManager::isShutdownRequested());
  EXPECT_EQ(ObjectManager::getShutdownReason(), "torque limit exceeded");
  EXPECT_TRUE(a.isShuttingDown());
  EXPECT_TRUE(a.isShutdownComplete());
  EXPECT_TRUE(f.isShutdownComplete());
  EXPECT_TRUE(s1.started);
  EXPECT_TRUE(s2.started);
  EXPECT_GE(s1.polls.load(), 3);
  EXPECT_TRUE(s2.isShutdownComplete());
  ObjectManager::resetShutdown();
  EXPECT_FALSE(ObjectManager::isShutdownRequested());
}

TEST(ObjectManagerThreads, ShutdownWaitIsBounded) {
  struct Never : test::TestArm {
    void startShutdown() override {}
    bool isShutdownComplete() const override { return false; }
  } never;
  ObjectManager::setShutdownTimeout(0.05);
  auto pending = ObjectManager().shutdownAllObjects("test");
  ObjectManager::setShutdownTimeout(5.0);
  ASSERT_EQ(pending.size(), 1u);
  EXPECT_EQ(pending[0], never.getName());
}

}  // namespace
}  // namespace rp
