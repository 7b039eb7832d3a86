// The emulated Puma 560 wired to an I/O board (ArmIoBoard), alone and behind rp-hwserver.
#include "ArmIoBoard.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <thread>

#include "ChildProcess.hpp"
#include "rp/io/HwServerIoBoard.hpp"
#include "rp/model/Puma560Model.hpp"

namespace rp {
namespace {

using emulator::ArmIoBoard;

ArmIoBoard::Config offline(const JointVector& q0) {
  ArmIoBoard::Config c;
  c.realTime = false;  // the test steps the simulation
  c.initialPosition = q0;
  return c;
}

TEST(ArmIoBoard, EncodersReportTheJointAnglesInCounts) {
  Puma560Model puma;
  ArmIoBoard board(puma, offline(puma.getHomePosition()));
  ASSERT_EQ(board.numEncoders(), 6);
  ASSERT_EQ(board.numAnalogOutputs(), 6);
  std::int64_t counts = 0;
  ASSERT_EQ(board.readEncoder(1, counts), IoStatus::kOk);
  EXPECT_EQ(counts, std::llround(puma.getHomePosition()[1] * 20000.0));
}

TEST(ArmIoBoard, BrakesHoldTheArmWhileTheAmplifiersAreOff) {
  Puma560Model puma;
  const JointVector qz = JointVector::Zero(6);
  ArmIoBoard board(puma, offline(qz));
  board.advance(0.5);
  EXPECT_NEAR((board.position() - qz).norm(), 0.0, 1e-15);
}

TEST(ArmIoBoard, UnsupportedArmFallsAndGravityCompensationInVoltsHoldsIt) {
  Puma560Model puma;
  const JointVector qz = JointVector::Zero(6);  // upper arm horizontal: a large gravity load on joint 2
  ArmIoBoard falling(puma, offline(qz));
  falling.writeDigitalOutput(0, true);
  falling.advance(0.2);
  EXPECT_GT(std::abs(falling.position()[1]), 0.01) << "no torque: the arm falls";

  // Torque = volts x gain: commanding the gravity torque in volts holds the arm still.
  ManipulatorData data(puma);
  JointVector g(6);
  gravityTorque(puma, data, qz, g);
  ArmIoBoard held(puma, offline(qz));
  held.writeDigitalOutput(0, true);
  for (int i = 0; i < 6; ++i) ASSERT_EQ(held.writeAnalogOutput(i, g[i] / held.amplifierGain(i)), IoStatus::kOk);
  held.advance(0.5);
  EXPECT_LT((held.position() - qz).norm(), 1e-6);
  EXPECT_GT(std::abs(g[1]), 1.0) << "the test is meaningful only with a real load";
}

TEST(ArmIoBoard, DacsRefuseNaNAndClampToTheirRange) {
  Puma560Model puma;
  const JointVector q0 = puma.getHomePosition();
  ArmIoBoard nan(puma, offline(q0)), zero(puma, offline(q0)), inf(puma, offline(q0)), ten(puma, offline(q0));
  EXPECT_EQ(nan.writeAnalogOutput(0, std::nan("")), IoStatus::kInvalidValue);
  ASSERT_EQ(inf.writeAnalogOutput(0, std::numeric_limits<double>::infinity()), IoStatus::kOk);
  ASSERT_EQ(ten.writeAnalogOutput(0, 10.0), IoStatus::kOk);  // the DAC range
  for (ArmIoBoard* b : {&nan, &zero, &inf, &ten}) {
    b->writeDigitalOutput(0, true);
    b->advance(0.05);
  }
  EXPECT_TRUE(nan.position().allFinite()) << "NaN never reached the arm";
  EXPECT_EQ(nan.position(), zero.position()) << "the NaN write left the DAC at 0 V";
  EXPECT_GT(inf.position()[0], q0[0]);
  EXPECT_EQ(inf.position()[0], ten.position()[0]) << "infinity clamped to +10 V";
}

TEST(RpHwServer, PumaBackendMovesTheArmOnDacVolts) {
  const std::string name = "test-puma-" + std::to_string(::getpid());
  // A long client watchdog: this test is not about it, and a loaded machine may pause the client.
  test::ChildProcess server(
      {RP_HWSERVER_PATH, "-name", name, "-rate", "500", "-board", "puma560", "-watchdog", "5000"});
  const auto line = server.readLine(30000);
  ASSERT_TRUE(line.has_value());
  EXPECT_NE(line->find("6 AO, 6 encoders"), std::string::npos) << *line;
  HwServerIoBoard arm(name, 1000);
  Puma560Model puma;
  std::int64_t start = 0;
  ASSERT_EQ(arm.readEncoder(0, start), IoStatus::kOk) << arm.lastError();
  EXPECT_EQ(start, std::llround(puma.getHomePosition()[0] * 20000.0));
  // The waist carries no gravity load: a positive torque turns it positively.
  ASSERT_EQ(arm.writeAnalogOutput(0, 3.0), IoStatus::kOk);
  ASSERT_EQ(arm.writeDigitalOutput(0, true), IoStatus::kOk);
  std::int64_t counts = start;
  for (int i = 0; i < 200 && counts < start + 200; ++i) {  // bounded wait, about 1 s at most
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ASSERT_EQ(arm.readEncoder(0, counts), IoStatus::kOk) << arm.lastError();
  }
  EXPECT_GE(counts, start + 200) << "200 counts = 0.01 rad";
  server.signal(SIGTERM);
  EXPECT_EQ(server.wait(5000), 0);
}

}  // namespace
}  // namespace rp
