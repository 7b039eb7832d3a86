#include "rp/ros2/Ros2Bridge.hpp"

#include <dds/dds.h>

#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <pthread.h>
#include <sched.h>

#include <nlohmann/json.hpp>

#include "../core/ShortNumber.hpp"
#include "../manipulator/ArmSnapshot.hpp"
#include "../model/ExportFrames.hpp"
#include "../rt/CycleSignal.hpp"
#include "EffortCommandControl.hpp"
#include "Ros2Common.hpp"
#include "geometry_msgs.h"
#include "rp/core/ObjectManager.hpp"
#include "rp/core/TypeDatabase.hpp"
#include "rp/manipulator/Manipulator.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/ManipulatorData.hpp"
#include "rp/model/UrdfExport.hpp"
#include "rp/rt/Clock.hpp"
#include "rp/rt/ControlProgram.hpp"
#include "sensor_msgs.h"
#include "std_msgs.h"
#include "tf2_msgs.h"
#include "trajectory_msgs.h"
#include "rp/trajectory/TimedTrajectoryGenerator.hpp"

namespace rp {

namespace {

using ros2detail::ddsError;
using ros2detail::isIpv4Address;
using ros2detail::joined;
using ros2detail::kMaxDomain;
using ros2detail::rosName;
using ros2detail::rosTime;
using ros2detail::wallNanoseconds;
using ros2detail::validInterface;
using ros2detail::validNamespace;

builtin_interfaces_msg_dds__Time_ now() { return rosTime(wallNanoseconds()); }

// The wall clock (ROS time) of a control program's real clock: one offset between the two,
// measured with the program's clock read just before and just after the wall clock (the tightest
// of three tries), and measured again each second, as NTP slews or steps the wall clock. Stamps
// of successive cycles are then exactly as far apart as the cycles' read times, without the noise
// of two clock reads per sample (a thread preempted between them would shift one stamp).
struct WallClockMapping {
  const Clock* clock = nullptr;
  std::int64_t offsetNs = 0;          // wall clock - program clock [ns]
  double measuredAt = -1;             // program clock time of the measurement [s]

  // The wall-clock time of clock time `t`, or `publishedAt` where `t` is not of the last second.
  builtin_interfaces_msg_dds__Time_ stamp(const Clock& c, double t, const builtin_interfaces_msg_dds__Time_& publishedAt) {
    const double clockNow = c.getTime();
    const double age = clockNow - t;
    if (!(age >= 0 && age < 1)) return publishedAt;
    if (&c != clock || !(clockNow - measuredAt < 1.0 && clockNow >= measuredAt)) measure(c);
    return rosTime(std::llround(t * 1e9) + offsetNs);
  }

  void measure(const Clock& c) {
    double bracket = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      const double before = c.getTime();
      const std::int64_t wall = wallNanoseconds();
      const double after = c.getTime();
      if (after - before < bracket) {
        bracket = after - before;
        offsetNs = wall - std::llround(0.5 * (before + after) * 1e9);
        measuredAt = after;
      }
    }
    clock = &c;
  }
};

// The wall-clock time of the servo cycle that took a snapshot at clock time `cycleTime`: on the
// real clock, through the arm's WallClockMapping; on a simulated clock (whose time is not the
// wall's) the time of publication.
builtin_interfaces_msg_dds__Time_ cycleStamp(Manipulator& m, WallClockMapping& wall, double cycleTime,
                                             const builtin_interfaces_msg_dds__Time_& publishedAt) {
  const ControlProgram* program = m.getControlProgram();
  if (program == nullptr || program->getClock().isSimulated()) return publishedAt;
  return wall.stamp(program->getClock(), cycleTime, publishedAt);
}

// Quaternion (x, y, z, w) of a rotation matrix, w >= 0.
void toQuaternion(const Transform& t, geometry_msgs_msg_dds__Quaternion_& q) {
  const Eigen::Matrix3d R = t.topLeftCorner<3, 3>();
  Eigen::Quaterniond e(R);
  e.normalize();
  if (e.w() < 0) e.coeffs() *= -1;
  q.x = e.x();
  q.y = e.y();
  q.z = e.z();
  q.w = e.w();
}

}  // namespace

// An arm's effort commands: taken by a listener in Cyclone DDS's receive thread, checked there and
// handed to the arm's EffortCommandControl at once (the bridge's cycle connects the control to the
// arm when the first command comes). Kept at one address (the listener's argument).
struct EffortInput {
  const std::atomic<bool>* commands = nullptr;  // the bridge's switch
  std::atomic<std::uint64_t>* acceptedTotal = nullptr;  // the bridge's counters
  std::atomic<std::uint64_t>* refusedTotal = nullptr;
  int n = 0;
  dds_entity_t reader = 0;
  std::unique_ptr<ros2detail::EffortCommandControl> control;
  std::atomic<bool> wanted{false};     // a command came: the bridge's cycle connects the control
  std::atomic<bool> connected{false};  // the control drives the arm (the bridge's thread sets it)
  std::atomic<std::uint64_t> accepted{0}, refused{0};
  // The listener's own: the writer whose commands drive the arm, until it lets go (an empty
  // command) or sends none for driverHold [ns] (the bridge's effortTimeout).
  dds_instance_handle_t driver = 0;
  std::int64_t driverLast = 0, driverHold = 0;
  mutable std::mutex mutex;
  std::string refusal;  // the last refusal, "" if none

  void refuse(const std::string& why) {
    ++refused;
    ++*refusedTotal;
    std::lock_guard<std::mutex> lock(mutex);
    refusal = "refused: " + why;
  }
  std::string lastRefusal() const {
    std::lock_guard<std::mutex> lock(mutex);
    return refusal;
  }
  // The listener: every command received.
  void take() {
    ros2detail::takeEach<std_msgs_msg_dds__Float64MultiArray_>(reader, [&](const std_msgs_msg_dds__Float64MultiArray_& msg, const dds_sample_info_t& info) {
      const std::int64_t now = ros2detail::steadyNanoseconds();
      const bool other = driver != 0 && info.publication_handle != driver && now - driverLast < driverHold;
      if (!commands->load()) {
        refuse("commands are off (rp.cfg: commands on)");
      } else if (other) {
        refuse("another writer drives the arm: one stream of effort commands at a time");
      } else if (msg.data._length == 0) {  // the driver lets go: the arm holds from its next cycle
        control->release();
        driver = 0;
      } else if (msg.data._length != static_cast<uint32_t>(n)) {
        refuse("data: " + std::to_string(msg.data._length) + " efforts, the arm has " + std::to_string(n) + " joints");
      } else {
        int bad = -1;
        for (int i = 0; i < n && bad < 0; ++i)
          if (!std::isfinite(msg.data._buffer[i])) bad = i;
        if (bad >= 0) {
          refuse("data[" + std::to_string(bad) + "] is not a finite number");
        } else {
          control->command(msg.data._buffer, n);
          driver = info.publication_handle;
          driverLast = now;
          ++accepted;
          ++*acceptedTotal;
          if (!connected.load(std::memory_order_relaxed)) wanted = true;
        }
      }
    });
  }
};

// One arm as the bridge publishes it.
struct ArmEntry {
  std::string name;      // object name
  std::string rosName;   // the name in frames, joints and topics
  std::vector<std::string> jointNames;
  std::vector<char*> jointNamePointers;  // into jointNames, as a JointState's name sequence wants them
  std::vector<std::string> frameNames;  // link1..n, tool
  std::vector<Transform> frameFromModel;  // frame k = model link frame k * this (URDF link frames)
  std::unique_ptr<ManipulatorData> data;
  dds_entity_t stateWriter = 0;
  dds_entity_t descriptionWriter = 0;
  std::string urdf;
  std::string lastState;
  std::chrono::steady_clock::time_point lastStateTime;
  bool seen = false;
  double lastTime = std::numeric_limits<double>::quiet_NaN();  // the joints' time (StateSnapshot) published last
  WallClockMapping wall;  // the arm's clock to the stamps' wall clock
  dds_entity_t trajectoryReader = 0;
  std::unique_ptr<TimedTrajectoryGenerator> generator;  // connected to the arm on the first trajectory taken
  std::string lastCommand;  // the message about the last trajectory (accepted or refused)
  std::uint64_t accepted = 0, refused = 0;
  std::unique_ptr<EffortInput> effort;  // `<object>/effort_commands`

  // The arm's readers (before the entry goes: no listener runs after).
  void deleteEndpoints() {
    dds_delete(stateWriter);
    dds_delete(descriptionWriter);
    dds_delete(trajectoryReader);
    if (effort) dds_delete(effort->reader);
  }
};

struct Ros2Bridge::Impl {
  Ros2BridgeOptions options;
  std::string nameSpace;  // without leading and trailing '/'
  bool leased = false;  // the DDS domain (ros2detail::acquireDomain())
  dds_entity_t participant = 0;
  std::map<std::string, dds_entity_t> topics;
  dds_entity_t jointStates = 0, tf = 0, tfStatic = 0, description = 0;
  std::map<const RoboticObject*, ArmEntry> arms;
  // Reused by every cycle (at the servo rate up to 1000 a second): once they have grown to the
  // number of objects and frames, a cycle allocates nothing for them.
  std::vector<ObjectReference> published;  // empty between cycles: no arm is kept from its destruction
  std::vector<geometry_msgs_msg_dds__TransformStamped_> transforms;
  std::chrono::steady_clock::time_point lastFull{};  // the last full cycle (see cycle())
  std::atomic<std::uint64_t> cycles{0}, jointStatesWritten{0}, tfWritten{0}, descriptions{0}, states{0}, failures{0};
  std::atomic<std::size_t> manipulators{0};
  std::atomic<std::uint64_t> trajectories{0}, trajectoriesRefused{0};
  std::atomic<std::uint64_t> efforts{0}, effortsRefused{0};  // of every arm (EffortInput counts its own too)
  std::atomic<bool> commands{false};
  std::string bridgeName;
  mutable std::mutex messagesMutex;
  std::map<std::string, std::string> lastMessages;  // object name -> lastCommand, for getLastCommandMessage()

  ~Impl() {
    if (participant > 0) dds_delete(participant);
    if (leased) ros2detail::releaseDomain(options.domain);
  }

  dds_entity_t topic(const dds_topic_descriptor_t& desc, const std::string& name) {
    const std::string full = ddsTopicName(nameSpace, name);
    auto it = topics.find(full);
    if (it != topics.end()) return it->second;
    const dds_entity_t t = dds_create_topic(participant, &desc, full.c_str(), nullptr, nullptr);
    if (t < 0) throw std::runtime_error("Ros2Bridge: cannot create topic " + full + ": " + ddsError(t));
    topics.emplace(full, t);
    return t;
  }

  // ROS 2's default QoS (reliable, volatile, keep-last 10), or transient-local keep-last 1 as
  // robot_state_publisher offers robot_description; XCDR1 as rmw_cyclonedds writes and reads.
  // A writer, or a reader as a ROS 2 subscription has it (`isReader`).
  dds_entity_t endpoint(const dds_topic_descriptor_t& desc, const std::string& name, bool transientLocal, bool isReader) {
    dds_qos_t* qos = ros2detail::rosQos(transientLocal);
    const dds_entity_t t = topic(desc, name);
    const dds_entity_t e = isReader ? dds_create_reader(participant, t, qos, nullptr) : dds_create_writer(participant, t, qos, nullptr);
    dds_delete_qos(qos);
    if (e < 0)
      throw std::runtime_error(std::string("Ros2Bridge: cannot create a ") + (isReader ? "reader" : "writer") + " on " + name +
                               ": " + ddsError(e));
    return e;
  }
  dds_entity_t writer(const dds_topic_descriptor_t& desc, const std::string& name, bool transientLocal) {
    return endpoint(desc, name, transientLocal, false);
  }
  dds_entity_t reader(const dds_topic_descriptor_t& desc, const std::string& name) { return endpoint(desc, name, false, true); }

  void write(dds_entity_t w, const void* sample, std::atomic<std::uint64_t>& counter) {
    if (dds_write(w, sample) < 0)
      ++failures;
    else
      ++counter;
  }

  void writeString(dds_entity_t w, const std::string& text, std::atomic<std::uint64_t>& counter) {
    std_msgs_msg_dds__String_ s{};
    s.data = const_cast<char*>(text.c_str());
    write(w, &s, counter);
  }

  void addArm(const RoboticObject* o, Manipulator& m, ArmEntry& e);
  void takeTrajectories(Manipulator& m, ArmEntry& e);
  void connectEffortControl(Manipulator& m, ArmEntry& e);
  std::string executeTrajectory(Manipulator& m, ArmEntry& e, const trajectory_msgs_msg_dds__JointTrajectory_& msg);
  void writeSample(const ManipulatorModel& model, ArmEntry& e, const JointVector& q, const JointVector& qd,
                   const JointVector& tau, const builtin_interfaces_msg_dds__Time_& stamp);
  void cycle();
  void publishCombinedDescription();
};

Ros2Bridge::Ros2Bridge(const std::string& name) : FunctionalObject(ClassSection(name, "Ros2Bridge")), impl_(std::make_unique<Impl>()) {
  Ros2BridgeOptions& o = impl_->options;
  const ConfigSection* section = configSection();
  if (section) {
    if (const ConfigSetting* s = section->find("domain")) {
      const double d = section->getNumbers("domain").at(0);
      if (!(d >= 0 && d <= kMaxDomain) || d != std::floor(d))
        throw section->errorAt(*s, "setting 'domain' must be a whole number 0 .. " + std::to_string(kMaxDomain));
      o.domain = static_cast<int>(d);
    }
    if (const ConfigSetting* s = section->find("namespace")) {
      o.nameSpace = section->getWord("namespace");
      if (!validNamespace(o.nameSpace))
        throw section->errorAt(*s, "setting 'namespace' must be a ROS namespace such as cell1 or /lab/cell1 (letters, "
                                   "digits, '_' and '/', each part starting with a letter or '_')");
    }
    if (const ConfigSetting* s = section->find("rate")) {
      const std::string word = section->getWord("rate");
      double r = -1;
      if (word == "servo") {
        r = Ros2BridgeOptions::kServoRate;
      } else {
        char* end = nullptr;
        r = std::strtod(word.c_str(), &end);
        if (end == word.c_str() || *end != '\0' || !(r >= 1 && r <= 1000)) r = -1;
      }
      if (r < 0) throw section->errorAt(*s, "setting 'rate' must be servo or 1 .. 1000 Hz, got '" + word + "'");
      o.rate = r;
    }
    if (const ConfigSetting* s = section->find("interfaces")) {
      if (s->values.empty()) throw section->errorAt(*s, "setting 'interfaces' needs at least one interface");
      for (const std::string& v : s->values)
        if (!validInterface(v)) throw section->errorAt(*s, "setting 'interfaces': '" + v + "' is not an interface name or address");
      o.interfaces = s->values;
    }
    if (section->find("commands")) o.commands = section->getWord("commands") == "on";
    // A whole number 0 .. 98: the schema (declareSettings()) checked it at the setting's line.
    if (section->has("priority")) o.priority = static_cast<int>(section->getNumbers("priority").at(0));
    if (section->has("effortTimeout")) o.effortTimeout = section->getNumbers("effortTimeout").at(0);  // range: the schema's
  }
  try {
    start();
  } catch (const std::exception& e) {
    if (section) {
      if (const ConfigSetting* s = section->find("interfaces")) throw section->errorAt(*s, std::string("setting 'interfaces': ") + e.what());
      throw ConfigError(section->fileName(), section->line(), e.what());
    }
    throw;
  }
  startControlLoop();
}

Ros2Bridge::Ros2Bridge(const std::string& name, const Ros2BridgeOptions& options)
    : FunctionalObject(name), impl_(std::make_unique<Impl>()) {
  if (const std::string why = checkOptions(options); !why.empty()) throw std::invalid_argument("Ros2Bridge: " + why);
  impl_->options = options;
  start();
  startControlLoop();
}

Ros2Bridge::~Ros2Bridge() {
  stopControlLoop();  // first: the publishing thread ends before DDS goes
  impl_.reset();
}

std::string Ros2Bridge::checkOptions(const Ros2BridgeOptions& o) {
  if (o.domain < 0 || o.domain > kMaxDomain) return "domain must be 0 .. " + std::to_string(kMaxDomain);
  if (!validNamespace(o.nameSpace)) return "namespace '" + o.nameSpace + "' is not a ROS namespace";
  if (!(o.rate == Ros2BridgeOptions::kServoRate || (o.rate >= 1 && o.rate <= 1000)))
    return "rate must be Ros2BridgeOptions::kServoRate or 1 .. 1000 Hz";
  if (o.priority < 0 || o.priority > 98) return "priority must be 0 (normal scheduling) .. 98";
  if (!(o.effortTimeout >= 0.002 && o.effortTimeout <= 1)) return "effortTimeout must be 0.002 .. 1 s";
  if (o.interfaces.empty()) return "interfaces must name at least one interface";
  for (const std::string& v : o.interfaces)
    if (!validInterface(v)) return "'" + v + "' is not an interface name or address";
  return "";
}

void Ros2Bridge::declareSettings(SettingSchema& schema) {
  RoboticObject::declareSettings(schema);
  schema.addInteger("domain", "DDS domain id (ROS_DOMAIN_ID)", 0, kMaxDomain);
  schema.addWord("namespace", "ROS namespace of the topics, e.g. cell1");
  schema.addWord("rate", "joint_states and tf samples per second, 1 .. 1000 Hz, or servo: every servo cycle's new joints");
  ros2detail::addInterfacesSetting(schema);
  schema.setDefault("domain", "0");
  schema.setDefault("namespace", "(none)");
  schema.setDefault("rate", "50");
  schema.setDefault("interfaces", "lo");
  schema.addChoice("commands", {"on", "off"}, "take trajectories from each arm's joint_trajectory topic (trajectory_msgs/JointTrajectory)");
  schema.setDefault("commands", "off");
  schema.addInteger("priority", "SCHED_FIFO priority of the publishing thread (0: normal scheduling)", 0, 98);
  schema.setDefault("priority", "26");
  schema.addNumbers("effortTimeout", 1, "s", "effort commands drive an arm this long after the last one, then it holds", 0.002, 1);
  schema.setDefault("effortTimeout", "0.02");
}

const Ros2BridgeOptions& Ros2Bridge::getOptions() const noexcept { return impl_->options; }

Ros2BridgeStatistics Ros2Bridge::getStatistics() const noexcept {
  Ros2BridgeStatistics s;
  s.cycles = impl_->cycles;
  s.jointStates = impl_->jointStatesWritten;
  s.tf = impl_->tfWritten;
  s.descriptions = impl_->descriptions;
  s.states = impl_->states;
  s.writeFailures = impl_->failures;
  s.manipulators = impl_->manipulators;
  s.trajectories = impl_->trajectories;
  s.trajectoriesRefused = impl_->trajectoriesRefused;
  s.efforts = impl_->efforts;
  s.effortsRefused = impl_->effortsRefused;
  return s;
}

void Ros2Bridge::setCommandsEnabled(bool on) noexcept { impl_->commands = on; }

bool Ros2Bridge::areCommandsEnabled() const noexcept { return impl_->commands; }

std::string Ros2Bridge::getLastCommandMessage(const std::string& object) const {
  std::lock_guard<std::mutex> lock(impl_->messagesMutex);
  const auto it = impl_->lastMessages.find(object);
  return it == impl_->lastMessages.end() ? std::string() : it->second;
}

std::string Ros2Bridge::ddsTopicName(const std::string& nameSpace, const std::string& topic) {
  std::string ns = nameSpace;
  while (!ns.empty() && ns.front() == '/') ns.erase(0, 1);
  while (!ns.empty() && ns.back() == '/') ns.pop_back();
  return ns.empty() ? "rt/" + topic : "rt/" + ns + "/" + topic;
}

std::string Ros2Bridge::cycloneConfig(const std::vector<std::string>& interfaces) {
  std::ostringstream x;
  x << "<CycloneDDS><Domain Id=\"any\">";
  const bool any = interfaces.size() == 1 && interfaces[0] == "any";
  if (!any) {
    x << "<General><Interfaces>";
    for (const std::string& i : interfaces) {
      const bool address = isIpv4Address(i);
      x << "<NetworkInterface " << (address ? "address" : "name") << "=\"" << i << "\"/>";
    }
    x << "</Interfaces>";
    const bool loopbackOnly = interfaces.size() == 1 && (interfaces[0] == "lo" || interfaces[0] == "127.0.0.1");
    // Linux's lo has no multicast: participants on this machine find each other by unicast.
    if (loopbackOnly) x << "<AllowMulticast>false</AllowMulticast>";
    x << "</General>";
    if (loopbackOnly)
      x << "<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>50</MaxAutoParticipantIndex>"
           "<Peers><Peer Address=\"127.0.0.1\"/></Peers></Discovery>";
  }
  x << "</Domain></CycloneDDS>";
  return x.str();
}

std::string Ros2Bridge::prefixUrdf(const std::string& object, const std::string& urdf) {
  static const char* const kNameAttributes[] = {"<link name=\"",         "<joint name=\"",  "<transmission name=\"",
                                                "<actuator name=\"",     "<parent link=\"", "<child link=\""};
  const std::string prefix = rosName(object) + "_";
  std::string out;
  out.reserve(urdf.size() + urdf.size() / 8);
  std::size_t at = 0;
  for (;;) {
    std::size_t next = std::string::npos, length = 0;  // the earliest name attribute from `at`
    for (const char* a : kNameAttributes) {
      const std::size_t p = urdf.find(a, at);
      if (p < next) {
        next = p;
        length = std::strlen(a);
      }
    }
    if (next == std::string::npos) break;
    const std::size_t nameStart = next + length;
    const std::size_t nameEnd = urdf.find('"', nameStart);
    if (nameEnd == std::string::npos) break;
    out.append(urdf, at, nameStart - at);
    const std::string name = urdf.substr(nameStart, nameEnd - nameStart);
    if (name != "world") out += prefix;
    out += name;
    at = nameEnd;
  }
  out.append(urdf, at, std::string::npos);
  return out;
}

void Ros2Bridge::start() {
  Impl& d = *impl_;
  d.bridgeName = getName();
  d.commands = d.options.commands;
  std::string ns = d.options.nameSpace;
  while (!ns.empty() && ns.front() == '/') ns.erase(0, 1);
  while (!ns.empty() && ns.back() == '/') ns.pop_back();
  d.nameSpace = ns;
  const auto domainId = static_cast<dds_domainid_t>(d.options.domain);
  const std::string config = cycloneConfig(d.options.interfaces);
  ros2detail::acquireDomain(d.options.domain, config, "Ros2Bridge", joined(d.options.interfaces));
  d.leased = true;
  d.participant = dds_create_participant(domainId, nullptr, nullptr);
  if (d.participant < 0)
    throw std::runtime_error("Ros2Bridge: cannot join DDS domain " + std::to_string(d.options.domain) + ": " +
                             ddsError(d.participant));
  d.jointStates = d.writer(sensor_msgs_msg_dds__JointState__desc, "joint_states", false);
  d.tf = d.writer(tf2_msgs_msg_dds__TFMessage__desc, "tf", false);
  d.tfStatic = d.writer(tf2_msgs_msg_dds__TFMessage__desc, "tf_static", true);
  d.description = d.writer(std_msgs_msg_dds__String__desc, "robot_description", true);
  if (d.options.rate == Ros2BridgeOptions::kServoRate) {
    // Every servo cycle: woken as executor cycles end (CycleSignal), or every 50 ms without any.
    addThread("ros2bridge", [this](const std::atomic<bool>& stop) {
      ros2detail::scheduleIoThread(impl_->options.priority, "Ros2Bridge");
      std::uint64_t seen = internal::cyclesEnded();
      while (!stop.load(std::memory_order_acquire)) {
        seen = internal::waitForCycleEnd(seen, 0.05);
        impl_->cycle();
      }
    });
  } else {
    addPeriodicThread("ros2bridge", 1.0 / d.options.rate, [this, scheduled = false]() mutable {
      if (!scheduled) ros2detail::scheduleIoThread(impl_->options.priority, "Ros2Bridge");
      scheduled = true;
      impl_->cycle();
    });
  }
}

void Ros2Bridge::Impl::addArm(const RoboticObject* o, Manipulator& m, ArmEntry& e) {
  (void)o;
  const ManipulatorModel& model = m.getModel();
  const int n = model.getNumberOfJoints();
  e.name = m.getName();
  e.rosName = rosName(e.name);
  e.data = std::make_unique<ManipulatorData>(model);
  for (int i = 0; i < n; ++i) {
    e.jointNames.push_back(e.rosName + "_" + model.getJointName(i));
    e.frameNames.push_back(e.rosName + "_" + model.getLinkName(i));
    // URDF link k is the frame after joint k's motion, as toUrdf() writes it: the model's link
    // frame k without the part of A_k after the motion (jointFrames().post; standard DH only).
    e.frameFromModel.push_back(rigidInverse(internal::jointFrames(model, i).post));
  }
  e.frameNames.push_back(e.rosName + "_tool");
  e.frameFromModel.push_back(Transform::unit());
  e.urdf = prefixUrdf(e.name, toUrdf(model));
  e.stateWriter = writer(std_msgs_msg_dds__String__desc, e.rosName + "/state", false);
  e.descriptionWriter = writer(std_msgs_msg_dds__String__desc, e.rosName + "/robot_description", true);
  writeString(e.descriptionWriter, e.urdf, descriptions);
  e.trajectoryReader = reader(trajectory_msgs_msg_dds__JointTrajectory__desc, e.rosName + "/joint_trajectory");
  e.generator = std::make_unique<TimedTrajectoryGenerator>(bridgeName + "_" + e.rosName + "_joint_trajectory");
  e.effort = std::make_unique<EffortInput>();
  e.effort->commands = &commands;
  e.effort->acceptedTotal = &efforts;
  e.effort->refusedTotal = &effortsRefused;
  e.effort->n = n;
  e.effort->driverHold = static_cast<std::int64_t>(options.effortTimeout * 1e9);
  e.effort->control = std::make_unique<ros2detail::EffortCommandControl>(bridgeName + "_" + e.rosName + "_effort", options.effortTimeout);
  dds_listener_t* listener = dds_create_listener(e.effort.get());
  dds_lset_data_available(listener, [](dds_entity_t, void* arg) { static_cast<EffortInput*>(arg)->take(); });
  {
    dds_qos_t* qos = ros2detail::rosQos(false);
    e.effort->reader = dds_create_reader(participant, topic(std_msgs_msg_dds__Float64MultiArray__desc, e.rosName + "/effort_commands"), qos, listener);
    dds_delete_qos(qos);
  }
  dds_delete_listener(listener);
  if (e.effort->reader < 0)
    throw std::runtime_error("Ros2Bridge: cannot create a reader on " + e.rosName + "/effort_commands: " + ddsError(e.effort->reader));
  // tf_static: the base, fixed in the world.
  geometry_msgs_msg_dds__TransformStamped_ ts{};
  ts.header.stamp = now();
  ts.header.frame_id = const_cast<char*>("world");
  const std::string base = e.rosName + "_base_link";
  ts.child_frame_id = const_cast<char*>(base.c_str());
  const Transform b = model.getBaseTransform();
  ts.transform.translation = {b(0, 3), b(1, 3), b(2, 3)};
  toQuaternion(b, ts.transform.rotation);
  tf2_msgs_msg_dds__TFMessage_ msg{};
  msg.transforms._buffer = &ts;
  msg.transforms._length = msg.transforms._maximum = 1;
  msg.transforms._release = false;
  write(tfStatic, &msg, tfWritten);
}

void Ros2Bridge::Impl::publishCombinedDescription() {
  // One robot holding every arm: each arm's URDF without its <robot> lines and its world link.
  std::string all = "<?xml version=\"1.0\"?>\n<robot name=\"" + (nameSpace.empty() ? std::string("rp") : rosName(nameSpace)) +
                    "\" xmlns:drake=\"http://drake.mit.edu\">\n  <link name=\"world\"/>\n";
  for (auto& [o, e] : arms) {
    const std::size_t open = e.urdf.find("<robot");
    const std::size_t body = e.urdf.find('>', open) + 1;
    const std::size_t close = e.urdf.rfind("</robot>");
    std::string part = e.urdf.substr(body, close - body);
    const std::string world = "<link name=\"world\"/>";
    if (const std::size_t w = part.find(world); w != std::string::npos) part.erase(w, world.size());
    all += part;
  }
  all += "</robot>\n";
  writeString(description, all, descriptions);
}

// One arm's sample: its joint_states message, and its frames added to this cycle's tf message.
void Ros2Bridge::Impl::writeSample(const ManipulatorModel& model, ArmEntry& e, const JointVector& q, const JointVector& qd,
                                   const JointVector& tau, const builtin_interfaces_msg_dds__Time_& stamp) {
  const int n = model.getNumberOfJoints();
  if (e.jointNamePointers.size() != e.jointNames.size()) {  // once, where the entry stays (arms' map)
    e.jointNamePointers.clear();
    for (const std::string& name : e.jointNames) e.jointNamePointers.push_back(const_cast<char*>(name.c_str()));
  }
  sensor_msgs_msg_dds__JointState_ js{};
  js.header.stamp = stamp;
  js.header.frame_id = const_cast<char*>("");
  js.name._buffer = e.jointNamePointers.data();
  js.position._buffer = const_cast<double*>(q.data());  // dds_write only reads
  js.velocity._buffer = const_cast<double*>(qd.data());
  js.effort._buffer = const_cast<double*>(tau.data());
  for (auto* s : {&js.position, &js.velocity, &js.effort}) s->_length = s->_maximum = static_cast<uint32_t>(n);
  js.name._length = js.name._maximum = static_cast<uint32_t>(n);
  write(jointStates, &js, jointStatesWritten);

  forwardKinematics(model, *e.data, q);
  for (std::size_t f = 0; f < e.frameNames.size(); ++f) {
    const Transform t = (f < static_cast<std::size_t>(n) ? e.data->linkTransforms[f] : e.data->endEffector) * e.frameFromModel[f];
    geometry_msgs_msg_dds__TransformStamped_ ts{};
    ts.header.stamp = stamp;
    ts.header.frame_id = const_cast<char*>("world");
    ts.child_frame_id = const_cast<char*>(e.frameNames[f].c_str());
    ts.transform.translation = {t(0, 3), t(1, 3), t(2, 3)};
    toQuaternion(t, ts.transform.rotation);
    transforms.push_back(ts);
  }
}

void Ros2Bridge::Impl::cycle() {
  ++cycles;
  // At the servo rate this runs after every servo cycle: the arms' state, trajectories taken,
  // arms joined and gone are looked at 50 times a second ("full" cycles), as at a set rate always.
  const bool servo = options.rate == Ros2BridgeOptions::kServoRate;
  const auto started = std::chrono::steady_clock::now();
  const bool full = !servo || started - lastFull >= std::chrono::milliseconds(20);
  if (full) lastFull = started;
  ObjectManager().getPublishedObjects(published);
  // The references go when the cycle ends, however it ends: an arm's destruction never waits for
  // the bridge's next cycle.
  struct Release {
    std::vector<ObjectReference>& references;
    ~Release() { references.clear(); }
  } release{published};
  if (full)
    for (auto& [o, e] : arms) e.seen = false;
  bool changed = false;
  const builtin_interfaces_msg_dds__Time_ publishedAt = now();
  transforms.clear();
  std::size_t count = 0;
  for (const ObjectReference& r : published) {
    auto* m = dynamic_cast<Manipulator*>(r.get());
    if (!m) continue;
    auto it = arms.find(r.get());
    if (!full && (it == arms.end() || it->second.name != m->getName())) continue;  // joins in a full cycle
    if (it == arms.end() || it->second.name != m->getName()) {
      if (it != arms.end()) it->second.deleteEndpoints();  // a new arm at the address of a destroyed one
      ArmEntry e;
      addArm(r.get(), *m, e);
      it = arms.insert_or_assign(r.get(), std::move(e)).first;
      changed = true;
    }
    ArmEntry& e = it->second;
    e.seen = true;
    ++count;
    const ManipulatorModel& model = m->getModel();
    const int n = model.getNumberOfJoints();
    // One consistent cycle of the servo loop (DefaultManipulator's snapshot: q, qd, tau, power).
    StateSnapshot snap;
    internal::ArmCycleState cycle;
    builtin_interfaces_msg_dds__Time_ stamp = publishedAt;
    bool fresh = true;  // a sample to write (at the servo rate: only of a servo cycle not yet written)
    if (m->getStateSnapshot(snap) && internal::armCycleState(*m, snap, n, cycle)) {
      // At the servo rate, each sample of the joints once: a cycle that read an arm's hardware
      // sample again (its server late) keeps that sample's time and publishes nothing.
      const double held = snap.readTime > 0 ? snap.readTime : snap.time;
      fresh = !servo || held != e.lastTime;
      e.lastTime = held;
      // Stamped with the time the cycle read the joints, as ros2_control's joint_state_broadcaster
      // stamps with the time of the controller manager's read.
      stamp = cycleStamp(*m, e.wall, held, publishedAt);
    } else {
      cycle.q = m->getJointPosition();
      cycle.qd = m->getJointVelocity();
      cycle.tau = m->getControlOutput();
      cycle.power = m->isArmPowerOn();
    }
    const JointVector &q = cycle.q, &qd = cycle.qd, &tau = cycle.tau;
    const bool power = cycle.power;
    if (q.size() != n || qd.size() != n || tau.size() != n) continue;
    if (fresh) writeSample(model, e, q, qd, tau, stamp);
    if (!full) continue;
    takeTrajectories(*m, e);
    connectEffortControl(*m, e);

    // Diagnostics: when they change and once a second.
    const ErrorStatus err = m->getErrorStatus();
    nlohmann::json j = {{"object", e.name},
                        {"class", m->getClassName()},
                        {"power", power},
                        {"errorCode", err.code},
                        {"error", err.message},
                        {"shutdown", ObjectManager::isShutdownRequested()},
                        {"shutdownReason", ObjectManager::isShutdownRequested() ? ObjectManager::getShutdownReason() : ""},
                        {"commands", commands.load()},
                        {"trajectory", e.lastCommand},
                        {"trajectoriesAccepted", e.accepted},
                        {"trajectoriesRefused", e.refused},
                        {"trajectoryDone", e.generator->isDone()},
                        {"effortDriving", e.effort->connected.load() && e.effort->control->isDriving()},
                        {"effort", e.effort->lastRefusal()},
                        {"effortsRefused", e.effort->refused.load()}};
    const std::string text = j.dump();
    const auto t = std::chrono::steady_clock::now();
    if (text != e.lastState || t - e.lastStateTime >= std::chrono::seconds(1)) {
      writeString(e.stateWriter, text, states);
      e.lastState = text;
      e.lastStateTime = t;
    }
  }
  if (!transforms.empty()) {
    tf2_msgs_msg_dds__TFMessage_ msg{};
    msg.transforms._buffer = transforms.data();
    msg.transforms._length = msg.transforms._maximum = static_cast<uint32_t>(transforms.size());
    write(tf, &msg, tfWritten);
  }
  for (auto it = arms.begin(); full && it != arms.end();) {  // arms destroyed since: their writers go
    if (!it->second.seen) {
      it->second.deleteEndpoints();
      it = arms.erase(it);
      changed = true;
    } else {
      ++it;
    }
  }
  if (changed) publishCombinedDescription();
  manipulators = count;
}

// At most this many trajectories are taken per arm and bridge cycle (the rest wait in the reader's
// keep-last 10 history for the next cycle).
constexpr int kTrajectoriesPerCycle = 4;

void Ros2Bridge::Impl::takeTrajectories(Manipulator& m, ArmEntry& e) {
  for (int taken = 0; taken < kTrajectoriesPerCycle; ++taken) {
    void* samples[1] = {nullptr};
    dds_sample_info_t info[1];
    const dds_return_t n = dds_take(e.trajectoryReader, samples, info, 1, 1);
    if (n <= 0) return;
    if (info[0].valid_data) {
      std::string why;
      try {
        why = executeTrajectory(m, e, *static_cast<const trajectory_msgs_msg_dds__JointTrajectory_*>(samples[0]));
      } catch (const std::exception& x) {
        why = x.what();
      }
      if (why.empty()) {
        ++e.accepted;
        ++trajectories;
      } else {
        e.lastCommand = "refused: " + why;
        ++e.refused;
        ++trajectoriesRefused;
      }
      std::lock_guard<std::mutex> lock(messagesMutex);
      lastMessages[e.name] = e.lastCommand;
    }
    dds_return_loan(e.trajectoryReader, samples, n);
  }
}

// The first effort command of an arm: its EffortCommandControl takes over from the arm's default
// control (and from the bridge's trajectory generator), unless the arm's program drives it.
void Ros2Bridge::Impl::connectEffortControl(Manipulator& m, ArmEntry& e) {
  EffortInput& in = *e.effort;
  if (in.connected.load()) {
    // Still the arm's control? Its program (or an operator's panel) may have set another, or
    // switched zero-gravity mode on (no servo control runs then): the commands no longer drive it.
    const std::string why = &m.getServoControl() != in.control.get()
                                ? "the arm's program set its servo control '" + m.getServoControl().getName() + "'"
                            : m.isZeroGravityModeOn() ? std::string("the arm is in zero-gravity mode")
                                                      : std::string();
    if (why.empty()) return;
    if (&m.getServoControl() == in.control.get()) m.releaseServoControl(*in.control);
    in.connected = false;
    in.refuse(why);
    return;
  }
  if (!in.wanted.exchange(false)) return;
  if (m.isZeroGravityModeOn()) {
    in.refuse("the arm is in zero-gravity mode");
    return;
  }
  TrajectoryGenerator* driving = m.getTrajectoryGenerator();
  if (driving != nullptr && driving != e.generator.get()) {
    in.refuse("the arm is driven by a trajectory generator of its program ('" + driving->getName() + "')");
    return;
  }
  try {
    if (driving != nullptr) m.clearTrajectoryGenerator();
    m.setServoControl(*in.control);
    in.connected = true;
  } catch (const std::exception& x) {
    in.refuse(x.what());
  }
}

namespace {

// Six significant digits (as a stream prints them).
std::string number(double x) { return internal::shortNumber(x, 6); }

std::string field(std::size_t point, const char* name) { return "points[" + std::to_string(point) + "]." + name; }

}  // namespace

// Checks a trajectory_msgs/JointTrajectory for arm `m` and hands it to the arm's generator: ""
// when it is executed, else why not (the field named as in the message).
std::string Ros2Bridge::Impl::executeTrajectory(Manipulator& m, ArmEntry& e,
                                                const trajectory_msgs_msg_dds__JointTrajectory_& msg) {
  if (!commands) return "commands are off (rp.cfg: commands on in the bridge's section, or setCommandsEnabled(true))";
  const ManipulatorModel& model = m.getModel();
  const int n = model.getNumberOfJoints();
  const auto dof = static_cast<std::size_t>(n);
  // joint_names: the arm's, each once, in any order.
  if (msg.joint_names._length != dof)
    return "joint_names: " + std::to_string(msg.joint_names._length) + " names, the arm has " + std::to_string(n) +
           " joints (" + joined(e.jointNames) + ")";
  std::vector<int> jointOf(dof, -1);  // message column -> arm joint
  std::vector<bool> named(dof, false);
  for (std::size_t c = 0; c < dof; ++c) {
    const char* name = msg.joint_names._buffer[c];
    const std::string text = name != nullptr ? name : "";
    std::size_t j = 0;
    while (j < dof && e.jointNames[j] != text) ++j;
    if (j == dof) return "joint_names[" + std::to_string(c) + "]: '" + text + "' is not a joint of the arm (" + joined(e.jointNames) + ")";
    if (named[j]) return "joint_names[" + std::to_string(c) + "]: '" + text + "' appears twice";
    named[j] = true;
    jointOf[c] = static_cast<int>(j);
  }
  // points: how many, sizes, finite values, times.
  const std::size_t count = msg.points._length;
  if (count == 0) return "points: none (an empty trajectory does not stop the arm here; send the position to hold)";
  if (count > static_cast<std::size_t>(TimedJointTrajectory::kMaxPoints))
    return "points: " + std::to_string(count) + ", more than " + std::to_string(TimedJointTrajectory::kMaxPoints);
  const auto& p0 = msg.points._buffer[0];
  const bool velocities = p0.velocities._length != 0, accelerations = p0.accelerations._length != 0;
  const JointVector qmin = model.getPositionMin(), qmax = model.getPositionMax();
  std::vector<TimedJointPoint> points(count);
  double previous = -1;
  for (std::size_t k = 0; k < count; ++k) {
    const auto& p = msg.points._buffer[k];
    if (p.positions._length != dof)
      return field(k, "positions") + ": " + std::to_string(p.positions._length) + " values, not " + std::to_string(n);
    if (p.velocities._length != (velocities ? dof : 0))
      return field(k, "velocities") + ": " + std::to_string(p.velocities._length) + " values, not " +
             std::to_string(velocities ? n : 0) + " as points[0] (every point needs the same fields)";
    if (p.accelerations._length != (accelerations ? dof : 0))
      return field(k, "accelerations") + ": " + std::to_string(p.accelerations._length) + " values, not " +
             std::to_string(accelerations ? n : 0) + " as points[0] (every point needs the same fields)";
    if (accelerations && !velocities) return field(k, "accelerations") + ": given without velocities";
    if (p.time_from_start.nanosec >= 1000000000u) return field(k, "time_from_start.nanosec") + ": 1e9 or more";
    const double t = p.time_from_start.sec + 1e-9 * p.time_from_start.nanosec;
    if (t < 0) return field(k, "time_from_start") + ": negative (" + number(t) + " s)";
    if (!(t > previous))
      return field(k, "time_from_start") + ": " + number(t) + " s, not after points[" + std::to_string(k - 1) + "] (" +
             number(previous) + " s)";
    previous = t;
    TimedJointPoint& out = points[k];
    out.time = t;
    out.position.resize(n);
    if (velocities) out.velocity.resize(n);
    if (accelerations) out.acceleration.resize(n);
    for (std::size_t c = 0; c < dof; ++c) {
      const int j = jointOf[c];
      const std::string column = "[" + std::to_string(c) + "] (" + e.jointNames[static_cast<std::size_t>(j)] + ")";
      const double q = p.positions._buffer[c];
      if (!std::isfinite(q)) return field(k, "positions") + column + ": not a finite number";
      if (q < qmin(j) || q > qmax(j))
        return field(k, "positions") + column + " = " + number(q) + " is outside the joint limits [" + number(qmin(j)) +
               ", " + number(qmax(j)) + "]";
      out.position(j) = q;
      if (velocities) {
        if (!std::isfinite(p.velocities._buffer[c])) return field(k, "velocities") + column + ": not a finite number";
        out.velocity(j) = p.velocities._buffer[c];
      }
      if (accelerations) {
        if (!std::isfinite(p.accelerations._buffer[c])) return field(k, "accelerations") + column + ": not a finite number";
        out.acceleration(j) = p.accelerations._buffer[c];
      }
    }
    if (k + 1 == count && ((velocities && !out.velocity.isZero(0)) || (accelerations && !out.acceleration.isZero(0))))
      return field(k, "velocities") + ": the last point's velocities and accelerations must be 0 (the arm stops there)";
  }
  // header.stamp: 0 starts on receipt (as joint_trajectory_controller); a time in the future later.
  double delay = 0;
  if (msg.header.stamp.sec != 0 || msg.header.stamp.nanosec != 0) {
    const double stamp = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec;
    const double wall = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
    delay = std::max(0.0, stamp - wall);
    if (delay > 60) return "header.stamp: " + number(delay) + " s in the future (at most 60 s)";
  }
  // The arm: powered, not shutting down, not driven by a program's generator.
  if (ObjectManager::isShutdownRequested()) return "the system is shutting down";
  if (!m.isArmPowerOn()) return "the arm power is off";
  // One command stream at a time: a trajectory may take the arm from effort commands only once
  // they have stopped (the arm holding).
  if (e.effort->connected.load() && e.effort->control->isDriving())
    return "the arm is driven by effort commands (" + e.rosName + "/effort_commands)";
  TrajectoryGenerator* driving = m.getTrajectoryGenerator();
  if (driving != nullptr && driving != e.generator.get())
    return "the arm follows the program's trajectory generator '" + driving->getName() + "'";
  // Where the motion starts: the generator's last setpoint if it drives the arm, else the arm at rest.
  Setpoint start;
  start.position = m.getJointPosition();
  start.velocity = JointVector::Zero(n);
  start.acceleration = JointVector::Zero(n);
  if (driving != nullptr) {
    JointVector q, qd;
    for (int attempt = 0; attempt < 100 && !e.generator->getLastSetpoint(q, qd); ++attempt) std::this_thread::yield();
    if (q.size() == n) {
      start.position = q;
      start.velocity = qd;
    }
  }
  if (points[0].time == 0) {
    for (int j = 0; j < n; ++j)
      if (std::abs(points[0].position(j) - start.position(j)) > 1e-3)
        return field(0, "positions") + " at time_from_start 0: " + e.jointNames[static_cast<std::size_t>(j)] + " is " +
               number(points[0].position(j) - start.position(j)) + " from the arm's setpoint (a jump; 1e-3 allowed)";
  }
  auto trajectory = std::make_unique<TimedJointTrajectory>(std::move(points));
  trajectory->start(start);
  const TrajectoryLimitViolation v =
      trajectory->findLimitViolation(qmin, qmax, model.getVelocityLimit());
  if (v.found) {
    const std::string piece = v.point == 0 ? "on the way from the arm's setpoint to points[0]"
                                           : "between points[" + std::to_string(v.point - 1) + "] and points[" +
                                                 std::to_string(v.point) + "]";
    const std::string joint = e.jointNames[static_cast<std::size_t>(v.joint)];
    return "points[" + std::to_string(v.point) + "]: " + joint + (v.velocity ? " velocity " : " position ") + number(v.value) +
           (v.velocity ? " exceeds the velocity limit " : " passes the joint limit ") + number(v.limit) + " " + piece +
           " (at " + number(v.time) + " s)";
  }
  if (e.effort->connected.load()) {  // held after effort commands: the default control takes over
    m.releaseServoControl(*e.effort->control);
    e.effort->connected = false;
  }
  if (driving == nullptr) m.setTrajectoryGenerator(*e.generator);
  const std::size_t size = msg.points._length;
  const std::string kind = accelerations ? "quintic" : velocities ? "cubic" : "cubic, velocities estimated";
  e.generator->execute(std::move(trajectory), delay);
  e.lastCommand = "accepted: " + std::to_string(size) + " points over " + number(previous) + " s (" + kind + ")" +
                  (delay > 0 ? ", starting in " + number(delay) + " s" : "");
  return "";
}

}  // namespace rp

RP_REGISTER_CLASS_AS(rp::Ros2Bridge, "Ros2Bridge");
