// The program rp-device, started as a child process against the device emulators.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "ChildProcess.hpp"
#include "ModbusEmulator.hpp"
#include "NetFtEmulator.hpp"

namespace rp {
namespace {

class RpDevice : public ::testing::Test {
 protected:
  // Writes rp.cfg text to a file of this process and test.
  std::string writeConfig(const std::string& text) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    file_ = ::testing::TempDir() + "rp-device-" + std::to_string(::getpid()) + "-" + info->name() + ".cfg";
    std::ofstream(file_) << text;
    return file_;
  }
  void TearDown() override {
    if (!file_.empty()) ::unlink(file_.c_str());
  }
  // Runs rp-device and returns (exit status, first line of stdout).
  std::pair<int, std::string> run(const std::vector<std::string>& args) {
    std::vector<std::string> argv{RP_DEVICE_PATH};
    argv.insert(argv.end(), args.begin(), args.end());
    test::ChildProcess child(argv);
    const std::string line = child.readLine(10000).value_or("");
    return {child.wait(10000).value_or(-1), line};
  }
  std::string file_;
};

TEST_F(RpDevice, ClosesAModbusGripper) {
  emulator::ModbusEmulator device;
  device.start();
  const auto cfg = writeConfig("[gripper]\nclass DefaultGripper\nboard modbus\nport " +
                               std::to_string(device.port()) + "\nopenLine 0\ncloseLine 1\n");
  const auto [status, out] = run({"-config", cfg, "gripper", "Close"});
  EXPECT_EQ(status, 0);
  EXPECT_EQ(out, "gripper: Close done");
  EXPECT_TRUE(device.coil(1));
  EXPECT_FALSE(device.coil(0));
}

TEST_F(RpDevice, ReadsAForceTorqueSensorAsJson) {
  emulator::NetFtEmulator sensor;
  sensor.setWrench({1.5, 0, -2, 0, 0.125, 0});
  sensor.start();
  const auto cfg = writeConfig("[ft]\nclass AtiFTSensor\nport " + std::to_string(sensor.port()) + "\n");
  const auto [status, out] = run({"-config", cfg, "ft", "read"});
  EXPECT_EQ(status, 0);
  EXPECT_EQ(out, "{\"force\": [1.5, 0, -2], \"torque\": [0, 0.125, 0]}");
}

TEST_F(RpDevice, DeviceErrorsExitWith1) {
  int port = 0;
  {
    emulator::ModbusEmulator probe;
    probe.start();
    port = probe.port();
  }
  const auto cfg = writeConfig("[gripper]\nclass DefaultGripper\nboard modbus\nport " + std::to_string(port) +
                               "\nopenLine 0\ncloseLine 1\n");
  EXPECT_EQ(run({"-config", cfg, "gripper", "Open"}).first, 1);
}

TEST_F(RpDevice, ConfigurationAndUsageErrorsExitWith2) {
  const auto cfg = writeConfig("[gripper]\nclass DefaultGripper\nopenLine 3\n");
  EXPECT_EQ(run({"-config", cfg, "gripper", "Open"}).first, 2) << "openLine without a board";
  EXPECT_EQ(run({"-config", cfg, "nobody", "Open"}).first, 2);
  EXPECT_EQ(run({"-config", "/nonexistent/rp.cfg", "gripper", "Open"}).first, 2);
  EXPECT_EQ(run({"-bogus", "gripper", "Open"}).first, 2);
  const auto cfg2 = writeConfig("[gripper]\nclass DefaultGripper\n");
  EXPECT_EQ(run({"-config", cfg2, "-sim", "gripper", "Fly"}).first, 2);
  const auto [status, out] = run({"-config", cfg2, "-sim", "gripper", "Close"});
  EXPECT_EQ(status, 0);
  EXPECT_EQ(out, "gripper: Close done");
}

}  // namespace
}  // namespace rp
