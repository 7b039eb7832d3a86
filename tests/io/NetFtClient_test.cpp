// NetFtClient against the Net F/T emulator on UDP 127.0.0.1 (ephemeral port), including faults.
#include "rp/io/NetFtClient.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <string>

#include "NetFtEmulator.hpp"
#include "rp/io/IoException.hpp"

namespace rp {
namespace {

using emulator::NetFtEmulator;

bool contains(const char* text, const char* part) { return std::string(text).find(part) != std::string::npos; }

TEST(NetFtClient, DecodesThePublishedExampleRecord) {
  // refdata/08, "EXAMPLE BYTE VECTORS".
  const std::uint8_t bytes[36] = {0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x1F, 0x40, 0x00, 0x00, 0x00, 0x00,
                                  0x00, 0x0F, 0x42, 0x40, 0xFF, 0xF0, 0xBD, 0xC0, 0x00, 0x00, 0x00, 0x00,
                                  0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x86, 0xA0};
  const NetFtRecord r = NetFtClient::decode(bytes, 1e6, 1e6);
  EXPECT_EQ(r.rdtSequence, 1u);
  EXPECT_EQ(r.ftSequence, 8000u);
  EXPECT_EQ(r.status, 0u);
  EXPECT_EQ(r.counts[0], 1000000);
  EXPECT_EQ(r.counts[1], -1000000);
  EXPECT_DOUBLE_EQ(r.force[0], 1.0);
  EXPECT_DOUBLE_EQ(r.force[1], -1.0);
  EXPECT_DOUBLE_EQ(r.force[2], 0.0);
  EXPECT_DOUBLE_EQ(r.torque[2], 0.1);
  // The emulator's encoder is an independent writer of the same layout.
  std::uint8_t again[36];
  NetFtEmulator::encode(1, 8000, 0, {1000000, -1000000, 0, 0, 0, 100000}, again);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(bytes), 36), std::string(reinterpret_cast<const char*>(again), 36));
}

TEST(NetFtClient, EncodesThePublishedRequests) {
  // refdata/08, REQUEST: start, stop, one sample, bias; and a count above 16 bits (the ROS drivers' bug).
  auto encode = [](NetFtClient::Command c, std::uint32_t n) {
    std::array<std::uint8_t, 8> b{};
    NetFtClient::encodeRequest(c, n, b.data());
    return b;
  };
  using A = std::array<std::uint8_t, 8>;
  EXPECT_EQ(encode(NetFtClient::Command::kStartRealtime, 0), (A{0x12, 0x34, 0x00, 0x02, 0, 0, 0, 0}));
  EXPECT_EQ(encode(NetFtClient::Command::kStop, 0), (A{0x12, 0x34, 0x00, 0x00, 0, 0, 0, 0}));
  EXPECT_EQ(encode(NetFtClient::Command::kStartRealtime, 1), (A{0x12, 0x34, 0x00, 0x02, 0, 0, 0, 1}));
  EXPECT_EQ(encode(NetFtClient::Command::kSetBias, 0), (A{0x12, 0x34, 0x00, 0x42, 0, 0, 0, 0}));
  EXPECT_EQ(encode(NetFtClient::Command::kStartRealtime, 0x00012345), (A{0x12, 0x34, 0x00, 0x02, 0x00, 0x01, 0x23, 0x45}));
}

class NetFtClientTest : public ::testing::Test {
 protected:
  void SetUp() override {
    sensor_.start();
    client_ = std::make_unique<NetFtClient>(
        NetFtClient::Config{.address = "127.0.0.1", .port = sensor_.port(), .countsPerForce = 1e6, .countsPerTorque = 1e6});
    ASSERT_EQ(client_->open(), IoStatus::kOk) << client_->lastError();
  }
  // Reads until `count` records have been delivered or nothing arrives for 200 ms (bounded).
  int drain(NetFtRecord& last, std::uint32_t untilSequence, int* dataLossResults = nullptr) {
    int calls = 0;
    for (int i = 0; i < 2000; ++i) {
      const IoStatus s = client_->receive(last, 200);
      if (s == IoStatus::kTimeout) break;
      if (s == IoStatus::kDataLoss && dataLossResults) ++*dataLossResults;
      ++calls;
      if (s == IoStatus::kOk || s == IoStatus::kDataLoss)
        if (last.rdtSequence >= untilSequence) break;
    }
    return calls;
  }
  NetFtEmulator sensor_;
  std::unique_ptr<NetFtClient> client_;
};

TEST_F(NetFtClientTest, StreamsTheEmulatedWrench) {
  sensor_.setWrench({1.5, -2.0, 9.81, 0.1, -0.2, 0.05});
  ASSERT_EQ(client_->startStreaming(10), IoStatus::kOk);
  NetFtRecord r;
  drain(r, 10);
  EXPECT_EQ(r.rdtSequence, 10u);
  EXPECT_NEAR(r.force[0], 1.5, 1e-6);
  EXPECT_NEAR(r.force[1], -2.0, 1e-6);
  EXPECT_NEAR(r.force[2], 9.81, 1e-6);
  EXPECT_NEAR(r.torque[0], 0.1, 1e-6);
  EXPECT_NEAR(r.torque[1], -0.2, 1e-6);
  EXPECT_NEAR(r.torque[2], 0.05, 1e-6);
  EXPECT_EQ(client_->receivedRecords(), 10u);
  EXPECT_EQ(client_->lostRecords(), 0u);
  EXPECT_EQ(client_->outOfOrderRecords(), 0u);
  for (int i = 0; i < 500 && sensor_.streaming(); ++i) ::usleep(1000);  // bounded
  EXPECT_FALSE(sensor_.streaming()) << "a finite stream ends by itself";
}

TEST_F(NetFtClientTest, ScriptedWrenchAndStopStreaming) {
  sensor_.setScript([](double t) { return std::array<double, 6>{t, 0, 0, 0, 0, 0}; });
  ASSERT_EQ(client_->startStreaming(), IoStatus::kOk);
  NetFtRecord r;
  drain(r, 30);
  EXPECT_GE(r.rdtSequence, 30u);
  EXPECT_GT(r.force[0], 0.0) << "time has passed since the stream started";
  ASSERT_EQ(client_->stopStreaming(), IoStatus::kOk);
  for (int i = 0; i < 100 && sensor_.streaming(); ++i) client_->receive(r, 10);
  EXPECT_FALSE(sensor_.streaming());
}

TEST_F(NetFtClientTest, BiasZeroesTheCurrentLoad) {
  sensor_.setWrench({3.0, 0.0, -4.0, 0.0, 0.5, 0.0});
  ASSERT_EQ(client_->startStreaming(), IoStatus::kOk);
  NetFtRecord r;
  drain(r, 5);
  ASSERT_NEAR(r.force[2], -4.0, 1e-6);
  ASSERT_EQ(client_->bias(), IoStatus::kOk);
  for (int i = 0; i < 100 && sensor_.biasRequests() == 0; ++i) client_->receive(r, 10);
  ASSERT_EQ(sensor_.biasRequests(), 1);
  const std::uint32_t after = sensor_.recordsGenerated() + 3;
  drain(r, after);
  EXPECT_NEAR(r.force[0], 0.0, 1e-6);
  EXPECT_NEAR(r.force[2], 0.0, 1e-6);
  EXPECT_NEAR(r.torque[1], 0.0, 1e-6);
  client_->stopStreaming();
}

TEST_F(NetFtClientTest, DetectsLostRecords) {
  sensor_.setFaults({.dropEvery = 5});
  ASSERT_EQ(client_->startStreaming(21), IoStatus::kOk);
  NetFtRecord r;
  int lossResults = 0;
  drain(r, 21, &lossResults);
  EXPECT_EQ(r.rdtSequence, 21u);
  EXPECT_EQ(client_->lostRecords(), 4u) << "records 5, 10, 15 and 20 never arrived";
  EXPECT_EQ(client_->receivedRecords(), 17u);
  EXPECT_GE(lossResults, 1);
}

TEST_F(NetFtClientTest, DetectsReorderedRecords) {
  sensor_.setFaults({.reorderEvery = 4});
  ASSERT_EQ(client_->startStreaming(13), IoStatus::kOk);
  NetFtRecord r;
  drain(r, 13);
  NetFtRecord stale;
  EXPECT_EQ(client_->receive(stale, 100), IoStatus::kTimeout) << "record 12, sent after 13, is never delivered";
  // Record 4 arrives after record 5 (likewise 8, 12): out of order, and no longer lost once it came.
  EXPECT_EQ(client_->outOfOrderRecords(), 3u);
  EXPECT_EQ(client_->lostRecords(), 0u);
  EXPECT_EQ(client_->receivedRecords(), 10u);
  EXPECT_EQ(r.rdtSequence, 13u);
}

TEST_F(NetFtClientTest, LostAndReorderedRecordsAreCountedOnceEach) {
  sensor_.setFaults({.dropEvery = 5, .reorderEvery = 3});
  ASSERT_EQ(client_->startStreaming(16), IoStatus::kOk);
  NetFtRecord r;
  drain(r, 16);
  NetFtRecord stale;
  client_->receive(stale, 100);  // the last held record, if any
  // Arrival order: 1 2 4 3 7 6 8 9 11 13 12 14 16. Dropped: 5, 10 and 15 (dropping wins over
  // holding back; 9, held while 10 was dropped, still comes before 11). Late: 3, 6 and 12.
  EXPECT_EQ(client_->lostRecords(), 3u);
  EXPECT_EQ(client_->outOfOrderRecords(), 3u);
  EXPECT_EQ(client_->receivedRecords(), 10u);
}

TEST_F(NetFtClientTest, GarbledAndTruncatedDatagramsAreDiscarded) {
  sensor_.setFaults({.garbleEvery = 3, .truncateEvery = 4});
  ASSERT_EQ(client_->startStreaming(10), IoStatus::kOk);
  NetFtRecord r;
  drain(r, 10);
  // 3, 6, 9 garbled (40 bytes); 4, 8 truncated (20 bytes).
  EXPECT_EQ(client_->malformedPackets(), 5u);
  EXPECT_EQ(client_->receivedRecords(), 5u);
  EXPECT_EQ(r.rdtSequence, 10u);
}

TEST_F(NetFtClientTest, OnlyMalformedDatagramsIsAProtocolError) {
  sensor_.setFaults({.truncateEvery = 1});
  ASSERT_EQ(client_->startStreaming(3), IoStatus::kOk);
  NetFtRecord r;
  IoStatus s = IoStatus::kTimeout;
  for (int i = 0; i < 20 && s == IoStatus::kTimeout; ++i) s = client_->receive(r, 50);
  EXPECT_EQ(s, IoStatus::kProtocolError);
  EXPECT_TRUE(contains(client_->lastError(), "malformed datagram")) << client_->lastError();
}

TEST_F(NetFtClientTest, SensorStatusWordIsADeviceError) {
  sensor_.setFaults({.status = 0x80000000u});
  ASSERT_EQ(client_->startStreaming(2), IoStatus::kOk);
  NetFtRecord r;
  IoStatus s = IoStatus::kTimeout;
  for (int i = 0; i < 20 && s == IoStatus::kTimeout; ++i) s = client_->receive(r, 50);
  EXPECT_EQ(s, IoStatus::kDeviceError);
  EXPECT_TRUE(contains(client_->lastError(), "status 0x80000000")) << client_->lastError();
}

TEST_F(NetFtClientTest, SilentSensorTimesOut) {
  sensor_.setFaults({.silent = true});
  ASSERT_EQ(client_->startStreaming(), IoStatus::kOk);
  NetFtRecord r;
  EXPECT_EQ(client_->receive(r, 100), IoStatus::kTimeout);
  EXPECT_TRUE(contains(client_->lastError(), "no new record within 100 ms")) << client_->lastError();
  EXPECT_EQ(client_->receive(r, 0), IoStatus::kTimeout) << "a zero timeout never waits";
}

TEST_F(NetFtClientTest, EmulatorKilledMidRunIsDetected) {
  ASSERT_EQ(client_->startStreaming(), IoStatus::kOk);
  NetFtRecord r;
  drain(r, 3);
  sensor_.stop();
  // Drain what was in flight, then the stream stops: timeout; a new request meets a closed port.
  IoStatus s = IoStatus::kOk;
  for (int i = 0; i < 50 && s != IoStatus::kTimeout; ++i) s = client_->receive(r, 50);
  EXPECT_EQ(s, IoStatus::kTimeout);
  client_->startStreaming();
  s = IoStatus::kTimeout;
  for (int i = 0; i < 10 && s == IoStatus::kTimeout; ++i) s = client_->receive(r, 50);
  EXPECT_EQ(s, IoStatus::kNotConnected);
  EXPECT_TRUE(contains(client_->lastError(), "no sensor at this address and port")) << client_->lastError();
}

TEST(NetFtClient, RejectsInvalidSettings) {
  EXPECT_THROW(NetFtClient({.address = "sensor.local"}), IoException);
  EXPECT_THROW(NetFtClient({.address = "127.0.0.1", .port = 70000}), IoException);
  EXPECT_THROW(NetFtClient({.address = "127.0.0.1", .port = 49152, .countsPerForce = 0.0}), IoException);
}

}  // namespace
}  // namespace rp
