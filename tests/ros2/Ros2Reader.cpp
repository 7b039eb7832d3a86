// A plain Cyclone DDS reader in a process of its own, for Ros2Bridge_test: joins DOMAIN on
// loopback (the configuration a Ros2Bridge uses), takes one sensor_msgs/JointState from
// rt/NS/joint_states and, as a late joiner, the std_msgs/String on rt/NS/robot_description, and
// prints them as text:
//   joint_states NAME POSITION NAME POSITION ...
//   robot_description BYTES TEXT-ON-ONE-LINE
// Exits 0, or 1 with a message on stderr when a sample does not come within 20 s.
// Usage: ros2_reader DOMAIN NS
#include <dds/dds.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "rp/ros2/Ros2Bridge.hpp"
#include "sensor_msgs.h"
#include "std_msgs.h"

namespace {

dds_entity_t reader(dds_entity_t participant, const dds_topic_descriptor_t& desc, const std::string& name, bool transientLocal) {
  const dds_entity_t t = dds_create_topic(participant, &desc, name.c_str(), nullptr, nullptr);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, transientLocal ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, transientLocal ? 1 : 10);
  const dds_entity_t r = dds_create_reader(participant, t, qos, nullptr);
  dds_delete_qos(qos);
  return r;
}

// Takes the first valid sample within 20 s into `print`.
template <class T, class F>
bool takeOne(dds_entity_t r, F print) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < end) {
    void* samples[1] = {nullptr};
    dds_sample_info_t info[1];
    const dds_return_t n = dds_take(r, samples, info, 1, 1);
    if (n > 0) {
      const bool ok = info[0].valid_data;
      if (ok) print(*static_cast<const T*>(samples[0]));
      dds_return_loan(r, samples, n);
      if (ok) return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: ros2_reader DOMAIN NS\n");
    return 2;
  }
  const auto domain = static_cast<dds_domainid_t>(std::atoi(argv[1]));
  const std::string ns = argv[2];
  const std::string config = rp::Ros2Bridge::cycloneConfig({"lo"});
  if (dds_create_domain(domain, config.c_str()) < 0) {
    std::fprintf(stderr, "ros2_reader: cannot create domain %u\n", domain);
    return 1;
  }
  const dds_entity_t participant = dds_create_participant(domain, nullptr, nullptr);
  const dds_entity_t js = reader(participant, sensor_msgs_msg_dds__JointState__desc, "rt/" + ns + "/joint_states", false);
  if (!takeOne<sensor_msgs_msg_dds__JointState_>(js, [](const sensor_msgs_msg_dds__JointState_& m) {
        std::printf("joint_states");
        for (uint32_t i = 0; i < m.name._length && i < m.position._length; ++i)
          std::printf(" %s %.17g", m.name._buffer[i], m.position._buffer[i]);
        std::printf("\n");
      })) {
    std::fprintf(stderr, "ros2_reader: no joint_states\n");
    return 1;
  }
  const dds_entity_t rd = reader(participant, std_msgs_msg_dds__String__desc, "rt/" + ns + "/robot_description", true);
  if (!takeOne<std_msgs_msg_dds__String_>(rd, [](const std_msgs_msg_dds__String_& m) {
        std::string text = m.data;
        const std::size_t bytes = text.size();
        for (char& c : text)
          if (c == '\n') c = ' ';
        std::printf("robot_description %zu %s\n", bytes, text.c_str());
      })) {
    std::fprintf(stderr, "ros2_reader: no robot_description\n");
    return 1;
  }
  std::fflush(stdout);
  dds_delete(DDS_CYCLONEDDS_HANDLE);
  return 0;
}
