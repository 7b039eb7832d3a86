// ModbusIoBoard against the Modbus TCP emulator on 127.0.0.1 (ephemeral port), including faults.
#include "rp/io/ModbusIoBoard.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "ModbusEmulator.hpp"
#include "rp/io/IoException.hpp"

namespace rp {
namespace {

using emulator::ModbusEmulator;

// Normal operations get a generous timeout (a loaded machine); fault tests pass a short one.
ModbusIoBoard::Config boardConfig(int port, int timeoutMs = 1000) {
  ModbusIoBoard::Config c;
  c.address = "127.0.0.1";
  c.port = port;
  c.responseTimeoutMs = timeoutMs;
  c.digitalOutputCoils = {8, 9, 3};
  c.digitalInputs = {0, 5};
  c.analogInputRegisters = {2};
  c.analogOutputRegisters = {4, 6};
  c.encoderRegisters = {10, 20};
  c.voltsPerCount = 0.001;
  return c;
}

bool contains(const char* text, const char* part) { return std::string(text).find(part) != std::string::npos; }

class ModbusIoBoardTest : public ::testing::Test {
 protected:
  void SetUp() override { server_.start(); }
  ModbusEmulator server_;
};

TEST_F(ModbusIoBoardTest, DigitalOutputsSetTheMappedCoils) {
  ModbusIoBoard board(boardConfig(server_.port()));
  ASSERT_EQ(board.writeDigitalOutput(0, true), IoStatus::kOk) << board.lastError();
  ASSERT_EQ(board.writeDigitalOutput(2, true), IoStatus::kOk) << board.lastError();
  EXPECT_TRUE(server_.coil(8));
  EXPECT_FALSE(server_.coil(9));
  EXPECT_TRUE(server_.coil(3));
  bool b = false;
  EXPECT_EQ(board.readDigitalOutput(2, b), IoStatus::kOk);
  EXPECT_TRUE(b);
  ASSERT_EQ(board.writeDigitalOutput(0, false), IoStatus::kOk);
  EXPECT_FALSE(server_.coil(8));
  EXPECT_TRUE(board.isConnected());
}

TEST_F(ModbusIoBoardTest, ReadsDiscreteInputsRegistersAndEncoders) {
  ModbusIoBoard board(boardConfig(server_.port()));
  server_.setDiscreteInput(5, true);
  server_.setInputRegister(2, static_cast<std::uint16_t>(-1234));  // -1.234 V at 1 mV/count
  server_.setInputRegister(10, 0xFFFF);  // -2 as a signed 32-bit count, high word first
  server_.setInputRegister(11, 0xFFFE);
  server_.setInputRegister(20, 0x0001);  // 65536 + 2
  server_.setInputRegister(21, 0x0002);
  bool b = false;
  ASSERT_EQ(board.readDigitalInput(1, b), IoStatus::kOk) << board.lastError();
  EXPECT_TRUE(b);
  ASSERT_EQ(board.readDigitalInput(0, b), IoStatus::kOk);
  EXPECT_FALSE(b);
  double v = 0;
  ASSERT_EQ(board.readAnalogInput(0, v), IoStatus::kOk);
  EXPECT_DOUBLE_EQ(v, -1.234);
  std::int64_t counts = 0;
  ASSERT_EQ(board.readEncoder(0, counts), IoStatus::kOk);
  EXPECT_EQ(counts, -2);
  ASSERT_EQ(board.readEncoder(1, counts), IoStatus::kOk);
  EXPECT_EQ(counts, 65538);
}

TEST_F(ModbusIoBoardTest, AnalogOutputsWriteScaledHoldingRegisters) {
  ModbusIoBoard board(boardConfig(server_.port()));
  ASSERT_EQ(board.writeAnalogOutput(1, -2.5), IoStatus::kOk) << board.lastError();
  EXPECT_EQ(static_cast<std::int16_t>(server_.holdingRegister(6)), -2500);
  ASSERT_EQ(board.writeAnalogOutput(0, 100.0), IoStatus::kOk);  // beyond 16 bits: clamped
  EXPECT_EQ(static_cast<std::int16_t>(server_.holdingRegister(4)), 32767);
}

TEST_F(ModbusIoBoardTest, AnalogOutputsRefuseNaNAndClampToTheRegisterRange) {
  ModbusIoBoard board(boardConfig(server_.port()));
  ASSERT_EQ(board.writeAnalogOutput(0, 1.25), IoStatus::kOk) << board.lastError();
  EXPECT_EQ(board.writeAnalogOutput(0, std::nan("")), IoStatus::kInvalidValue);
  EXPECT_TRUE(contains(board.lastError(), "NaN volts refused")) << board.lastError();
  EXPECT_EQ(static_cast<std::int16_t>(server_.holdingRegister(4)), 1250) << "the register keeps its value";
  EXPECT_TRUE(board.isConnected());
  ASSERT_EQ(board.writeAnalogOutput(0, -std::numeric_limits<double>::infinity()), IoStatus::kOk);
  EXPECT_EQ(static_cast<std::int16_t>(server_.holdingRegister(4)), -32768);
  ASSERT_EQ(board.writeAnalogOutput(1, std::numeric_limits<double>::infinity()), IoStatus::kOk);
  EXPECT_EQ(static_cast<std::int16_t>(server_.holdingRegister(6)), 32767);
  ASSERT_EQ(board.writeAnalogOutput(1, -1e300), IoStatus::kOk);
  EXPECT_EQ(static_cast<std::int16_t>(server_.holdingRegister(6)), -32768);
}

TEST_F(ModbusIoBoardTest, AddressOutsideTheDeviceIsADeviceError) {
  auto config = boardConfig(server_.port());
  config.digitalOutputCoils = {500};  // the emulator has 64 coils: Modbus exception "illegal data address"
  ModbusIoBoard board(config);
  EXPECT_EQ(board.writeDigitalOutput(0, true), IoStatus::kDeviceError);
  EXPECT_TRUE(contains(board.lastError(), "write coil 500 failed")) << board.lastError();
  EXPECT_TRUE(board.isConnected()) << "an exception reply keeps the connection";
}

TEST_F(ModbusIoBoardTest, LineOutsideTheMappingIsInvalidLine) {
  ModbusIoBoard board(boardConfig(server_.port()));
  EXPECT_EQ(board.writeDigitalOutput(3, true), IoStatus::kInvalidLine);
  EXPECT_STREQ(board.lastError(), "digital output 3 out of range (board has 3)");
}

TEST(ModbusIoBoard, DeviceAbsentIsConnectionRefused) {
  int port = 0;
  {
    ModbusEmulator probe;  // find a free port, then close it again
    probe.start();
    port = probe.port();
  }
  ModbusIoBoard board(boardConfig(port));
  EXPECT_EQ(board.writeDigitalOutput(0, true), IoStatus::kNotConnected);
  EXPECT_TRUE(contains(board.lastError(), "connect failed")) << board.lastError();
  EXPECT_TRUE(contains(board.lastError(), ("127.0.0.1:" + std::to_string(port)).c_str())) << board.lastError();
  EXPECT_FALSE(board.isConnected());
}

TEST_F(ModbusIoBoardTest, SilentDeviceTimesOutWithinTheResponseTimeout) {
  ModbusIoBoard board(boardConfig(server_.port(), 150));
  ASSERT_EQ(board.connect(), IoStatus::kOk);
  server_.setFault(ModbusEmulator::Fault::kSilent);
  const auto start = std::chrono::steady_clock::now();
  bool b = false;
  EXPECT_EQ(board.readDigitalInput(0, b), IoStatus::kTimeout);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5)) << "bounded, never a hang";
  EXPECT_TRUE(contains(board.lastError(), "read discrete input 0 failed")) << board.lastError();
  // The device answers again: the board reconnects by itself.
  server_.setFault(ModbusEmulator::Fault::kNone);
  EXPECT_EQ(board.readDigitalInput(0, b), IoStatus::kOk) << board.lastError();
}

TEST_F(ModbusIoBoardTest, GarbledReplyIsAProtocolError) {
  ModbusIoBoard board(boardConfig(server_.port(), 150));
  server_.setFault(ModbusEmulator::Fault::kGarbled);
  EXPECT_EQ(board.writeDigitalOutput(0, true), IoStatus::kProtocolError) << board.lastError();
  EXPECT_FALSE(board.isConnected()) << "the stream is out of step: reconnect next time";
}

TEST_F(ModbusIoBoardTest, TruncatedReplyTimesOut) {
  ModbusIoBoard board(boardConfig(server_.port(), 150));
  server_.setFault(ModbusEmulator::Fault::kTruncated);
  double v = 0;
  const IoStatus s = board.readAnalogInput(0, v);
  EXPECT_TRUE(s == IoStatus::kTimeout || s == IoStatus::kProtocolError) << toString(s) << ": " << board.lastError();
}

TEST_F(ModbusIoBoardTest, EmulatorKilledMidRunGivesNotConnected) {
  ModbusIoBoard board(boardConfig(server_.port()));
  ASSERT_EQ(board.writeDigitalOutput(1, true), IoStatus::kOk) << board.lastError();
  server_.stop();
  IoStatus s = IoStatus::kOk;
  for (int i = 0; i < 3 && s == IoStatus::kOk; ++i) s = board.writeDigitalOutput(1, false);  // bounded
  EXPECT_EQ(s, IoStatus::kNotConnected) << board.lastError();
  EXPECT_EQ(board.writeDigitalOutput(1, false), IoStatus::kNotConnected) << "and reconnecting is refused";
}

TEST(ModbusIoBoard, RejectsInvalidSettingsNamingTheField) {
  auto config = boardConfig(1502);
  config.unitId = 300;
  try {
    ModbusIoBoard board(config);
    FAIL();
  } catch (const IoException& e) {
    EXPECT_TRUE(contains(e.what(), "unitId = 300")) << e.what();
  }
  config = boardConfig(1502);
  config.encoderRegisters = {65535};
  try {
    ModbusIoBoard board(config);
    FAIL();
  } catch (const IoException& e) {
    EXPECT_TRUE(contains(e.what(), "encoderRegisters[0] = 65535")) << e.what();
  }
  config = boardConfig(0);
  EXPECT_THROW(ModbusIoBoard{config}, IoException);
}

}  // namespace
}  // namespace rp
