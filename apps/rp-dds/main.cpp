// rp-dds: the ROS 2 topics on a DDS domain without ROS 2 installed (see docs/ros2.md).
//
//   rp-dds list [-domain D] [-interfaces IF...] [-time S]
//   rp-dds echo TOPIC [-domain D] [-interfaces IF...] [-count N] [-time S]
//
// list: every topic whose writers discovery announces within S seconds (default 2), as ROS names
// (`/cell1/joint_states`, without the `rt` prefix) with their ROS type and number of writers.
// echo: the samples of TOPIC (a ROS name: `/cell1/joint_states` or `cell1/joint_states`) as text,
// for the types the bridge publishes (sensor_msgs/msg/JointState, tf2_msgs/msg/TFMessage,
// std_msgs/msg/String), N of them (default: until Ctrl-C or S seconds, if given). The reader asks
// for the durability the writers offer, so it gets robot_description as a late joiner.
// -interfaces as Ros2Bridge's setting (default lo: this machine).
// Exit status: 0 done; 1 nothing received (no writer of TOPIC, or no sample within S seconds);
// 2 usage error.
#include <dds/dds.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "rp/ros2/Ros2Bridge.hpp"
#include "sensor_msgs.h"
#include "std_msgs.h"
#include "tf2_msgs.h"

namespace {

constexpr const char* kUsage =
    "usage: rp-dds list [-domain D] [-interfaces IF...] [-time S]\n"
    "       rp-dds echo TOPIC [-domain D] [-interfaces IF...] [-count N] [-time S]\n"
    "  list: the topics announced on DDS domain D (default 0) within S seconds (default 2)\n"
    "  echo: the samples of TOPIC (a ROS name, e.g. /cell1/joint_states) as text, N of them\n"
    "  -interfaces: network interfaces DDS may use (default lo; any: Cyclone DDS's choice)\n"
    "  exit status: 0 done, 1 nothing received, 2 usage error\n";

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::atomic<bool> interrupted{false};

struct Options {
  std::string command;
  std::string topic;
  int domain = 0;
  std::vector<std::string> interfaces{"lo"};
  double seconds = -1;  // -1: list 2 s, echo until N samples or Ctrl-C
  long count = -1;      // -1: no limit
};

double number(const std::string& option, const char* text, double lo, double hi) {
  char* end = nullptr;
  const double x = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(x >= lo && x <= hi))
    throw UsageError(option + ": '" + text + "' must be a number " + std::to_string(lo) + " .. " + std::to_string(hi));
  return x;
}

Options parse(int argc, char** argv) {
  Options o;
  if (argc < 2) throw UsageError("a command is needed: list or echo");
  o.command = argv[1];
  if (o.command != "list" && o.command != "echo") throw UsageError("unknown command '" + o.command + "'");
  int i = 2;
  if (o.command == "echo") {
    if (argc < 3 || argv[2][0] == '-') throw UsageError("echo needs a TOPIC");
    o.topic = argv[2];
    i = 3;
  }
  for (; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) throw UsageError(a + " needs a value");
    if (a == "-domain") {
      const double d = number(a, argv[++i], 0, 230);
      if (d != static_cast<int>(d)) throw UsageError("-domain must be a whole number");
      o.domain = static_cast<int>(d);
    } else if (a == "-time") {
      o.seconds = number(a, argv[++i], 0.1, 86400);
    } else if (a == "-count" && o.command == "echo") {
      o.count = static_cast<long>(number(a, argv[++i], 1, 1e9));
    } else if (a == "-interfaces") {
      o.interfaces.clear();
      while (i + 1 < argc && argv[i + 1][0] != '-') o.interfaces.push_back(argv[++i]);
    } else {
      throw UsageError("unknown option '" + a + "'");
    }
  }
  rp::Ros2BridgeOptions check;
  check.interfaces = o.interfaces;
  if (const std::string why = rp::Ros2Bridge::checkOptions(check); !why.empty()) throw UsageError("-interfaces: " + why);
  return o;
}

// "sensor_msgs::msg::dds_::JointState_" -> "sensor_msgs/msg/JointState".
std::string rosType(const std::string& ddsType) {
  std::string t;
  for (std::size_t i = 0; i < ddsType.size();) {
    if (ddsType.compare(i, 8, "::dds_::") == 0) {
      t += '/';
      i += 8;
    } else if (ddsType.compare(i, 2, "::") == 0) {
      t += '/';
      i += 2;
    } else {
      t += ddsType[i++];
    }
  }
  if (!t.empty() && t.back() == '_') t.pop_back();
  return t;
}

// "rt/cell1/joint_states" -> "/cell1/joint_states"; other DDS topics as they are.
std::string rosTopic(const std::string& ddsTopic) {
  return ddsTopic.rfind("rt/", 0) == 0 ? ddsTopic.substr(2) : ddsTopic;
}

struct Writers {
  std::string type;
  int count = 0;
  bool transientLocal = false;
};

// The writers discovery announces within `seconds`, by DDS topic name (stops early once `topic` is seen).
std::map<std::string, Writers> discover(dds_entity_t participant, double seconds, const std::string& topic = "") {
  std::map<std::string, Writers> found;
  const dds_entity_t pubs = dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end && !interrupted) {
    void* samples[32] = {};
    dds_sample_info_t info[32];
    const dds_return_t n = dds_take(pubs, samples, info, 32, 32);
    for (dds_return_t k = 0; k < n; ++k) {
      if (!info[k].valid_data || info[k].instance_state != DDS_IST_ALIVE) continue;
      const auto* ep = static_cast<const dds_builtintopic_endpoint_t*>(samples[k]);
      Writers& w = found[ep->topic_name];
      w.type = ep->type_name;
      ++w.count;
      dds_durability_kind_t d;
      if (dds_qget_durability(ep->qos, &d) && d == DDS_DURABILITY_TRANSIENT_LOCAL) w.transientLocal = true;
    }
    if (n > 0) dds_return_loan(pubs, samples, n);
    if (!topic.empty() && found.count(topic) && std::chrono::steady_clock::now() + std::chrono::milliseconds(200) < end) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the topic's other writers
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  dds_delete(pubs);
  return found;
}

std::string stamp(const builtin_interfaces_msg_dds__Time_& t) {
  char b[64];
  std::snprintf(b, sizeof b, "%d.%09u", t.sec, t.nanosec);
  return b;
}

void printDoubles(const char* name, const dds_sequence_double& s) {
  std::printf("%s: [", name);
  for (uint32_t i = 0; i < s._length; ++i) std::printf("%s%.9g", i ? ", " : "", s._buffer[i]);
  std::printf("]\n");
}

void print(const std::string& type, const void* sample) {
  if (type == "sensor_msgs::msg::dds_::JointState_") {
    const auto& m = *static_cast<const sensor_msgs_msg_dds__JointState_*>(sample);
    std::printf("header: {stamp: %s, frame_id: '%s'}\nname: [", stamp(m.header.stamp).c_str(), m.header.frame_id);
    for (uint32_t i = 0; i < m.name._length; ++i) std::printf("%s%s", i ? ", " : "", m.name._buffer[i]);
    std::printf("]\n");
    printDoubles("position", m.position);
    printDoubles("velocity", m.velocity);
    printDoubles("effort", m.effort);
  } else if (type == "tf2_msgs::msg::dds_::TFMessage_") {
    const auto& m = *static_cast<const tf2_msgs_msg_dds__TFMessage_*>(sample);
    std::printf("transforms:\n");
    for (uint32_t i = 0; i < m.transforms._length; ++i) {
      const auto& t = m.transforms._buffer[i];
      std::printf("- {stamp: %s, frame_id: %s, child_frame_id: %s, translation: [%.9g, %.9g, %.9g], rotation: [%.9g, %.9g, %.9g, %.9g]}\n",
                  stamp(t.header.stamp).c_str(), t.header.frame_id, t.child_frame_id, t.transform.translation.x,
                  t.transform.translation.y, t.transform.translation.z, t.transform.rotation.x, t.transform.rotation.y,
                  t.transform.rotation.z, t.transform.rotation.w);
    }
  } else {
    std::printf("data: %s\n", static_cast<const std_msgs_msg_dds__String_*>(sample)->data);
  }
  std::printf("---\n");
  std::fflush(stdout);
}

int run(const Options& o) {
  const auto domain = static_cast<dds_domainid_t>(o.domain);
  const std::string config = rp::Ros2Bridge::cycloneConfig(o.interfaces);
  if (const dds_entity_t d = dds_create_domain(domain, config.c_str()); d < 0)
    throw std::runtime_error("cannot start DDS domain " + std::to_string(o.domain) + ": " + dds_strretcode(d));
  const dds_entity_t participant = dds_create_participant(domain, nullptr, nullptr);
  if (participant < 0) throw std::runtime_error(std::string("cannot join the domain: ") + dds_strretcode(participant));

  if (o.command == "list") {
    const auto found = discover(participant, o.seconds > 0 ? o.seconds : 2);
    for (const auto& [topic, w] : found)
      std::printf("%s %s %d writer%s%s\n", rosTopic(topic).c_str(), rosType(w.type).c_str(), w.count, w.count == 1 ? "" : "s",
                  w.transientLocal ? " transient-local" : "");
    return found.empty() ? 1 : 0;
  }

  std::string name = o.topic;
  while (!name.empty() && name.front() == '/') name.erase(0, 1);
  const std::string ddsTopic = "rt/" + name;
  const auto found = discover(participant, o.seconds > 0 ? std::min(o.seconds, 5.0) : 5.0, ddsTopic);
  const auto it = found.find(ddsTopic);
  if (it == found.end()) {
    std::fprintf(stderr, "rp-dds: no writer of /%s on domain %d\n", name.c_str(), o.domain);
    return 1;
  }
  const std::string type = it->second.type;
  const dds_topic_descriptor_t* desc = type == "sensor_msgs::msg::dds_::JointState_" ? &sensor_msgs_msg_dds__JointState__desc
                                       : type == "tf2_msgs::msg::dds_::TFMessage_"   ? &tf2_msgs_msg_dds__TFMessage__desc
                                       : type == "std_msgs::msg::dds_::String_"      ? &std_msgs_msg_dds__String__desc
                                                                                     : nullptr;
  if (!desc) throw UsageError("/" + name + " is a " + rosType(type) + ", which rp-dds cannot print");
  const dds_entity_t topic = dds_create_topic(participant, desc, ddsTopic.c_str(), nullptr, nullptr);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, it->second.transientLocal ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 10);
  const dds_entity_t reader = dds_create_reader(participant, topic, qos, nullptr);
  dds_delete_qos(qos);
  if (reader < 0) throw std::runtime_error(std::string("cannot read /") + name + ": " + dds_strretcode(reader));
  long printed = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.seconds > 0 ? o.seconds : 1e9);
  while (!interrupted && std::chrono::steady_clock::now() < end && (o.count < 0 || printed < o.count)) {
    void* samples[1] = {nullptr};
    dds_sample_info_t info[1];
    const dds_return_t n = dds_take(reader, samples, info, 1, 1);
    if (n > 0) {
      if (info[0].valid_data) {
        print(type, samples[0]);
        ++printed;
      }
      dds_return_loan(reader, samples, n);
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  return printed > 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGINT, [](int) { interrupted = true; });
  std::signal(SIGTERM, [](int) { interrupted = true; });
  try {
    if (argc == 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
      std::cout << kUsage;
      return 0;
    }
    const int status = run(parse(argc, argv));
    dds_delete(DDS_CYCLONEDDS_HANDLE);
    return status;
  } catch (const UsageError& e) {
    std::cerr << "rp-dds: " << e.what() << "\n" << kUsage;
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "rp-dds: " << e.what() << "\n";
    return 2;
  }
}
