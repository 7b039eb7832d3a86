// The program rp-emulate, started as a child process, with the drivers talking to it.
#include <gtest/gtest.h>

#include <string>

#include "ChildProcess.hpp"
#include "rp/io/BarrettHandSerial.hpp"
#include "rp/io/ModbusIoBoard.hpp"
#include "rp/io/NetFtClient.hpp"

namespace rp {
namespace {

int portOf(const std::string& line) { return std::stoi(line.substr(line.rfind(':') + 1)); }

TEST(RpEmulate, HelpPrintsTheUsageAndExits0) {
  for (const char* help : {"--help", "-h"}) {
    test::ChildProcess emulator({RP_EMULATE_PATH, help}, true);
    EXPECT_EQ(emulator.readLine(10000).value_or("(nothing)"), "usage: rp-emulate modbus [-port P] [-duration S]") << help;
    EXPECT_EQ(emulator.wait(10000), 0) << help;
  }
  test::ChildProcess unknown({RP_EMULATE_PATH, "--frobnicate"}, true);
  EXPECT_EQ(unknown.readLine(10000).value_or("(nothing)"),
            "rp-emulate: unknown device '--frobnicate' (modbus, barretthand or netft)");
  EXPECT_EQ(unknown.wait(10000), 2);
}

TEST(RpEmulate, ModbusPrintsItsPortAndCoilChanges) {
  test::ChildProcess emulator({RP_EMULATE_PATH, "modbus", "-duration", "20"});
  const auto line = emulator.readLine(30000);
  ASSERT_TRUE(line.has_value());
  ASSERT_EQ(line->rfind("modbus 127.0.0.1:", 0), 0u) << *line;
  ModbusIoBoard::Config config;
  config.port = portOf(*line);
  config.responseTimeoutMs = 500;
  config.digitalOutputCoils = {3};
  ModbusIoBoard board(config);
  ASSERT_EQ(board.writeDigitalOutput(0, true), IoStatus::kOk) << board.lastError();
  EXPECT_EQ(emulator.readLine(5000).value_or("(nothing)"), "coil 3 = 1");
  emulator.signal(SIGTERM);
  EXPECT_EQ(emulator.wait(5000), 0);
}

TEST(RpEmulate, BarrettHandAnswersOnItsPseudoTerminal) {
  test::ChildProcess emulator({RP_EMULATE_PATH, "barretthand", "-duration", "20"});
  const auto line = emulator.readLine(30000);
  ASSERT_TRUE(line.has_value());
  ASSERT_EQ(line->rfind("barretthand /dev/", 0), 0u) << *line;
  BarrettHandSerial hand({.port = line->substr(12), .timeoutMs = 1000, .motionTimeoutMs = 2000});
  ASSERT_EQ(hand.open(), IoStatus::kOk) << hand.lastError();
  ASSERT_EQ(hand.initialize(), IoStatus::kOk) << hand.lastError();
  EXPECT_EQ(emulator.readLine(5000).value_or("(nothing)"), "command HI");
  emulator.signal(SIGTERM);
  EXPECT_EQ(emulator.wait(5000), 0);
}

TEST(RpEmulate, NetFtStreamsTheGivenWrench) {
  test::ChildProcess emulator({RP_EMULATE_PATH, "netft", "-wrench", "1", "-2", "3", "0.1", "0.2", "-0.3",
                               "-duration", "20"});
  const auto line = emulator.readLine(30000);
  ASSERT_TRUE(line.has_value());
  ASSERT_EQ(line->rfind("netft 127.0.0.1:", 0), 0u) << *line;
  NetFtClient sensor({.address = "127.0.0.1", .port = portOf(*line)});
  ASSERT_EQ(sensor.open(), IoStatus::kOk);
  ASSERT_EQ(sensor.startStreaming(5), IoStatus::kOk);
  NetFtRecord r;
  IoStatus s = IoStatus::kTimeout;
  for (int i = 0; i < 20 && s == IoStatus::kTimeout; ++i) s = sensor.receive(r, 100);
  ASSERT_EQ(s, IoStatus::kOk) << sensor.lastError();
  EXPECT_NEAR(r.force[1], -2.0, 1e-6);
  EXPECT_NEAR(r.torque[2], -0.3, 1e-6);
  emulator.signal(SIGTERM);
  EXPECT_EQ(emulator.wait(5000), 0);
}

TEST(RpEmulate, BadArgumentsExitWithStatus2) {
  test::ChildProcess a({RP_EMULATE_PATH, "toaster"});
  EXPECT_EQ(a.wait(5000), 2);
  test::ChildProcess b({RP_EMULATE_PATH, "netft", "-rate", "fast"});
  EXPECT_EQ(b.wait(5000), 2);
  // These used to run until killed (-duration), or to be taken as given.
  for (const auto& [args, message] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"modbus", "-duration", "-1"}, "rp-emulate: -duration must not be negative (0: until a signal)"},
           {{"modbus", "-duration", "nan"}, "rp-emulate: -duration: 'nan' is not a finite number"},
           {{"barretthand", "-movetime", "-5"}, "rp-emulate: -movetime must not be negative"},
           {{"netft", "-drop", "-1"}, "rp-emulate: -drop, -reorder, -garble and -truncate must not be negative (0: never)"},
           {{"netft", "-wrench", "0", "0", "nan", "0", "0", "0"}, "rp-emulate: -wrench: 'nan' is not a finite number"}}) {
    std::vector<std::string> argv{RP_EMULATE_PATH};
    argv.insert(argv.end(), args.begin(), args.end());
    test::ChildProcess c(argv, true);
    EXPECT_EQ(c.readLine(5000).value_or("(nothing)"), message) << args[1];
    EXPECT_EQ(c.wait(5000), 2) << args[1];
  }
}

}  // namespace
}  // namespace rp
