// ForceTorqueSensor in simulation, and AtiFTSensor against the Net F/T emulator, including the
// servo-loop path that requests a system shutdown when the sensor fails.
#include "rp/effector/ForceTorqueSensor.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "AllocationCounter.hpp"
#include "EffectorTestSupport.hpp"
#include "WaitFor.hpp"
#include "NetFtEmulator.hpp"
#include "Vec3.hpp"
#include "rp/effector/AtiFTSensor.hpp"
#include "rp/math/Transform.hpp"

namespace rp {
namespace {

using test::vec3;

using emulator::NetFtEmulator;
using test::contains;

class ForceTorqueSensorTest : public test::EffectorTest {};

TEST_F(ForceTorqueSensorTest, SimulationReportsPayloadWeightAndExternalWrench) {
  // Sensor rotated 90 deg about x: world -z is sensor +y... (R^T (0,0,-mg)).
  configure("[ft]\nclass AtiFTSensor\norientation 90 0 0\npayload 2\npayloadCenter 0 0 100\nupdateRate 0\n");
  auto* ft = om_.createDerivedObject<ForceTorqueSensor>("ft");
  ASSERT_TRUE(ft->isSimulationModeOn());
  Vector<3> f, t;
  ASSERT_TRUE(ft->read(f, t));
  const double w = 2.0 * 9.80665;
  // Independent reference: gravity expressed in the sensor frame by hand for roll = 90 deg:
  // sensor y = world z, sensor z = world -y, so world (0, 0, -w) = sensor (0, -w, 0).
  EXPECT_NEAR(f[0], 0.0, 1e-9);
  EXPECT_NEAR(f[1], -w, 1e-9);
  EXPECT_NEAR(f[2], 0.0, 1e-9);
  // torque = c x F = (0, 0, 0.1) x (0, -w, 0) = (0.1 w, 0, 0)
  EXPECT_NEAR(t[0], 0.1 * w, 1e-9);
  EXPECT_NEAR(t[1], 0.0, 1e-9);
  ft->setSimulatedWrench(vec3(1.0, 2.0, 3.0), vec3(0.0, 0.0, 0.5));
  ASSERT_TRUE(ft->read(f, t));
  EXPECT_NEAR(f[2], 3.0, 1e-9);
  EXPECT_NEAR(t[2], 0.5, 1e-9);
  ft->executeCommand("Bias");
  ASSERT_TRUE(ft->read(f, t));
  EXPECT_NEAR(f.norm() + t.norm(), 0.0, 1e-9) << "biased";
  std::string reply;
  ASSERT_TRUE(ft->handleMessage("read", "", reply));
  EXPECT_TRUE(contains(reply, "{\"force\": [")) << reply;
  EXPECT_TRUE(contains(reply, "\"torque\": [")) << reply;
  EXPECT_EQ(ft->getLastReading().count, 4u) << "three read() calls and the read message";
  const auto commands = ft->getCommands();
  ASSERT_EQ(commands.size(), 1u);
  EXPECT_EQ(commands[0].name, "Bias");
}

using test::waitFor;

TEST_F(ForceTorqueSensorTest, TheLibraryDrivesUpdate) {
  configure("[ft]\nclass AtiFTSensor\npayload 2\n");  // default updateRate 1000
  auto* ft = om_.createDerivedObject<ForceTorqueSensor>("ft");
  EXPECT_EQ(ft->getUpdateRate(), 1000.0);
  EXPECT_EQ(ft->getThreadNames(), std::vector<std::string>{"ft-update"});
  EXPECT_TRUE(ft->areThreadsRunning());
  // Nobody calls read() or update(): the sensor's own thread takes the readings.
  ASSERT_TRUE(waitFor([&] { return ft->getLastReading().count >= 20; })) << ft->getLastReading().count;
  EXPECT_NEAR(ft->getLastReading().force[2], -2.0 * 9.80665, 1e-9);
  ft->setSimulatedWrench(vec3(0.0, 0.0, 5.0), vec3(0.0, 0.0, 0.0));
  EXPECT_TRUE(waitFor([&] { return std::abs(ft->getLastReading().force[2] - (5.0 - 2.0 * 9.80665)) < 1e-9; }));
  // read() takes turns with the thread.
  Vector<3> f, t;
  for (int i = 0; i < 50; ++i) ASSERT_TRUE(ft->read(f, t));
  EXPECT_NEAR(f[2], 5.0 - 2.0 * 9.80665, 1e-9);
  om_.deleteObject(ft);  // stops and joins the thread
}

TEST_F(ForceTorqueSensorTest, UpdateRateZeroLeavesUpdateToTheProgram) {
  configure("[ft]\nclass AtiFTSensor\nupdateRate 0\n");
  auto* ft = om_.createDerivedObject<ForceTorqueSensor>("ft");
  EXPECT_TRUE(ft->getThreadNames().empty());
  EXPECT_EQ(ft->getLastReading().count, 0u);
  EXPECT_TRUE(ft->update());
  EXPECT_EQ(ft->getLastReading().count, 1u);
}

class AtiFTSensorTest : public test::EffectorTest {
 protected:
  void SetUp() override {
    sensor_.setWrench({4.0, -5.0, 6.0, 0.25, -0.5, 0.75});
    sensor_.start();
    configure("[ft]\nclass AtiFTSensor\nsimulationMode off\naddress 127.0.0.1\nport " + std::to_string(sensor_.port()) +
              "\ncountsPerForce 1000000\ncountsPerTorque 1000000\ntimeout 300\nmaxMissedCycles 20\n"
              "updateRate 0\n");  // these tests call update() as a program's own loop does
  }
  void TearDown() override {
    if (ObjectManager::isShutdownRequested()) {
      ObjectManager::waitForShutdown(10.0);
      ObjectManager::resetShutdown();
    }
    EffectorTest::TearDown();
  }
  NetFtEmulator sensor_;
};

TEST_F(AtiFTSensorTest, ReadsTheStreamedWrenchAndBiases) {
  auto* ft = om_.createDerivedObject<AtiFTSensor>("ft");
  Vector<3> f, t;
  ASSERT_TRUE(ft->read(f, t)) << ft->getErrorStatus().message;
  EXPECT_NEAR(f[0], 4.0, 1e-6);
  EXPECT_NEAR(f[1], -5.0, 1e-6);
  EXPECT_NEAR(t[2], 0.75, 1e-6);
  std::string reply;
  ASSERT_TRUE(ft->handleMessage("read", "", reply));
  EXPECT_EQ(reply, "{\"force\": [4, -5, 6], \"torque\": [0.25, -0.5, 0.75]}");
  ft->executeCommand("Bias");
  EXPECT_EQ(ft->getErrorCode(), 0);
  for (int i = 0; i < 100 && sensor_.biasRequests() == 0; ++i) ft->read(f, t);
  EXPECT_EQ(sensor_.biasRequests(), 1);
  // Records after the bias read zero.
  for (int i = 0; i < 200 && f.norm() > 1e-9; ++i) ASSERT_TRUE(ft->read(f, t));
  EXPECT_NEAR(f.norm() + t.norm(), 0.0, 1e-9);
}

TEST_F(AtiFTSensorTest, LostAndReorderedRecordsAreCountedNotErrors) {
  sensor_.setFaults({.dropEvery = 3, .reorderEvery = 5});
  auto* ft = om_.createDerivedObject<AtiFTSensor>("ft");
  Vector<3> f, t;
  for (int i = 0; i < 30; ++i) ASSERT_TRUE(ft->read(f, t)) << ft->getErrorStatus().message;
  EXPECT_GT(ft->lostRecords(), 0u);
  EXPECT_EQ(ft->getErrorCode(), 0);
}

TEST_F(AtiFTSensorTest, ServoLoopUpdateDoesNotAllocate) {
  auto* ft = om_.createDerivedObject<AtiFTSensor>("ft");
  Vector<3> f, t;
  ASSERT_TRUE(ft->read(f, t));  // streaming started outside the loop
  test::AllocationGuard guard;
  for (int i = 0; i < 200; ++i) ft->update();
  EXPECT_EQ(guard.count(), 0u);
}

TEST_F(AtiFTSensorTest, SensorDyingInTheServoLoopRequestsASafeShutdown) {
  auto* ft = om_.createDerivedObject<AtiFTSensor>("ft");
  Vector<3> f, t;
  ASSERT_TRUE(ft->read(f, t));
  sensor_.stop();
  bool healthy = true;
  for (int cycle = 0; cycle < 2000 && healthy; ++cycle) {  // bounded: a 1 ms servo loop
    healthy = ft->update();
    ::usleep(1000);
  }
  EXPECT_FALSE(healthy);
  EXPECT_EQ(ft->getErrorCode(), 1);
  EXPECT_TRUE(contains(ft->getErrorStatus().message, "cycles without a reading")) << ft->getErrorStatus().message;
  EXPECT_TRUE(ObjectManager::isShutdownRequested());
  EXPECT_EQ(ObjectManager::getShutdownReason().rfind("force/torque sensor failed: NetFt 127.0.0.1:", 0), 0u) << ObjectManager::getShutdownReason();
  EXPECT_TRUE(contains(ObjectManager::getShutdownReason(), "cycles without a reading)")) << ObjectManager::getShutdownReason();
}

TEST_F(AtiFTSensorTest, SensorDyingUnderTheLibrarysUpdateThreadRequestsASafeShutdown) {
  configure("[ft]\nclass AtiFTSensor\nsimulationMode off\naddress 127.0.0.1\nport " + std::to_string(sensor_.port()) +
            "\ntimeout 300\nmaxMissedCycles 100\nupdateRate 1000\n");
  auto* ft = om_.createDerivedObject<AtiFTSensor>("ft");
  ASSERT_TRUE(waitFor([&] { return ft->getLastReading().count > 0; })) << ft->getErrorStatus().message;
  EXPECT_NEAR(ft->getLastReading().force[0], 4.0, 1e-6) << "the streamed wrench, read by the update thread";
  EXPECT_FALSE(ObjectManager::isShutdownRequested());
  sensor_.stop();
  ASSERT_TRUE(waitFor([] { return ObjectManager::isShutdownRequested(); }));
  EXPECT_EQ(ObjectManager::getShutdownReason().rfind("force/torque sensor failed: NetFt 127.0.0.1:", 0), 0u) << ObjectManager::getShutdownReason();
  EXPECT_TRUE(contains(ObjectManager::getShutdownReason(), "cycles without a reading)")) << ObjectManager::getShutdownReason();
  EXPECT_EQ(ft->getErrorCode(), 1);
  EXPECT_TRUE(contains(ft->getErrorStatus().message, "cycles without a reading")) << ft->getErrorStatus().message;
}

TEST_F(AtiFTSensorTest, AbsentSensorIsAnError) {
  const int port = sensor_.port();
  sensor_.stop();
  configure("[ft]\nclass AtiFTSensor\nsimulationMode off\nport " + std::to_string(port) + "\ntimeout 100\nupdateRate 0\n");
  auto* ft = om_.createDerivedObject<ForceTorqueSensor>("ft");
  Vector<3> f, t;
  EXPECT_FALSE(ft->read(f, t));
  EXPECT_EQ(ft->getErrorCode(), 1);
  std::string reply;
  ASSERT_TRUE(ft->handleMessage("read", "", reply));
  EXPECT_TRUE(contains(reply, "{\"error\": \"NetFt 127.0.0.1:")) << reply;
}

TEST_F(AtiFTSensorTest, InvalidSettingsAreConfigurationErrors) {
  try {  // the declared range refuses it when rp.cfg is read
    configure("[ft]\nclass AtiFTSensor\nport 70000\n");
    om_.createDerivedObject<ForceTorqueSensor>("ft");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_TRUE(contains(e.what(), "test.cfg:3: setting 'port': '70000' is outside 1..65535")) << e.what();
  }
  configure("[ft]\nclass AtiFTSensor\naddress sensor.local\n");
  EXPECT_THROW(om_.createDerivedObject<ForceTorqueSensor>("ft"), ConfigError);
}

}  // namespace
}  // namespace rp
