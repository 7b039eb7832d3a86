// The fixture of the ROS 2 bridge tests (Ros2Bridge_test, Ros2Trajectory_test): a simulated
// platform, a DDS domain and namespace of the test process's own, and plain Cyclone DDS readers.
#pragma once

#include <dds/dds.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <string>
#include <thread>

#include "rp/RoboticPlatform.hpp"

namespace rp::test {

inline bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Sets `stop` and joins `thread` when the scope ends, however it ends (a test's fake remote arm).
struct StopAndJoin {
  std::atomic<bool>& stop;
  std::thread& thread;
  ~StopAndJoin() {
    stop = true;
    thread.join();
  }
};

// A domain and a namespace of this process's own, so that parallel test processes never meet.
inline Ros2BridgeOptions uniqueOptions() {
  Ros2BridgeOptions o;
  o.domain = 1 + static_cast<int>(getpid() % 200);
  o.nameSpace = "t";
  o.nameSpace += std::to_string(getpid());  // (not "t" + ...: GCC 12's -Wrestrict false positive where inlined)
  o.rate = 100;
  return o;
}

class Ros2Fixture : public ::testing::Test {
 protected:
  void SetUp() override {
    RoboticPlatform::setSimulationModeOn();
    ObjectManager::resetShutdown();
  }
  void TearDown() override {
    if (participant_ > 0) dds_delete(participant_);  // before the bridge takes the domain down
    participant_ = 0;
    ObjectManager().deleteAllObjects();
    RoboticPlatform::setConfiguration(Configuration());
  }
  void configure(const std::string& text) { RoboticPlatform::setConfiguration(Configuration::parse(text, "test.cfg")); }

  // A reader of ROS topic `topic` in the bridge's namespace (transient-local for a late joiner).
  dds_entity_t reader(const dds_topic_descriptor_t& desc, const std::string& topic, bool transientLocal = false) {
    if (participant_ <= 0) participant_ = dds_create_participant(static_cast<dds_domainid_t>(options_.domain), nullptr, nullptr);
    EXPECT_GT(participant_, 0);
    const std::string name = "rt/" + options_.nameSpace + "/" + topic;
    const dds_entity_t t = dds_create_topic(participant_, &desc, name.c_str(), nullptr, nullptr);
    EXPECT_GT(t, 0) << name;
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_durability(qos, transientLocal ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 10);
    const dds_entity_t r = dds_create_reader(participant_, t, qos, nullptr);
    dds_delete_qos(qos);
    EXPECT_GT(r, 0) << name;
    return r;
  }

  // Takes samples until `accept` returns true for one (the sample is loaned until returned).
  template <class T>
  bool takeUntil(dds_entity_t r, const std::function<bool(const T&)>& accept, double seconds = 10) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      void* samples[1] = {nullptr};
      dds_sample_info_t info[1];
      const dds_return_t n = dds_take(r, samples, info, 1, 1);
      if (n > 0) {
        const bool ok = info[0].valid_data && accept(*static_cast<const T*>(samples[0]));
        dds_return_loan(r, samples, n);
        if (ok) return true;
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    }
    return false;
  }

  // A writer of the DDS topic `name` (on the wire, "rt/NS/TOPIC") with ROS 2's QoS (reliable,
  // keep-last 10, XCDR1), or transient-local keep-last 1 as robot_description is offered; it does
  // not wait for a reader (a test's fake remote arm writes before the program under test exists).
  dds_entity_t topicWriter(const dds_topic_descriptor_t& desc, const std::string& name, bool transientLocal = false) {
    if (participant_ <= 0) participant_ = dds_create_participant(static_cast<dds_domainid_t>(options_.domain), nullptr, nullptr);
    const dds_entity_t t = dds_create_topic(participant_, &desc, name.c_str(), nullptr, nullptr);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_durability(qos, transientLocal ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, transientLocal ? 1 : 10);
    dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
    dds_qset_data_representation(qos, 1, &xcdr1);
    const dds_entity_t w = dds_create_writer(participant_, t, qos, nullptr);
    dds_delete_qos(qos);
    EXPECT_GT(w, 0) << name;
    return w;
  }

  // A writer of ROS topic `topic` in the bridge's namespace with ROS 2's QoS (reliable, keep-last
  // 10, XCDR1), once the bridge's reader is matched.
  dds_entity_t writer(const dds_topic_descriptor_t& desc, const std::string& topic) {
    const std::string name = "rt/" + options_.nameSpace + "/" + topic;
    const dds_entity_t w = topicWriter(desc, name);
    dds_publication_matched_status_t matched{};
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (dds_get_publication_matched_status(w, &matched) >= 0 && matched.current_count == 0 &&
           std::chrono::steady_clock::now() < end)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    EXPECT_EQ(matched.current_count, 1u) << "the bridge's reader of " << name << " did not appear";
    return w;
  }

  Ros2BridgeOptions options_ = uniqueOptions();
  dds_entity_t participant_ = 0;
};

}  // namespace rp::test
