// A plain Cyclone DDS writer in a process of its own, for Ros2Trajectory_test: joins DOMAIN on
// loopback (the configuration a Ros2Bridge uses), waits for the bridge's reader of
// rt/NS/ARM/joint_trajectory, writes one trajectory_msgs/JointTrajectory with ROS 2's QoS
// (reliable, volatile, keep-last 10, XCDR1) and waits until the reader has acknowledged it.
// Usage: ros2_trajectory_writer DOMAIN NS ARM NAME,NAME,... POINT...
//   POINT: T:Q,Q,...[:V,V,...[:A,A,...]]  (time_from_start [s], positions, velocities, accelerations)
// Prints "written N points" and exits 0; 1 with a message on stderr when no reader appears within
// 20 s or the write fails; 2 on bad usage.
#include <dds/dds.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "TrajectoryMessage.hpp"
#include "rp/ros2/Ros2Bridge.hpp"

namespace {

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, separator)) parts.push_back(part);
  return parts;
}

std::vector<double> numbers(const std::string& text) {
  std::vector<double> out;
  for (const std::string& n : split(text, ',')) out.push_back(std::strtod(n.c_str(), nullptr));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 6) {
    std::fprintf(stderr, "usage: ros2_trajectory_writer DOMAIN NS ARM NAME,NAME,... T:Q,Q,...[:V,...[:A,...]]...\n");
    return 2;
  }
  const auto domain = static_cast<dds_domainid_t>(std::atoi(argv[1]));
  const std::string topic = "rt/" + std::string(argv[2]) + "/" + argv[3] + "/joint_trajectory";
  rp::test::TrajectoryMessage m;
  m.names = split(argv[4], ',');
  for (int a = 5; a < argc; ++a) {
    const std::vector<std::string> fields = split(argv[a], ':');
    rp::test::TrajectoryMessage::Point p;
    p.time = std::strtod(fields.at(0).c_str(), nullptr);
    if (fields.size() > 1) p.positions = numbers(fields[1]);
    if (fields.size() > 2) p.velocities = numbers(fields[2]);
    if (fields.size() > 3) p.accelerations = numbers(fields[3]);
    m.points.push_back(p);
  }
  const std::string config = rp::Ros2Bridge::cycloneConfig({"lo"});
  if (dds_create_domain(domain, config.c_str()) < 0) {
    std::fprintf(stderr, "ros2_trajectory_writer: cannot create domain %u\n", domain);
    return 1;
  }
  const dds_entity_t participant = dds_create_participant(domain, nullptr, nullptr);
  const dds_entity_t t = dds_create_topic(participant, &trajectory_msgs_msg_dds__JointTrajectory__desc, topic.c_str(), nullptr, nullptr);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 10);
  dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(qos, 1, &xcdr1);
  const dds_entity_t writer = dds_create_writer(participant, t, qos, nullptr);
  dds_delete_qos(qos);
  if (writer < 0) {
    std::fprintf(stderr, "ros2_trajectory_writer: cannot create a writer on %s\n", topic.c_str());
    return 1;
  }
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  dds_publication_matched_status_t matched{};
  while (dds_get_publication_matched_status(writer, &matched) >= 0 && matched.current_count == 0) {
    if (std::chrono::steady_clock::now() > end) {
      std::fprintf(stderr, "ros2_trajectory_writer: no reader of %s\n", topic.c_str());
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (dds_write(writer, &m.message()) < 0 || dds_wait_for_acks(writer, DDS_SECS(10)) < 0) {
    std::fprintf(stderr, "ros2_trajectory_writer: the write on %s failed or was not acknowledged\n", topic.c_str());
    return 1;
  }
  std::printf("written %zu points\n", m.points.size());
  std::fflush(stdout);
  dds_delete(DDS_CYCLONEDDS_HANDLE);
  return 0;
}
