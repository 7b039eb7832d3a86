#pragma once
// Internal to src/ros2: the wire conventions shared by Ros2Bridge and RemoteManipulator (names,
// ROS 2's default QoS as rmw_cyclonedds has it, joining a DDS domain restricted to interfaces).
// Moved here from Ros2Bridge.cpp; not installed.

#include <dds/dds.h>
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "builtin_interfaces.h"
#include "rp/core/Configuration.hpp"

namespace rp::ros2detail {

constexpr int kMaxDomain = 230;  // Cyclone DDS's largest domain id with the default port mapping

// A ROS namespace: parts of letters, digits and '_', not starting with a digit, between '/'.
// (Hand-written: GCC 12's std::regex trips -Wmaybe-uninitialized in the sanitizer builds.)
inline bool validNamespace(const std::string& ns) {
  if (ns.size() > 200) return false;
  std::size_t begin = ns.empty() || ns.front() != '/' ? 0 : 1;
  std::size_t end = ns.size();
  if (end > begin && ns[end - 1] == '/') --end;
  if (begin >= end) return ns.empty();
  std::size_t partStart = begin;
  for (std::size_t i = begin; i <= end; ++i) {
    if (i == end || ns[i] == '/') {
      if (i == partStart) return false;  // empty part: "a//b"
      partStart = i + 1;
      continue;
    }
    const auto c = static_cast<unsigned char>(ns[i]);
    if (!(std::isalnum(c) || c == '_') || (i == partStart && std::isdigit(c))) return false;
  }
  return true;
}

inline bool validInterface(const std::string& name) {
  if (name.empty() || name.size() > 40) return false;
  for (char ch : name) {
    const auto c = static_cast<unsigned char>(ch);
    if (!(std::isalnum(c) || c == '_' || c == '.' || c == ':' || c == '@' || c == '-')) return false;
  }
  return true;
}

inline bool isIpv4Address(const std::string& text) {
  if (text.empty()) return false;
  for (char c : text)
    if (!(std::isdigit(static_cast<unsigned char>(c)) || c == '.')) return false;
  return true;
}

// A ROS name made of an object name (rp allows more characters than ROS names).
inline std::string rosName(const std::string& name) {
  std::string out;
  for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '_';
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "_" + out;
  return out;
}

inline std::string joined(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : " ") + w;
  return out;
}

inline std::string ddsError(dds_return_t r) { return dds_strretcode(r); }

// ROS 2's default QoS (reliable, volatile, keep-last 10), or transient-local keep-last 1 as
// robot_state_publisher offers robot_description; XCDR1 as rmw_cyclonedds writes and reads.
// The caller deletes it (dds_delete_qos).
inline dds_qos_t* rosQos(bool transientLocal) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(qos, transientLocal ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, transientLocal ? 1 : 10);
  dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(qos, 1, &xcdr1);
  return qos;
}

// The DDS domains this process created, shared by their users (bridges, remote arms, remote arm
// boards): deleting a domain deletes every participant in it, so only the last user's release
// deletes it. A domain some other code created (dds_create_domain directly) is used, never deleted.
struct DomainRegistry {
  struct Entry {
    dds_entity_t entity = 0;  // 0: not ours to delete
    int users = 0;
    std::string interfaces;
  };
  std::mutex mutex;
  std::map<int, Entry> domains;
  // Never destroyed: objects that release their domain may be destroyed at exit, after the
  // function-local statics (rp's shutdown runs from an exit handler).
  static DomainRegistry& instance() {
    static DomainRegistry* r = new DomainRegistry;
    return *r;
  }
};

// Joins DDS domain `domain` restricted by `config` (Ros2Bridge::cycloneConfig()), creating it if
// this process has not; each call is matched by one releaseDomain() after the caller's participant
// is deleted. `who` and `interfaces` name the caller and the interfaces in the exception, which
// also comes when the process uses the domain on other interfaces already.
inline void acquireDomain(int domain, const std::string& config, const std::string& who, const std::string& interfaces) {
  DomainRegistry& r = DomainRegistry::instance();
  std::lock_guard<std::mutex> lock(r.mutex);
  auto it = r.domains.find(domain);
  if (it != r.domains.end()) {
    if (it->second.interfaces != interfaces)
      throw std::runtime_error(who + ": DDS domain " + std::to_string(domain) + " is used in this process on " +
                               it->second.interfaces + " already, not on " + interfaces);
    ++it->second.users;
    return;
  }
  const dds_entity_t d = dds_create_domain(static_cast<dds_domainid_t>(domain), config.c_str());
  if (d < 0 && d != DDS_RETCODE_PRECONDITION_NOT_MET)  // (not met: created by other code of this process)
    throw std::runtime_error(who + ": DDS domain " + std::to_string(domain) + " cannot start on " + interfaces + ": " +
                             ddsError(d) + " (see Cyclone DDS's message above)");
  r.domains[domain] = {d > 0 ? d : 0, 1, interfaces};
}

// One user of `domain` lets go (after deleting its participant); the last one deletes it.
inline void releaseDomain(int domain) {
  DomainRegistry& r = DomainRegistry::instance();
  std::lock_guard<std::mutex> lock(r.mutex);
  auto it = r.domains.find(domain);
  if (it == r.domains.end() || --it->second.users > 0) return;
  if (it->second.entity > 0) dds_delete(it->second.entity);
  r.domains.erase(it);
}

// A remote arm's address `NS/OBJECT` (`OBJECT` alone without a namespace), split: the namespace
// without a leading '/', the object, and "NS/OBJECT" for messages.
struct RemoteArm {
  std::string nameSpace, object, label;
};
inline RemoteArm splitRemote(const std::string& remote) {
  RemoteArm r;
  const std::size_t slash = remote.rfind('/');
  r.object = slash == std::string::npos ? remote : remote.substr(slash + 1);
  r.nameSpace = slash == std::string::npos ? "" : remote.substr(0, slash);
  while (!r.nameSpace.empty() && r.nameSpace.front() == '/') r.nameSpace.erase(0, 1);
  r.label = r.nameSpace.empty() ? r.object : r.nameSpace + "/" + r.object;
  return r;
}

// Why a remote arm's address, domain and interfaces cannot be used ("" if they can); the message
// starts with the setting's name (RemoteManipulator, Ros2IoBoard).
inline std::string checkRemote(const std::string& remote, int domain, const std::vector<std::string>& interfaces) {
  const std::size_t slash = remote.rfind('/');
  const std::string object = slash == std::string::npos ? remote : remote.substr(slash + 1);
  const std::string ns = slash == std::string::npos ? "" : remote.substr(0, slash);
  if (remote.empty() || object.empty() || !validNamespace(ns) || (!ns.empty() && ns.back() == '/') || rosName(object) != object)
    return "remote '" + remote + "' is not NS/OBJECT (a ROS namespace, then the arm's object name)";
  if (domain < 0 || domain > kMaxDomain) return "domain must be 0 .. " + std::to_string(kMaxDomain);
  if (interfaces.empty()) return "interfaces must name at least one interface";
  for (const std::string& v : interfaces)
    if (!validInterface(v)) return "interfaces: '" + v + "' is not an interface name or address";
  return "";
}

// Declares the `interfaces` setting (one to 16 words), as the bridge and a remote arm take it.
inline void addInterfacesSetting(SettingSchema& schema) {
  schema.addWords("interfaces", 1, 16, "network interfaces (names or IPv4 addresses) DDS may use; any: Cyclone DDS's choice");
}

// The steady clock [ns]: receipt times and ages (no system call: vDSO).
inline std::int64_t steadyNanoseconds() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Takes every sample `reader` holds, one at a time, and calls `use(sample, info)` for each one with
// valid data; each loan is returned however `use` ends. For listeners and reader threads.
template <class T, class Use>
void takeEach(dds_entity_t reader, Use&& use) {
  for (;;) {
    void* loan[1] = {nullptr};
    dds_sample_info_t info[1];
    const dds_return_t count = dds_take(reader, loan, info, 1, 1);
    if (count <= 0) return;
    struct Return {
      dds_entity_t reader;
      void** loan;
      dds_return_t count;
      ~Return() { dds_return_loan(reader, loan, count); }
    } giveBack{reader, loan, count};
    if (info[0].valid_data) use(*static_cast<const T*>(loan[0]), info[0]);
  }
}

// The wall clock, the source of ROS time [ns since the epoch].
inline std::int64_t wallNanoseconds() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// A time in nanoseconds since the epoch (not negative) as a ROS Time.
inline builtin_interfaces_msg_dds__Time_ rosTime(std::int64_t ns) {
  builtin_interfaces_msg_dds__Time_ t{};
  t.sec = static_cast<int32_t>(ns / 1000000000);
  t.nanosec = static_cast<uint32_t>(ns % 1000000000);
  return t;
}

// Runs the calling thread (a bridge's publishing thread, a Ros2IoBoard's writer) at SCHED_FIFO
// `priority` (0: normal scheduling). A refusal is said once per process, on stderr, naming `who`.
inline void scheduleIoThread(int priority, const char* who) {
  if (priority <= 0) return;
  sched_param sp{};
  sp.sched_priority = priority;
  if (const int err = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp); err != 0) {
    static std::atomic<bool> warned{false};
    if (!warned.exchange(true))
      std::fprintf(stderr, "rp: %s: cannot use SCHED_FIFO priority %d (%s): its thread runs with normal scheduling\n", who,
                   priority, std::strerror(err));
  }
}

}  // namespace rp::ros2detail
