// Gripper and DefaultGripper: commands, control panel, simulated grasping, digital outputs on a
// simulated board, on a Modbus TCP device (the emulator) and through a hardware server.
#include "rp/effector/Gripper.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "EffectorTestSupport.hpp"
#include "ModbusEmulator.hpp"
#include "Vec3.hpp"
#include "rp/effector/DefaultGripper.hpp"
#include "rp/io/SimulatedIoBoard.hpp"
#include "rp/math/Transform.hpp"

namespace rp {
namespace {

using test::vec3;

using test::contains;

class GripperTest : public test::EffectorTest {};

std::vector<std::string> commandNames(const RoboticObject& o) {
  std::vector<std::string> names;
  for (const auto& c : o.getCommands()) names.push_back(c.name);
  return names;
}

TEST_F(GripperTest, RegistersCommandsPanelAndTypeDatabaseEntry) {
  configure("[gripper]\nclass DefaultGripper\n");
  Gripper* g = om_.createDerivedObject<Gripper>("gripper");
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->getClassName(), "DefaultGripper");
  EXPECT_EQ(commandNames(*g), (std::vector<std::string>{"Open", "Close", "Relax"}));
  EXPECT_EQ(g->getState(), Gripper::State::Unknown);
  g->executeCommand("Close");
  EXPECT_EQ(g->getState(), Gripper::State::Closed);
  g->executeCommand("Relax");
  EXPECT_EQ(g->getState(), Gripper::State::Relaxed);
  const ControlPanel panel = g->getControlPanel();
  const auto state = std::find_if(panel.fields.begin(), panel.fields.end(), [](auto& f) { return f.name == "state"; });
  ASSERT_NE(state, panel.fields.end());
  StateSnapshot snapshot;
  ASSERT_TRUE(g->getStateSnapshot(snapshot));
  EXPECT_EQ(state->choices.at(static_cast<std::size_t>(snapshot.values[state->stateIndex])), "relaxed");
  std::string reply;
  ASSERT_TRUE(g->handleMessage("read", "", reply));
  EXPECT_EQ(reply, "{\"state\": \"relaxed\", \"simulation\": true, \"grasped\": []}");
  EXPECT_TRUE(ObjectManager::getTypeDatabase().isDerivedFrom<Gripper>("DefaultGripper"));
  EXPECT_TRUE(ObjectManager::getTypeDatabase().isDerivedFrom<Gripper>("BarrettHand"));
}

TEST_F(GripperTest, SimulatedGripperGraspsNearbyObjectsAndReleasesThem) {
  configure("[gripper]\nclass DefaultGripper\nposition 0 0 500\ngraspRange 30\ngraspable box\n");
  auto* g = om_.createDerivedObject<Gripper>("gripper");
  PhysicalObject boxObject("box"), farObject("far");
  PhysicalObject* box = &boxObject;
  PhysicalObject* far = &farObject;
  box->setTransform(translation(0.01, 0.0, 0.48));  // 22 mm from the gripper: in range
  far->setTransform(translation(0.2, 0.0, 0.5));
  g->addGraspable(*far);
  ASSERT_TRUE(g->close());
  ASSERT_EQ(g->getGraspedObjects(), std::vector<PhysicalObject*>{box}) << "only the object within 30 mm";
  EXPECT_EQ(box->getConnection(), g);
  // The gripper moves: the box moves with it.
  g->setTransform(translation(0.3, 0.1, 0.2) * zRotation(M_PI / 2));
  const Vector<3> held = getPosition(Gripper::worldTransform(*box));
  const Vector<3> expected = transformPoint(translation(0.3, 0.1, 0.2) * zRotation(M_PI / 2), vec3(0.01, 0.0, -0.02));
  EXPECT_NEAR((held - expected).norm(), 0.0, 1e-12);
  ASSERT_TRUE(g->open());
  EXPECT_TRUE(g->getGraspedObjects().empty());
  EXPECT_EQ(box->getConnection(), nullptr);
  EXPECT_NEAR((getPosition(box->getTransform()) - expected).norm(), 0.0, 1e-12) << "released where it was";
  EXPECT_EQ(far->getConnection(), nullptr);
  g->removeGraspable(*far);
}

TEST_F(GripperTest, DrivesTwoDigitalOutputs) {
  configure("[gripper]\nclass DefaultGripper\nsimulationMode off\n");
  auto* g = om_.createDerivedObject<DefaultGripper>("gripper");
  SimulatedIoBoard board;
  g->setIoBoard(board, 3, 4);
  bool openLine = false, closeLine = false;
  ASSERT_TRUE(g->close());
  board.readDigitalOutput(3, openLine);
  board.readDigitalOutput(4, closeLine);
  EXPECT_FALSE(openLine);
  EXPECT_TRUE(closeLine);
  ASSERT_TRUE(g->open());
  board.readDigitalOutput(3, openLine);
  board.readDigitalOutput(4, closeLine);
  EXPECT_TRUE(openLine);
  EXPECT_FALSE(closeLine);
  ASSERT_TRUE(g->relax());
  board.readDigitalOutput(3, openLine);
  board.readDigitalOutput(4, closeLine);
  EXPECT_FALSE(openLine);
  EXPECT_FALSE(closeLine);
}

TEST_F(GripperTest, ModbusGripperSetsCoilsAndReportsADeadDevice) {
  emulator::ModbusEmulator device;
  device.start();
  configure("[gripper]\nclass DefaultGripper\nsimulationMode off\nboard modbus\naddress 127.0.0.1\nport " +
            std::to_string(device.port()) + "\ntimeout 1000\nopenLine 6\ncloseLine 7\n");
  auto* g = om_.createDerivedObject<Gripper>("gripper");
  ASSERT_EQ(g->getErrorCode(), 0);
  g->executeCommand("Close");
  EXPECT_EQ(g->getErrorCode(), 0) << g->getErrorStatus().message;
  EXPECT_TRUE(device.coil(7));
  EXPECT_FALSE(device.coil(6));
  g->executeCommand("Open");
  EXPECT_TRUE(device.coil(6));
  EXPECT_FALSE(device.coil(7));
  device.stop();
  EXPECT_FALSE(g->close());
  EXPECT_EQ(g->getState(), Gripper::State::Open) << "state unchanged by a failed command";
  EXPECT_EQ(g->getErrorCode(), 1);
  EXPECT_TRUE(contains(g->getErrorStatus().message, "gripper: ModbusIoBoard 127.0.0.1:")) << g->getErrorStatus().message;
}

TEST_F(GripperTest, ACommandSaysWhatItDidOrWhyTheDeviceDidNot) {
  // What the pop-up menu shows: the command's result, or the driver's reason when the device did
  // not carry it out (never "done" for a close that did not happen).
  emulator::ModbusEmulator device;
  device.start();
  configure("[gripper]\nclass DefaultGripper\nsimulationMode off\nboard modbus\naddress 127.0.0.1\nport " +
            std::to_string(device.port()) + "\ntimeout 1000\nopenLine 6\ncloseLine 7\n");
  auto* g = om_.createDerivedObject<Gripper>("gripper");
  EXPECT_EQ(g->executeCommand("Close"), "closed");
  EXPECT_TRUE(device.coil(7));
  EXPECT_EQ(g->executeCommand("Open"), "open");
  device.stop();
  try {
    g->executeCommand("Close");
    FAIL() << "a close the device did not carry out was reported as done";
  } catch (const std::runtime_error& e) {
    EXPECT_TRUE(contains(e.what(), "gripper: ModbusIoBoard 127.0.0.1:")) << e.what();
  }
  EXPECT_EQ(g->getState(), Gripper::State::Open);
}

TEST_F(GripperTest, HardwareServerThatIsNotRunningIsADeviceError) {
  configure("[gripper]\nclass DefaultGripper\nsimulationMode off\nboard hwserver\nserver rp-test-nobody\n"
            "openLine 0\ncloseLine 1\n");
  auto* g = om_.createDerivedObject<Gripper>("gripper");
  EXPECT_EQ(g->getErrorCode(), 1);
  EXPECT_TRUE(contains(g->getErrorStatus().message, "no hardware server 'rp-test-nobody'"))
      << g->getErrorStatus().message;
  EXPECT_FALSE(g->close());
}

TEST_F(GripperTest, ConfigurationErrorsNameFileAndLine) {
  configure("[gripper]\nclass DefaultGripper\nboard modbus\nopenLine 0\n");
  try {
    om_.createDerivedObject<Gripper>("gripper");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_TRUE(contains(e.what(), "test.cfg:1:")) << e.what();
    EXPECT_TRUE(contains(e.what(), "no 'closeLine' setting")) << e.what();
  }
  configure("[gripper]\nclass DefaultGripper\nopenLine 0\ncloseLine 1\n");
  try {
    om_.createDerivedObject<Gripper>("gripper");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_TRUE(contains(e.what(), "test.cfg:3: setting 'openLine' needs a 'board' setting")) << e.what();
  }
  configure("[gripper]\nclass DefaultGripper\nboard simulated\nopenLine 0\ncloseLine 99\n");
  EXPECT_THROW(om_.createDerivedObject<Gripper>("gripper"), ConfigError);
}

}  // namespace
}  // namespace rp
