// BarrettHandSerial against the BarrettHand emulator on a pseudo-terminal, including faults.
#include "rp/io/BarrettHandSerial.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "BarrettHandEmulator.hpp"
#include "rp/io/IoException.hpp"

namespace rp {
namespace {

using emulator::BarrettHandEmulator;

bool contains(const char* text, const char* part) { return std::string(text).find(part) != std::string::npos; }

class BarrettHandSerialTest : public ::testing::Test {
 protected:
  void SetUp() override {
    hand_.start();
    config_.port = hand_.devicePath();
    config_.timeoutMs = 1000;  // generous for normal replies on a loaded machine
    config_.motionTimeoutMs = 1000;
  }
  BarrettHandEmulator hand_;
  BarrettHandSerial::Config config_;
};

TEST_F(BarrettHandSerialTest, InitialisesClosesOpensAndRelaxes) {
  BarrettHandSerial driver(config_);
  ASSERT_EQ(driver.open(), IoStatus::kOk) << driver.lastError();
  ASSERT_EQ(driver.initialize(), IoStatus::kOk) << driver.lastError();
  EXPECT_TRUE(hand_.initialized());
  ASSERT_EQ(driver.closeGrasp(), IoStatus::kOk) << driver.lastError();
  std::array<int, 4> p{};
  ASSERT_EQ(driver.readPositions(p), IoStatus::kOk) << driver.lastError();
  EXPECT_EQ(p[0], 17500);
  EXPECT_EQ(p[1], 17500);
  EXPECT_EQ(p[2], 17500);
  EXPECT_EQ(p[3], 0) << "GC moves fingers 1-3 only, not the spread";
  ASSERT_EQ(driver.openGrasp(), IoStatus::kOk);
  ASSERT_EQ(driver.readPositions(p), IoStatus::kOk);
  EXPECT_EQ(p[0], 0);
  ASSERT_EQ(driver.relax(), IoStatus::kOk);
  EXPECT_EQ(hand_.commands(), (std::vector<std::string>{"HI", "GC", "FGET P", "GO", "FGET P", "T"}));
}

TEST_F(BarrettHandSerialTest, ReplyTextIsReturned) {
  BarrettHandSerial driver(config_);
  ASSERT_EQ(driver.open(), IoStatus::kOk);
  std::string reply;
  ASSERT_EQ(driver.command("PGET TEMP", &reply), IoStatus::kOk) << driver.lastError();
  EXPECT_EQ(reply, "285");
}

TEST_F(BarrettHandSerialTest, ErrReplyIsADeviceErrorWithItsMeaning) {
  BarrettHandSerial driver(config_);
  ASSERT_EQ(driver.open(), IoStatus::kOk);
  EXPECT_EQ(driver.closeGrasp(), IoStatus::kDeviceError) << "closing before HI";
  EXPECT_EQ(driver.lastErrorCode(), 4);
  EXPECT_TRUE(contains(driver.lastError(), "'GC' failed: ERR 4 (motor not initialized)")) << driver.lastError();
  EXPECT_EQ(driver.command("XYZZY"), IoStatus::kDeviceError);
  EXPECT_EQ(driver.lastErrorCode(), 32);
  EXPECT_TRUE(contains(driver.lastError(), "unknown command")) << driver.lastError();
  EXPECT_EQ(driver.initialize(), IoStatus::kOk) << "the hand still works after an error";
  EXPECT_EQ(driver.lastErrorCode(), 0);
}

TEST(BarrettHandSerial, DescribesErrorBitMasks) {
  EXPECT_EQ(BarrettHandSerial::describeErrorCode(4), "motor not initialized");
  EXPECT_EQ(BarrettHandSerial::describeErrorCode(16 | 8192), "couldn't reach position, overtemperature fault");
  EXPECT_EQ(BarrettHandSerial::describeErrorCode(8), "unknown error");
}

TEST(BarrettHandSerial, NoSuchSerialPort) {
  BarrettHandSerial driver({.port = "/dev/rp-no-such-port", .timeoutMs = 100});
  EXPECT_EQ(driver.open(), IoStatus::kNotConnected);
  EXPECT_TRUE(contains(driver.lastError(), "/dev/rp-no-such-port: cannot open serial port: No such file"))
      << driver.lastError();
  EXPECT_EQ(driver.initialize(), IoStatus::kNotConnected);
  EXPECT_TRUE(contains(driver.lastError(), "port not open")) << driver.lastError();
}

TEST(BarrettHandSerial, NotASerialPort) {
  BarrettHandSerial driver({.port = "/dev/null", .timeoutMs = 100});
  EXPECT_EQ(driver.open(), IoStatus::kNotConnected);
  EXPECT_TRUE(contains(driver.lastError(), "not a serial port")) << driver.lastError();
}

TEST(BarrettHandSerial, RejectsUnsupportedBaudRate) {
  EXPECT_THROW(BarrettHandSerial({.port = "/dev/ttyS0", .baud = 1234}), IoException);
}

TEST_F(BarrettHandSerialTest, SilentHandTimesOut) {
  hand_.setFault(BarrettHandEmulator::Fault::kSilent);
  BarrettHandSerial driver(config_);
  ASSERT_EQ(driver.open(), IoStatus::kOk);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(driver.command("PGET TEMP", nullptr, 200), IoStatus::kTimeout);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5)) << "bounded, never a hang";
  EXPECT_TRUE(contains(driver.lastError(), "'PGET TEMP' failed: no reply within 200 ms")) << driver.lastError();
}

TEST_F(BarrettHandSerialTest, GarbledReplyIsAProtocolError) {
  hand_.setFault(BarrettHandEmulator::Fault::kGarbled);
  BarrettHandSerial driver(config_);
  ASSERT_EQ(driver.open(), IoStatus::kOk);
  EXPECT_EQ(driver.command("HI", nullptr, 200), IoStatus::kProtocolError);
  EXPECT_TRUE(contains(driver.lastError(), "'HI' failed: garbled reply")) << driver.lastError();
}

// Replies with the echo and the prompt right but the text between them not the protocol's: a
// motion command answered with text was reported as done, FGET P with junk after its four
// numbers was read, and an error code too large for an int came out as ERR -1 (every bit).
TEST_F(BarrettHandSerialTest, RepliesThatAreNotTheProtocolAreProtocolErrors) {
  BarrettHandSerial driver(config_);
  ASSERT_EQ(driver.open(), IoStatus::kOk);
  hand_.setFault(BarrettHandEmulator::Fault::kWrongText);
  hand_.setWrongText("GARBAGE \x01\x02");
  EXPECT_EQ(driver.closeGrasp(), IoStatus::kProtocolError);
  EXPECT_TRUE(contains(driver.lastError(), "'GC' failed: unexpected reply 'GARBAGE ")) << driver.lastError();
  for (const char* text : {"100 200 300 400 555", "100 200 300 400abc", "100 200 300", "0x10 20 30 40"}) {
    hand_.setWrongText(text);
    std::array<int, 4> p{};
    EXPECT_EQ(driver.readPositions(p), IoStatus::kProtocolError) << text;
    EXPECT_TRUE(contains(driver.lastError(), "'FGET P' failed: expected 4 positions, got '")) << driver.lastError();
  }
  hand_.setWrongText("  10 20 30 40  ");
  std::array<int, 4> p{};
  EXPECT_EQ(driver.readPositions(p), IoStatus::kOk) << driver.lastError();
  EXPECT_EQ(p, (std::array<int, 4>{10, 20, 30, 40}));
  for (const char* text : {"ERR 99999999999999999999", "ERR 4x", "ERR", "ERR -4"}) {
    hand_.setWrongText(text);
    EXPECT_EQ(driver.initialize(), IoStatus::kProtocolError) << text;
    EXPECT_TRUE(contains(driver.lastError(), "'HI' failed: unreadable error reply")) << driver.lastError();
  }
  hand_.setWrongText("ERR 4");
  EXPECT_EQ(driver.initialize(), IoStatus::kDeviceError);
  EXPECT_EQ(driver.lastErrorCode(), 4);
  hand_.setFault(BarrettHandEmulator::Fault::kNone);
  EXPECT_EQ(driver.initialize(), IoStatus::kOk) << driver.lastError();
}

TEST_F(BarrettHandSerialTest, TruncatedReplyTimesOutAndSaysSo) {
  hand_.setFault(BarrettHandEmulator::Fault::kTruncated);
  BarrettHandSerial driver(config_);
  ASSERT_EQ(driver.open(), IoStatus::kOk);
  EXPECT_EQ(driver.command("PGET TEMP", nullptr, 200), IoStatus::kTimeout);
  EXPECT_TRUE(contains(driver.lastError(), "truncated reply")) << driver.lastError();
  hand_.setFault(BarrettHandEmulator::Fault::kNone);
  std::string reply;
  EXPECT_EQ(driver.command("PGET TEMP", &reply), IoStatus::kOk) << "stale bytes are flushed: " << driver.lastError();
  EXPECT_EQ(reply, "285");
}

TEST_F(BarrettHandSerialTest, InjectedErrorCodesAreReported) {
  hand_.setFault(BarrettHandEmulator::Fault::kError, 8192);
  BarrettHandSerial driver(config_);
  ASSERT_EQ(driver.open(), IoStatus::kOk);
  EXPECT_EQ(driver.initialize(), IoStatus::kDeviceError);
  EXPECT_EQ(driver.lastErrorCode(), 8192);
  EXPECT_TRUE(contains(driver.lastError(), "overtemperature fault")) << driver.lastError();
}

TEST_F(BarrettHandSerialTest, EmulatorKilledMidRunGivesNotConnected) {
  BarrettHandSerial driver(config_);
  ASSERT_EQ(driver.open(), IoStatus::kOk);
  ASSERT_EQ(driver.initialize(), IoStatus::kOk);
  hand_.stop();
  const IoStatus s = driver.closeGrasp();
  EXPECT_TRUE(s == IoStatus::kNotConnected || s == IoStatus::kTimeout) << toString(s);
  EXPECT_EQ(s, IoStatus::kNotConnected) << driver.lastError();
  EXPECT_FALSE(driver.isOpen());
}

}  // namespace
}  // namespace rp
