// The hardware server: in process (HwServer + HwServerIoBoard), and as the program rp-hwserver
// started as a child process, with a simulated board and with a Modbus board (the emulator).
#include "rp/io/HwServer.hpp"

#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <cmath>
#include <limits>
#include <string>
#include <thread>

#include "AllocationCounter.hpp"
#include "ChildProcess.hpp"
#include "ModbusEmulator.hpp"
#include "rp/io/HwServerIoBoard.hpp"
#include "rp/io/IoException.hpp"
#include "rp/io/SimulatedIoBoard.hpp"

namespace rp {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Unique per process and test, so that ctest -j runs do not collide.
std::string uniqueName(const char* what) { return std::string("test-") + what + "-" + std::to_string(::getpid()); }

// Whether no process holds the lock of the server segment `name` (what HwServer::start() asks of a
// segment it finds: a lock held is a living server).
bool segmentUnlocked(const std::string& name) {
  const int fd = ::shm_open(("/rp-hwserver-" + name).c_str(), O_RDONLY | O_CLOEXEC, 0);
  if (fd < 0) return false;
  const bool unlocked = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
  ::close(fd);  // (and the lock just taken with it)
  return unlocked;
}

// These tests are not about the client watchdog (HwServerWatchdog_test is): a watchdog time long
// enough that a client descheduled on a loaded machine keeps its outputs.
constexpr double kLongWatchdogMs = 5000.0;

TEST(HwServer, ServesABoardToSeveralClients) {
  SimulatedIoBoard board({.digitalInputs = 4, .digitalOutputs = 4, .analogInputs = 2, .analogOutputs = 2,
                          .encoders = 2, .analogRange = 10.0, .loopback = true});
  board.setEncoder(1, 4242);
  HwServer server(board, uniqueName("inproc"), 500.0, kLongWatchdogMs);
  server.start();
  HwServerIoBoard a(server.name());
  HwServerIoBoard b(server.name());
  EXPECT_EQ(a.numDigitalOutputs(), 4);
  EXPECT_EQ(a.numEncoders(), 2);
  ASSERT_EQ(a.writeDigitalOutput(2, true), IoStatus::kOk) << a.lastError();
  ASSERT_EQ(b.writeAnalogOutput(1, -3.25), IoStatus::kOk) << b.lastError();
  ASSERT_EQ(a.waitForCycle(1000), IoStatus::kOk) << a.lastError();
  ASSERT_EQ(a.waitForCycle(1000), IoStatus::kOk) << a.lastError();  // outputs written, then inputs read
  bool on = false;
  EXPECT_TRUE(board.readDigitalOutput(2, on) == IoStatus::kOk && on) << "the server wrote the board";
  ASSERT_EQ(b.readDigitalInput(2, on), IoStatus::kOk);
  EXPECT_TRUE(on) << "loopback seen by the other client";
  double v = 0;
  ASSERT_EQ(a.readAnalogInput(1, v), IoStatus::kOk);
  EXPECT_DOUBLE_EQ(v, -3.25);
  std::int64_t counts = 0;
  ASSERT_EQ(b.readEncoder(1, counts), IoStatus::kOk);
  EXPECT_EQ(counts, 4242);
  EXPECT_EQ(a.readEncoder(2, counts), IoStatus::kInvalidLine);
  EXPECT_GT(server.cycles(), 2u);
  server.stop();
  EXPECT_EQ(a.readDigitalInput(0, on), IoStatus::kNotConnected);
  EXPECT_TRUE(contains(a.lastError(), "has stopped")) << a.lastError();
  EXPECT_TRUE(board.readDigitalOutput(2, on) == IoStatus::kOk && !on) << "outputs off when the server stops";
}

TEST(HwServer, ClientRefusesNaNAndTheServersBoardClamps) {
  SimulatedIoBoard board({.digitalInputs = 0, .digitalOutputs = 0, .analogInputs = 0, .analogOutputs = 2,
                          .encoders = 0, .analogRange = 10.0, .loopback = false});
  HwServer server(board, uniqueName("nan"), 500.0, kLongWatchdogMs);
  server.start();
  HwServerIoBoard client(server.name());
  ASSERT_EQ(client.writeAnalogOutput(0, 3.0), IoStatus::kOk);
  EXPECT_EQ(client.writeAnalogOutput(0, std::nan("")), IoStatus::kInvalidValue);
  ASSERT_EQ(client.writeAnalogOutput(1, -std::numeric_limits<double>::infinity()), IoStatus::kOk);
  ASSERT_EQ(client.confirmWrites(5000), IoStatus::kOk) << client.lastError();
  double v = 0;
  ASSERT_EQ(board.readAnalogOutput(0, v), IoStatus::kOk);
  EXPECT_EQ(v, 3.0) << "NaN never reached the server";
  ASSERT_EQ(client.readAppliedAnalogOutput(1, v), IoStatus::kOk);
  EXPECT_EQ(v, -std::numeric_limits<double>::infinity()) << "what the board accepted...";
  ASSERT_EQ(board.readAnalogOutput(1, v), IoStatus::kOk);
  EXPECT_EQ(v, -10.0) << "... and clamped to its range";
}

TEST(HwServer, ClientOperationsDoNotAllocate) {
  SimulatedIoBoard board;
  HwServer server(board, uniqueName("alloc"), 200.0, kLongWatchdogMs);
  server.start();
  HwServerIoBoard client(server.name());
  bool b = false;
  double v = 0;
  std::int64_t c = 0;
  test::AllocationGuard guard;
  for (int i = 0; i < 100; ++i) {
    client.writeDigitalOutput(i % 16, (i & 1) != 0);
    client.readDigitalInput(i % 16, b);
    client.writeAnalogOutput(i % 8, 0.1 * i);
    client.readAnalogInput(i % 8, v);
    client.readEncoder(i % 8, c);
    client.checkServer();
  }
  EXPECT_EQ(guard.count(), 0u);
}

TEST(HwServer, NoSuchServerIsAnErrorNamingIt) {
  try {
    HwServerIoBoard client(uniqueName("absent"));
    FAIL();
  } catch (const IoException& e) {
    EXPECT_TRUE(contains(e.what(), "no hardware server 'test-absent-")) << e.what();
  }
}

TEST(HwServer, RejectsBadNamesAndRates) {
  SimulatedIoBoard board;
  EXPECT_THROW(HwServer(board, "../etc", 100.0), IoException);
  EXPECT_THROW(HwServer(board, "ok", 0.0), IoException);
  HwServer first(board, uniqueName("twice"), 100.0);
  first.start();
  HwServer second(board, first.name(), 100.0);
  try {
    second.start();
    FAIL();
  } catch (const IoException& e) {
    EXPECT_TRUE(contains(e.what(), "another server of this name is running")) << e.what();
  }
}

// A server that died leaves its segment behind, and the pid stored in it may by then belong to
// another, living process (in a fresh container pids repeat from run to run). The segment is still
// replaced: it is the server's lock that tells a living server, not its pid.
TEST(HwServer, ASegmentLeftByADeadServerIsReplacedEvenIfItsPidLivesOn) {
  const std::string name = uniqueName("pidreuse");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    SimulatedIoBoard board;
    HwServer server(board, name, 100.0);
    server.start();
    // exec ends the server (its thread and its lock) but not the process: the pid lives on.
    ::execl("/bin/sleep", "sleep", "30", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  bool replaced = false;
  for (int i = 0; i < 1000; ++i) {  // bounded: 10 s
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    // The exec is over when the process is `sleep` and the server's lock is free: the lock goes
    // with the last reference to the segment's open file, which the exec drops at its own pace
    // (waiting for the name alone once met the lock still held).
    std::ifstream comm("/proc/" + std::to_string(child) + "/comm");
    std::string what;
    if (!(comm >> what) || what != "sleep" || !segmentUnlocked(name)) continue;
    SimulatedIoBoard board;
    HwServer server(board, name, 100.0);
    EXPECT_NO_THROW(server.start()) << "the dead server's segment was not replaced";
    HwServerIoBoard client(name);
    replaced = client.waitForCycle(2000) == IoStatus::kOk;
    break;
  }
  ::kill(child, SIGKILL);
  ::waitpid(child, nullptr, 0);
  EXPECT_TRUE(replaced);
}

TEST(RpHwServer, ServesASimulatedBoardAndDetectsItsDeath) {
  const std::string name = uniqueName("child");
  test::ChildProcess server({RP_HWSERVER_PATH, "-name", name, "-rate", "200", "-board", "simulated", "-loopback",
                              "-watchdog", "5000"});
  const auto line = server.readLine(30000);
  ASSERT_TRUE(line.has_value());
  EXPECT_TRUE(contains(*line, "rp-hwserver: serving " + name)) << *line;
  HwServerIoBoard client(name, 1000);  // stale after 1 s without a cycle
  ASSERT_EQ(client.writeDigitalOutput(5, true), IoStatus::kOk) << client.lastError();
  ASSERT_EQ(client.waitForCycle(2000), IoStatus::kOk) << client.lastError();
  ASSERT_EQ(client.waitForCycle(2000), IoStatus::kOk) << client.lastError();
  bool on = false;
  ASSERT_EQ(client.readDigitalInput(5, on), IoStatus::kOk);
  EXPECT_TRUE(on);
  // Killed without a chance to clean up: the heartbeat stops and the client says so.
  server.signal(SIGKILL);
  ASSERT_TRUE(server.wait(5000).has_value());
  IoStatus s = IoStatus::kOk;
  for (int i = 0; i < 400 && s == IoStatus::kOk; ++i) {  // bounded: 4 s
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    s = client.readDigitalInput(5, on);
  }
  EXPECT_EQ(s, IoStatus::kNotConnected);
  EXPECT_TRUE(contains(client.lastError(), "is not responding")) << client.lastError();
  // A new server of the same name replaces the dead one's segment.
  test::ChildProcess again({RP_HWSERVER_PATH, "-name", name, "-board", "simulated"});
  const auto line2 = again.readLine(30000);
  ASSERT_TRUE(line2.has_value());
  again.signal(SIGTERM);
  EXPECT_EQ(again.wait(5000), 0);
}

TEST(RpHwServer, DrivesModbusCoilsAndReportsTheBoardFailing) {
  emulator::ModbusEmulator device;
  device.start();
  device.setDiscreteInput(1, true);
  const std::string name = uniqueName("modbus");
  test::ChildProcess server({RP_HWSERVER_PATH, "-name", name, "-rate", "100", "-board", "modbus", "-port",
                             std::to_string(device.port()), "-timeout", "100", "-watchdog", "5000", "-coils", "4,5",
                             "-discreteInputs", "0,1"});
  const auto line = server.readLine(30000);
  ASSERT_TRUE(line.has_value());
  EXPECT_TRUE(contains(*line, "2 DI, 2 DO")) << *line;
  HwServerIoBoard client(name, 1000);
  ASSERT_EQ(client.writeDigitalOutput(1, true), IoStatus::kOk) << client.lastError();
  for (int i = 0; i < 200 && !device.coil(5); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_TRUE(device.coil(5)) << "client -> shared memory -> server -> Modbus TCP -> coil";
  EXPECT_FALSE(device.coil(4));
  bool in = false;
  ASSERT_EQ(client.readDigitalInput(1, in), IoStatus::kOk);
  EXPECT_TRUE(in);
  device.stop();  // the I/O device dies; the server keeps running and reports it
  IoStatus s = IoStatus::kOk;
  for (int i = 0; i < 200 && s == IoStatus::kOk; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    s = client.readDigitalInput(1, in);
  }
  EXPECT_EQ(s, IoStatus::kDeviceError);
  EXPECT_TRUE(contains(client.lastError(), "board error")) << client.lastError();
  EXPECT_TRUE(contains(client.lastError(), "ModbusIoBoard 127.0.0.1:")) << client.lastError();
  server.signal(SIGTERM);
  EXPECT_EQ(server.wait(5000), 0);
}

TEST(RpHwServer, BadArgumentsExitWithStatus2) {
  test::ChildProcess server({RP_HWSERVER_PATH, "-name", "x", "-board", "nonsense"});
  EXPECT_EQ(server.wait(5000), 2);
  // Numbers that are not finite: -duration nan used to run the server until it was killed.
  for (const auto& [option, value] : std::vector<std::pair<std::string, std::string>>{
           {"-duration", "nan"}, {"-duration", "inf"}, {"-countsPerRadian", "inf"}, {"-rate", "nan"}}) {
    test::ChildProcess bad({RP_HWSERVER_PATH, "-name", "rp-test-bad-args", "-board", "simulated", option, value}, true);
    EXPECT_EQ(bad.readLine(5000).value_or("(nothing)"),
              "rp-hwserver: " + option + ": '" + value + "' is not a finite number");
    EXPECT_EQ(bad.wait(5000), 2) << option << " " << value;
  }
}

}  // namespace
}  // namespace rp
