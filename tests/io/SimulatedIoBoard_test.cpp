#include "rp/io/SimulatedIoBoard.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "AllocationCounter.hpp"
#include "rp/io/IoException.hpp"

namespace rp {
namespace {

TEST(SimulatedIoBoard, AnalogOutputsRefuseNaNAndClampInfinities) {
  SimulatedIoBoard board({.digitalInputs = 0, .digitalOutputs = 0, .analogInputs = 1, .analogOutputs = 1,
                          .encoders = 0, .analogRange = 5.0, .loopback = true});
  double v = 0;
  ASSERT_EQ(board.writeAnalogOutput(0, 1.5), IoStatus::kOk);
  EXPECT_EQ(board.writeAnalogOutput(0, std::nan("")), IoStatus::kInvalidValue);
  EXPECT_STREQ(board.lastError(), "analog output 0: NaN volts refused (nothing written)");
  ASSERT_EQ(board.readAnalogOutput(0, v), IoStatus::kOk);
  EXPECT_EQ(v, 1.5) << "the output keeps its value";
  ASSERT_EQ(board.readAnalogInput(0, v), IoStatus::kOk);
  EXPECT_EQ(v, 1.5) << "and the loopback input too";
  ASSERT_EQ(board.writeAnalogOutput(0, std::numeric_limits<double>::infinity()), IoStatus::kOk);
  ASSERT_EQ(board.readAnalogOutput(0, v), IoStatus::kOk);
  EXPECT_EQ(v, 5.0);
  ASSERT_EQ(board.writeAnalogOutput(0, -std::numeric_limits<double>::infinity()), IoStatus::kOk);
  ASSERT_EQ(board.readAnalogOutput(0, v), IoStatus::kOk);
  EXPECT_EQ(v, -5.0);
}

TEST(SimulatedIoBoard, OutputsKeepTheirValueAndInputsFollowTheSimulation) {
  SimulatedIoBoard board({.digitalInputs = 4, .digitalOutputs = 3, .analogInputs = 2, .analogOutputs = 2,
                          .encoders = 2, .analogRange = 5.0, .loopback = false});
  EXPECT_EQ(board.numDigitalInputs(), 4);
  EXPECT_EQ(board.numDigitalOutputs(), 3);
  EXPECT_EQ(board.numAnalogInputs(), 2);
  EXPECT_EQ(board.numAnalogOutputs(), 2);
  EXPECT_EQ(board.numEncoders(), 2);

  bool b = true;
  EXPECT_EQ(board.readDigitalInput(3, b), IoStatus::kOk);
  EXPECT_FALSE(b);
  EXPECT_EQ(board.writeDigitalOutput(2, true), IoStatus::kOk);
  EXPECT_EQ(board.readDigitalOutput(2, b), IoStatus::kOk);
  EXPECT_TRUE(b);
  EXPECT_EQ(board.readDigitalInput(2, b), IoStatus::kOk);
  EXPECT_FALSE(b) << "without loopback an output does not drive an input";
  EXPECT_EQ(board.setDigitalInput(1, true), IoStatus::kOk);
  EXPECT_EQ(board.readDigitalInput(1, b), IoStatus::kOk);
  EXPECT_TRUE(b);

  double v = 0;
  EXPECT_EQ(board.writeAnalogOutput(0, 7.5), IoStatus::kOk);
  EXPECT_EQ(board.readAnalogOutput(0, v), IoStatus::kOk);
  EXPECT_DOUBLE_EQ(v, 5.0) << "clamped to the analog range";
  EXPECT_EQ(board.setAnalogInput(1, -2.25), IoStatus::kOk);
  EXPECT_EQ(board.readAnalogInput(1, v), IoStatus::kOk);
  EXPECT_DOUBLE_EQ(v, -2.25);

  std::int64_t counts = 0;
  EXPECT_EQ(board.setEncoder(1, -123456789012LL), IoStatus::kOk);
  EXPECT_EQ(board.readEncoder(1, counts), IoStatus::kOk);
  EXPECT_EQ(counts, -123456789012LL);
}

TEST(SimulatedIoBoard, LoopbackDrivesInputsFromOutputs) {
  SimulatedIoBoard board({.digitalInputs = 2, .digitalOutputs = 4, .analogInputs = 1, .analogOutputs = 1,
                          .encoders = 0, .analogRange = 10.0, .loopback = true});
  bool b = false;
  double v = 0;
  EXPECT_EQ(board.writeDigitalOutput(1, true), IoStatus::kOk);
  EXPECT_EQ(board.readDigitalInput(1, b), IoStatus::kOk);
  EXPECT_TRUE(b);
  EXPECT_EQ(board.writeDigitalOutput(3, true), IoStatus::kOk) << "an output without a matching input is fine";
  EXPECT_EQ(board.writeAnalogOutput(0, -3.5), IoStatus::kOk);
  EXPECT_EQ(board.readAnalogInput(0, v), IoStatus::kOk);
  EXPECT_DOUBLE_EQ(v, -3.5);
}

TEST(SimulatedIoBoard, OutOfRangeLinesReturnInvalidLineWithAMessage) {
  SimulatedIoBoard board;
  bool b = false;
  EXPECT_EQ(board.readDigitalInput(16, b), IoStatus::kInvalidLine);
  EXPECT_EQ(board.lastStatus(), IoStatus::kInvalidLine);
  EXPECT_EQ(std::string(board.lastError()), "digital input 16 out of range (board has 16)");
  EXPECT_EQ(board.writeDigitalOutput(-1, true), IoStatus::kInvalidLine);
  std::int64_t c = 0;
  EXPECT_EQ(board.readEncoder(8, c), IoStatus::kInvalidLine);
  EXPECT_EQ(std::string(board.lastError()), "encoder 8 out of range (board has 8)");
}

TEST(SimulatedIoBoard, RejectsImpossibleSizes) {
  try {
    SimulatedIoBoard board({.digitalInputs = -1});
    FAIL() << "expected IoException";
  } catch (const IoException& e) {
    EXPECT_NE(std::string(e.what()).find("digitalInputs = -1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(SimulatedIoBoard({.encoders = 5000}), IoException);
  EXPECT_THROW(SimulatedIoBoard({.analogRange = 0.0}), IoException);
}

TEST(SimulatedIoBoard, CyclicOperationsDoNotAllocate) {
  SimulatedIoBoard board;
  bool b = false;
  double v = 0;
  std::int64_t c = 0;
  test::AllocationGuard guard;
  for (int i = 0; i < 100; ++i) {
    board.writeDigitalOutput(i % 16, (i & 1) != 0);
    board.readDigitalInput(i % 16, b);
    board.writeAnalogOutput(i % 8, 0.01 * i);
    board.readAnalogInput(i % 8, v);
    board.readEncoder(i % 8, c);
    board.readEncoder(99, c);  // the error path formats a message into a fixed buffer
  }
  EXPECT_EQ(guard.count(), 0u);
}

}  // namespace
}  // namespace rp
