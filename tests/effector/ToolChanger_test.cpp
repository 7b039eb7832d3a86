// ToolChanger and DefaultToolChanger: commands, simulation, two digital outputs.
#include "rp/effector/ToolChanger.hpp"

#include <gtest/gtest.h>

#include "EffectorTestSupport.hpp"
#include "ModbusEmulator.hpp"
#include "rp/effector/DefaultToolChanger.hpp"

namespace rp {
namespace {

class ToolChangerTest : public test::EffectorTest {};

TEST_F(ToolChangerTest, SimulatedToolChangerFollowsItsCommands) {
  configure("[changer]\nclass DefaultToolChanger\n");
  auto* c = om_.createDerivedObject<ToolChanger>("changer");
  std::vector<std::string> names;
  for (const auto& cmd : c->getCommands()) names.push_back(cmd.name);
  EXPECT_EQ(names, (std::vector<std::string>{"Lock", "Unlock", "Relax"}));
  c->executeCommand("Lock");
  EXPECT_EQ(c->getState(), ToolChanger::State::Locked);
  c->executeCommand("Unlock");
  EXPECT_EQ(c->getState(), ToolChanger::State::Unlocked);
  std::string reply;
  ASSERT_TRUE(c->handleMessage("read", "", reply));
  EXPECT_EQ(reply, "{\"state\": \"unlocked\", \"simulation\": true}");
}

TEST_F(ToolChangerTest, ModbusToolChangerDrivesLockAndUnlockCoils) {
  emulator::ModbusEmulator device;
  device.start();
  configure("[changer]\nclass DefaultToolChanger\nsimulationMode off\nboard modbus\nport " +
            std::to_string(device.port()) + "\ntimeout 1000\nlockLine 10\nunlockLine 11\n");
  auto* c = om_.createDerivedObject<ToolChanger>("changer");
  ASSERT_TRUE(c->lock()) << c->getErrorStatus().message;
  EXPECT_TRUE(device.coil(10));
  EXPECT_FALSE(device.coil(11));
  ASSERT_TRUE(c->unlock());
  EXPECT_FALSE(device.coil(10));
  EXPECT_TRUE(device.coil(11));
  ASSERT_TRUE(c->relax());
  EXPECT_FALSE(device.coil(10));
  EXPECT_FALSE(device.coil(11));
  device.stop();
  EXPECT_FALSE(c->lock());
  EXPECT_EQ(c->getState(), ToolChanger::State::Relaxed);
  EXPECT_TRUE(test::contains(c->getErrorStatus().message, "changer: ModbusIoBoard")) << c->getErrorStatus().message;
}

}  // namespace
}  // namespace rp
