// The program rp-device, started as a child process against the device emulators.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>

#include "BarrettHandEmulator.hpp"
#include "ChildProcess.hpp"
#include "ModbusEmulator.hpp"
#include "NetFtEmulator.hpp"
#include "rp/io/HwServerIoBoard.hpp"

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
    std::vector<std::string> argv{RP_DEVICE_PATH, "-nosim"};  // the hardware: here the emulators
    argv.insert(argv.end(), args.begin(), args.end());
    test::ChildProcess child(argv);
    const std::string line = child.readLine(30000).value_or("");
    return {child.wait(10000).value_or(-1), line};
  }
  // Runs rp-device with stderr on the same pipe: (exit status, first line of stdout or stderr).
  std::pair<int, std::string> runMerged(const std::vector<std::string>& args) {
    std::vector<std::string> argv{RP_DEVICE_PATH, "-nosim"};  // the hardware: here the emulators
    argv.insert(argv.end(), args.begin(), args.end());
    test::ChildProcess child(argv, true);
    const std::string line = child.readLine(30000).value_or("");
    return {child.wait(10000).value_or(-1), line};
  }
  std::string file_;
};

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// rp-hwserver on a Modbus board (the emulator) at a slow rate, so that a command that did not wait
// for the server would report done long before the coil is set.
class RpDeviceThroughHwServer : public RpDevice {
 protected:
  void startServer(int port, const std::string& coils) {
    name_ = "test-rpdev-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name();
    name_ = name_.substr(0, 64);
    server_ = std::make_unique<test::ChildProcess>(std::vector<std::string>{
        RP_HWSERVER_PATH, "-name", name_, "-rate", "20", "-board", "modbus", "-port", std::to_string(port), "-timeout",
        "200", "-watchdog", "5000", "-coils", coils, "-discreteInputs", "0"});
    const auto line = server_->readLine(30000);
    ASSERT_TRUE(line.has_value() && contains(*line, "serving")) << line.value_or("(nothing)");
  }
  void TearDown() override {
    if (server_) {
      server_->signal(SIGTERM);
      EXPECT_EQ(server_->wait(10000), 0);
    }
    RpDevice::TearDown();
  }
  std::string name_;
  std::unique_ptr<test::ChildProcess> server_;
};

TEST_F(RpDeviceThroughHwServer, CommandIsDoneOnlyWhenTheBoardHasIt) {
  emulator::ModbusEmulator device;
  device.start();
  startServer(device.port(), "0,1");
  const auto cfg = writeConfig("[changer]\nclass DefaultToolChanger\nboard hwserver\nserver " + name_ +
                               "\nlockLine 0\nunlockLine 1\n");
  test::ChildProcess child({RP_DEVICE_PATH, "-nosim", "-config", cfg, "changer", "Unlock"});
  EXPECT_EQ(child.readLine(30000).value_or("(nothing)"), "changer: Unlock done");
  EXPECT_EQ(device.coilSwitchedOn(1), 1) << "the unlock coil was set before 'done'";
  EXPECT_EQ(device.coilSwitchedOn(0), 0);
  EXPECT_EQ(child.wait(10000), 0);
}

TEST_F(RpDeviceThroughHwServer, CommandFailsWhenTheServersBoardIsGone) {
  int port = 0;
  {
    emulator::ModbusEmulator probe;  // a port nobody listens on any more
    probe.start();
    port = probe.port();
  }
  startServer(port, "0,1");
  const auto cfg = writeConfig("[changer]\nclass DefaultToolChanger\nboard hwserver\nserver " + name_ +
                               "\nlockLine 0\nunlockLine 1\n");
  const auto [status, out] = runMerged({"-config", cfg, "changer", "Unlock"});
  EXPECT_EQ(status, 1) << out;
  EXPECT_TRUE(contains(out, "rp-device: changer: hardware server '" + name_ + "'")) << out;
  EXPECT_TRUE(contains(out, "not connected")) << out;
  EXPECT_FALSE(contains(out, "changer: changer:")) << "the object is named once: " << out;
}

TEST_F(RpDeviceThroughHwServer, RefusedWriteIsReportedToItsCommandAndStallsNothingElse) {
  emulator::ModbusEmulator device;  // 64 coils: coil 500 is refused ("illegal data address")
  device.start();
  startServer(device.port(), "0,500,2,3");
  const auto cfg = writeConfig("[changer]\nclass DefaultToolChanger\nboard hwserver\nserver " + name_ +
                               "\nlockLine 0\nunlockLine 1\n\n[gripper]\nclass DefaultGripper\nboard hwserver\n"
                               "server " + name_ + "\nopenLine 2\ncloseLine 3\n");
  const auto [status, out] = runMerged({"-config", cfg, "changer", "Unlock"});
  EXPECT_EQ(status, 1) << out;
  EXPECT_TRUE(contains(out, "digital output 1: device error")) << out;
  EXPECT_TRUE(contains(out, "write coil 500 failed")) << out;
  // The next command, on other lines of the same server, is not charged with that refusal.
  const auto [status2, out2] = runMerged({"-config", cfg, "gripper", "Close"});
  EXPECT_EQ(status2, 0) << out2;
  EXPECT_EQ(out2, "gripper: Close done");
  EXPECT_EQ(device.coilSwitchedOn(3), 1);
  // And the server still reads its inputs.
  HwServerIoBoard monitor(name_, 5000);
  device.setDiscreteInput(0, true);
  bool in = false;
  for (int i = 0; i < 1000 && !in; ++i) {  // bounded: 10 s
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_EQ(monitor.readDigitalInput(0, in), IoStatus::kOk) << monitor.lastError();
  }
  EXPECT_TRUE(in);
}

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

// As every program (docs/hardware.md): objects simulate unless -nosim or simulationMode off.
TEST_F(RpDevice, SimulatesUnlessNosim) {
  emulator::ModbusEmulator device;
  device.start();
  const auto cfg = writeConfig("[gripper]\nclass DefaultGripper\nboard modbus\nport " + std::to_string(device.port()) +
                               "\nopenLine 0\ncloseLine 1\n");
  test::ChildProcess child({RP_DEVICE_PATH, "-config", cfg, "gripper", "Close"});
  EXPECT_EQ(child.readLine(10000).value_or("(nothing)"), "gripper: Close done");
  EXPECT_EQ(child.wait(10000), 0);
  EXPECT_FALSE(device.coil(1)) << "the simulated gripper reached the device";
  const auto [status, out] = run({"-config", cfg, "gripper", "Close"});  // run() adds -nosim
  EXPECT_EQ(status, 0);
  EXPECT_TRUE(device.coil(1));
  const auto cfgOff = writeConfig("[gripper]\nclass DefaultGripper\nsimulationMode off\nboard modbus\nport " +
                                  std::to_string(device.port()) + "\nopenLine 0\ncloseLine 1\n");
  test::ChildProcess child2({RP_DEVICE_PATH, "-config", cfgOff, "gripper", "Open"});
  EXPECT_EQ(child2.readLine(10000).value_or("(nothing)"), "gripper: Open done");
  EXPECT_EQ(child2.wait(10000), 0);
  EXPECT_TRUE(device.coil(0)) << "simulationMode off: the hardware";
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

TEST_F(RpDevice, ReadsAHandWithoutInitialisingIt) {
  emulator::BarrettHandEmulator hand;
  hand.start();
  const auto cfg = writeConfig("[hand]\nclass BarrettHand\nport " + hand.devicePath() + "\ntimeout 2000\n");
  const auto [status, out] = run({"-config", cfg, "hand", "read"});
  EXPECT_EQ(status, 0);
  EXPECT_EQ(out, "{\"state\": \"unknown\", \"positions\": [0, 0, 0, 0]}");
  EXPECT_EQ(hand.commands(), std::vector<std::string>{"FGET P"}) << "no HI (a calibration move of every finger)";
  EXPECT_EQ(run({"-config", cfg, "hand", "Initialize"}).first, 0);
  EXPECT_EQ(hand.commands().back(), "HI");
}

TEST_F(RpDevice, HandWithoutPortIsAConfigurationError) {
  const auto cfg = writeConfig("[hand]\nclass BarrettHand\n");
  const auto [status, out] = runMerged({"-config", cfg, "hand", "read"});
  EXPECT_EQ(status, 2) << out;
  EXPECT_EQ(out, "rp-device: " + cfg + ":1: [hand] has no 'port' setting (the hand's serial port, e.g. /dev/ttyS0)");
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
