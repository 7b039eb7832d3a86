#include "rp/ros2/RemoteManipulator.hpp"

#include <dds/dds.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <nlohmann/json.hpp>

#include "../rt/CycleSignal.hpp"
#include "Ros2Common.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/core/TypeDatabase.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/ManipulatorData.hpp"
#include "rp/model/UrdfModel.hpp"
#include "rp/ros2/Ros2Bridge.hpp"
#include "rp/rt/TripleBuffer.hpp"
#include "rp/trajectory/TrajectoryGenerator.hpp"
#include "sensor_msgs.h"
#include "std_msgs.h"
#include "trajectory_msgs.h"

namespace rp {

namespace {

using ros2detail::ddsError;
using ros2detail::joined;

constexpr double kHorizon = 0.05;   // the setpoint's time_from_start [s]
constexpr double kStopTime = 0.2;   // the stop after it [s]
// The local model's joint velocity limits are this fraction of the remote arm's: motions planned
// here keep a reserve, so that the remote arm can catch up with a streamed setpoint that arrives
// late (the remote bridge refuses a point it could only reach above its limits). With the 50 ms
// horizon, a setpoint up to 12 ms late is still reachable.
constexpr double kVelocityReserve = 0.8;
constexpr std::size_t kLatencies = 4096;

constexpr double kIoWakeup = 0.01;   // the longest sleep of the I/O threads [s]

builtin_interfaces_msg_dds__Duration_ duration(double s) {
  builtin_interfaces_msg_dds__Duration_ d{};
  d.sec = static_cast<int32_t>(std::floor(s));
  d.nanosec = static_cast<uint32_t>(std::lround((s - std::floor(s)) * 1e9));
  if (d.nanosec >= 1000000000u) {
    ++d.sec;
    d.nanosec -= 1000000000u;
  }
  return d;
}

}  // namespace

struct RemoteManipulator::Impl {
  RemoteManipulatorOptions options;
  std::string nameSpace, object;  // the remote bridge's namespace and the arm's ROS name
  std::string label;              // "NS/OBJECT" for messages
  std::string badSample;          // the first joint_states sample refused (a value not finite), or empty
  bool leased = false;  // the DDS domain (ros2detail::acquireDomain())
  dds_entity_t participant = 0;
  dds_entity_t jointStates = 0, state = 0, description = 0, trajectory = 0;
  std::unique_ptr<ManipulatorModel> model;
  int n = 0;
  std::vector<std::string> jointNames;  // `<object>_<joint>`, as in joint_states

  // The state received by the reader thread (other threads read it under the lock).
  mutable std::mutex stateMutex;
  JointVector q, qd, tau;
  bool remotePower = false;
  std::string remoteState;
  std::uint64_t refusedBaseline = 0;
  bool haveBaseline = false;
  // The reader thread's own.
  std::chrono::steady_clock::time_point lastReceipt;
  double lastStamp = -1;
  std::array<int, kMaxJoints> column{};  // model joint -> joint_states column

  // Between the loop and the I/O threads, without a lock or a wait on the loop's side.
  struct Joints {
    double q[kMaxJoints];
  };
  struct Stream {  // the next trajectory to write: its two points
    std::uint64_t sequence;
    double positions[2][kMaxJoints], velocities[2][kMaxJoints];
  };
  TripleBuffer<Joints> received;  // reader thread -> loop (its only reader)
  TripleBuffer<Stream> stream;    // loop -> writer thread (its only reader)
  TripleBuffer<Joints> desired;   // loop -> any thread: the cycle's setpoint position
  std::thread reader, writer;
  std::atomic<bool> stopIo{false};
  dds_entity_t waitset = 0, wake = 0;  // the reader's waitset and the guard condition that ends its wait

  // The loop's own.
  JointVector qLoop, hold;
  Setpoint setpoint;
  TrajectoryGenerator* activeGenerator = nullptr;
  Stream next{};  // the trajectory this cycle hands to the writer (its sequence counts the cycles that wrote one)

  std::atomic<TrajectoryGenerator*> generator{nullptr};
  std::atomic<const void*> executing{nullptr};
  std::atomic<bool> holdHere{false}, streaming{true}, faulted{false}, remotePowerFlag{false};

  // Statistics (the loop writes under statsMutex).
  mutable std::mutex statsMutex;
  std::array<double, kLatencies> latencies{};
  std::size_t latencyCount = 0;
  std::uint64_t samples = 0, gaps = 0, missing = 0, sent = 0, failures = 0, refusals = 0;
  double period = 0;

  // The message written every cycle: buffers made once.
  std::vector<char*> names;
  std::array<std::array<double, kMaxJoints>, 2> positions{}, velocities{};
  std::array<trajectory_msgs_msg_dds__JointTrajectoryPoint_, 2> points{};
  trajectory_msgs_msg_dds__JointTrajectory_ message{};

  ~Impl() {
    stopThreads();
    if (participant > 0) dds_delete(participant);
    if (leased) ros2detail::releaseDomain(options.domain);
  }

  void stopThreads() {
    stopIo = true;
    if (wake > 0) dds_set_guardcondition(wake, true);
    if (reader.joinable()) reader.join();
    if (writer.joinable()) writer.join();
  }

  dds_entity_t endpoint(const dds_topic_descriptor_t& desc, const std::string& topic, bool transientLocal, bool isReader) {
    const std::string full = Ros2Bridge::ddsTopicName(nameSpace, topic);
    const dds_entity_t t = dds_create_topic(participant, &desc, full.c_str(), nullptr, nullptr);
    if (t < 0) throw std::runtime_error("RemoteManipulator: cannot create topic " + full + ": " + ddsError(t));
    dds_qos_t* qos = ros2detail::rosQos(transientLocal);
    const dds_entity_t e = isReader ? dds_create_reader(participant, t, qos, nullptr) : dds_create_writer(participant, t, qos, nullptr);
    dds_delete_qos(qos);
    if (e < 0) throw std::runtime_error("RemoteManipulator: cannot create an endpoint on " + full + ": " + ddsError(e));
    return e;
  }

  // Takes every joint_states sample received; true if one of the arm's came.
  bool takeJointStates();
  // Takes every `<object>/state` sample; returns a fault message ("" if none).
  std::string takeStates();
  // The reader thread: waits for samples, takes them, hands the joints to the loop and raises
  // the faults it finds (through `fault`, once).
  void read(const std::function<void(const std::string&)>& fault);
  // The writer thread: after each cycle of a loop, writes the loop's new trajectory, if any.
  void write();
};

bool RemoteManipulator::Impl::takeJointStates() {
  bool got = false;
  for (;;) {
    void* loan[1] = {nullptr};
    dds_sample_info_t info[1];
    const dds_return_t count = dds_take(jointStates, loan, info, 1, 1);
    if (count <= 0) break;
    const auto& js = *static_cast<const sensor_msgs_msg_dds__JointState_*>(loan[0]);
    bool ours = info[0].valid_data && js.name._length >= static_cast<uint32_t>(n) && js.position._length == js.name._length;
    if (ours) {  // the arm's sample: each of its joints named in it
      for (int i = 0; i < n && ours; ++i) {
        int c = -1;
        for (uint32_t k = 0; k < js.name._length; ++k)
          if (js.name._buffer[k] != nullptr && jointNames[static_cast<std::size_t>(i)] == js.name._buffer[k]) c = static_cast<int>(k);
        ours = c >= 0;
        column[static_cast<std::size_t>(i)] = c;
      }
    }
    // A position that is not a number is no state of an arm: the sample is refused (not stored)
    // and named once; the reader thread makes it a fault, connect() an error. (A velocity or
    // effort that is not a number is one the publisher does not have, as ros2_control's
    // joint_state_broadcaster writes it: taken as absent, 0, like a missing array.)
    for (int i = 0; i < n && ours; ++i) {
      const double q = js.position._buffer[static_cast<uint32_t>(column[static_cast<std::size_t>(i)])];
      if (std::isfinite(q)) continue;
      if (badSample.empty()) {
        char text[320];
        std::snprintf(text, sizeof text, "the remote arm %.120s sent joint_states with position of joint '%.60s' %g: not a finite number",
                      label.c_str(), jointNames[static_cast<std::size_t>(i)].c_str(), q);
        badSample = text;
      }
      ours = false;
    }
    if (ours) {
      const double receipt = 1e-9 * static_cast<double>(ros2detail::wallNanoseconds());
      const double stamp = js.header.stamp.sec + 1e-9 * js.header.stamp.nanosec;
      {
        std::lock_guard<std::mutex> lock(stateMutex);
        for (int i = 0; i < n; ++i) {
          const auto c = static_cast<uint32_t>(column[static_cast<std::size_t>(i)]);
          q(i) = js.position._buffer[c];
          qd(i) = js.velocity._length == js.name._length && std::isfinite(js.velocity._buffer[c]) ? js.velocity._buffer[c] : 0.0;
          tau(i) = js.effort._length == js.name._length && std::isfinite(js.effort._buffer[c]) ? js.effort._buffer[c] : 0.0;
        }
      }
      Joints j{};
      for (int i = 0; i < n; ++i) j.q[i] = js.position._buffer[static_cast<uint32_t>(column[static_cast<std::size_t>(i)])];
      received.write(j);
      std::lock_guard<std::mutex> lock(statsMutex);
      ++samples;
      latencies[latencyCount++ % kLatencies] = receipt - stamp;
      if (lastStamp >= 0 && stamp > lastStamp) {
        const double dt = stamp - lastStamp;
        if (period == 0 || dt < period) period = dt;
        if (dt > 1.5 * period) {
          ++gaps;
          missing += static_cast<std::uint64_t>(std::max(0.0, std::round(dt / period) - 1));
        }
      }
      lastStamp = stamp;
      got = true;
    }
    dds_return_loan(jointStates, loan, count);
  }
  if (got) lastReceipt = std::chrono::steady_clock::now();
  return got;
}

std::string RemoteManipulator::Impl::takeStates() {
  std::string fault;
  for (;;) {
    void* loan[1] = {nullptr};
    dds_sample_info_t info[1];
    const dds_return_t count = dds_take(state, loan, info, 1, 1);
    if (count <= 0) break;
    const auto& s = *static_cast<const std_msgs_msg_dds__String_*>(loan[0]);
    if (info[0].valid_data && s.data != nullptr) {
      const std::string text = s.data;
      const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
      if (j.is_object()) {
        const bool power = j.value("power", false);
        const auto refused = j.value("trajectoriesRefused", std::uint64_t{0});
        {
          std::lock_guard<std::mutex> lock(stateMutex);
          remoteState = text;
          remotePower = power;
          if (!haveBaseline) {
            refusedBaseline = refused;
            haveBaseline = true;
          }
        }
        remotePowerFlag = power;
        if (j.value("errorCode", 0) != 0)
          fault = "the remote arm " + label + " reports an error: " + j.value("error", std::string());
        else if (j.value("shutdown", false))
          fault = "the remote arm " + label + " is shutting down: " + j.value("shutdownReason", std::string());
        else if (refused > refusedBaseline) {
          {
            std::lock_guard<std::mutex> lock(statsMutex);
            refusals = refused - refusedBaseline;
          }
          fault = "the remote arm " + label + " refused the trajectory: " + j.value("trajectory", std::string());
        }
      }
    }
    dds_return_loan(state, loan, count);
  }
  return fault;
}

void RemoteManipulator::Impl::read(const std::function<void(const std::string&)>& fault) {
  const auto timeout = std::chrono::duration<double>(options.timeout);
  while (!stopIo.load()) {
    dds_waitset_wait(waitset, nullptr, 0, DDS_SECS(kIoWakeup));
    if (stopIo.load()) break;
    takeJointStates();
    std::string message;
    try {
      message = takeStates();
    } catch (const std::exception& e) {
      message = std::string("the remote arm's state: ") + e.what();
    }
    if (message.empty()) message = badSample;
    if (faulted.load()) continue;  // raiseFault() takes the first fault only
    if (message.empty() && std::chrono::steady_clock::now() - lastReceipt > timeout) {
      char text[160];
      std::snprintf(text, sizeof text, "no joint_states from %.60s for %.2f s: the remote arm or its process is gone",
                    label.c_str(), options.timeout);
      message = text;
    }
    if (!message.empty()) fault(message);
  }
}

void RemoteManipulator::Impl::write() {
  std::uint64_t seen = internal::cyclesEnded(), written = 0;
  Stream s{};
  while (!stopIo.load()) {
    seen = internal::waitForCycleEnd(seen, kIoWakeup);
    if (!stream.readAsOnlyReader(s) || s.sequence == written) continue;
    written = s.sequence;
    for (std::size_t k = 0; k < 2; ++k)
      for (int i = 0; i < n; ++i) {
        positions[k][static_cast<std::size_t>(i)] = s.positions[k][i];
        velocities[k][static_cast<std::size_t>(i)] = s.velocities[k][i];
      }
    const bool ok = dds_write(trajectory, &message) >= 0;
    std::lock_guard<std::mutex> lock(statsMutex);
    ++(ok ? sent : failures);
  }
}

RemoteManipulator::RemoteManipulator(const std::string& name)
    : Manipulator(ClassSection(name, "RemoteManipulator")), ControlProgram(name.empty() ? "remote" : name), impl_(std::make_unique<Impl>()) {
  setProgramName(getName());
  RemoteManipulatorOptions& o = impl_->options;
  const ConfigSection* section = configSection();
  if (section == nullptr)
    throw std::invalid_argument("RemoteManipulator '" + getName() + "': no rp.cfg section [" + getName() +
                                "] with the setting 'remote NS/OBJECT'");
  const ConfigSetting* remote = section->find("remote");
  if (remote == nullptr)
    throw ConfigError(section->fileName(), section->line(),
                      "RemoteManipulator needs the setting 'remote NS/OBJECT' (the remote Ros2Bridge's namespace and the arm's name)");
  if (remote->values.size() != 1) throw section->errorAt(*remote, "setting 'remote' takes one word, NS/OBJECT");
  o.remote = remote->values[0];
  if (const ConfigSetting* s = section->find("domain")) {
    const double d = section->getNumbers("domain").at(0);
    if (!(d >= 0 && d <= ros2detail::kMaxDomain) || d != std::floor(d))
      throw section->errorAt(*s, "setting 'domain' must be a whole number 0 .. " + std::to_string(ros2detail::kMaxDomain));
    o.domain = static_cast<int>(d);
  }
  if (const ConfigSetting* s = section->find("interfaces")) {
    if (s->values.empty()) throw section->errorAt(*s, "setting 'interfaces' needs at least one interface");
    o.interfaces = s->values;
  }
  if (section->find("rate")) o.rate = section->getNumbers("rate").at(0);
  if (section->find("timeout")) o.timeout = section->getNumbers("timeout").at(0);
  if (section->find("connectTimeout")) o.connectTimeout = section->getNumbers("connectTimeout").at(0);
  if (const std::string why = checkOptions(o); !why.empty()) {
    for (const char* key : {"remote", "interfaces", "rate", "timeout", "connectTimeout"})
      if (why.rfind(key, 0) == 0)
        if (const ConfigSetting* s = section->find(key)) throw section->errorAt(*s, "setting " + why);
    throw ConfigError(section->fileName(), section->line(), why);
  }
  try {
    connect();
  } catch (const std::exception& e) {
    throw section->errorAt(*remote, std::string("setting 'remote ") + o.remote + "': " + e.what());
  }
  startControlLoop();
}

RemoteManipulator::RemoteManipulator(const std::string& name, const RemoteManipulatorOptions& options)
    : Manipulator(name), ControlProgram(name.empty() ? "remote" : name), impl_(std::make_unique<Impl>()) {
  setProgramName(getName());
  if (const std::string why = checkOptions(options); !why.empty()) throw std::invalid_argument("RemoteManipulator: " + why);
  impl_->options = options;
  connect();
  startControlLoop();
}

RemoteManipulator::~RemoteManipulator() {
  stopControlLoop();
  impl_->stopThreads();
  const RemoteManipulatorStatistics s = getStatistics();
  if (s.gaps > 0 || s.writeFailures > 0)
    std::fprintf(stderr,
                 "RemoteManipulator '%s': %llu joint_states samples from %s, %llu gaps (about %llu lost), latency median %.3f ms, "
                 "p99 %.3f ms; %llu trajectories sent, %llu write failures\n",
                 getName().c_str(), static_cast<unsigned long long>(s.samples), impl_->label.c_str(),
                 static_cast<unsigned long long>(s.gaps), static_cast<unsigned long long>(s.missing), 1e3 * s.latencyMedian,
                 1e3 * s.latencyP99, static_cast<unsigned long long>(s.trajectoriesSent),
                 static_cast<unsigned long long>(s.writeFailures));
  if (TrajectoryGenerator* g = impl_->generator.exchange(nullptr)) {
    disconnectGenerator(*g);
    g->detach(*this);
  }
  impl_.reset();
}

std::string RemoteManipulator::checkOptions(const RemoteManipulatorOptions& o) {
  if (std::string why = ros2detail::checkRemote(o.remote, o.domain, o.interfaces); !why.empty()) return why;
  if (!(o.rate >= 10 && o.rate <= 500)) return "rate must be 10 .. 500 Hz";
  if (!(o.timeout >= 0.05 && o.timeout <= 60)) return "timeout must be 0.05 .. 60 s";
  if (!(o.connectTimeout >= 0.1 && o.connectTimeout <= 600)) return "connectTimeout must be 0.1 .. 600 s";
  return "";
}

void RemoteManipulator::declareSettings(SettingSchema& schema) {
  RoboticObject::declareSettings(schema);
  schema.addWord("remote", "required: the remote arm, the remote Ros2Bridge's namespace / the arm's object name, e.g. cell1/puma");
  schema.addInteger("domain", "DDS domain id (ROS_DOMAIN_ID) of the remote bridge", 0, ros2detail::kMaxDomain);
  ros2detail::addInterfacesSetting(schema);
  schema.addNumbers("rate", 1, "Hz", "setpoints streamed to the remote arm per second", 10, 500);
  schema.addNumbers("timeout", 1, "s", "silence of the remote arm's joint_states that is a fault", 0.05, 60);
  schema.addNumbers("connectTimeout", 1, "s", "longest wait for the remote arm at construction", 0.1, 600);
  schema.setDefault("domain", "0");
  schema.setDefault("interfaces", "lo");
  schema.setDefault("rate", "100");
  schema.setDefault("timeout", "0.5");
  schema.setDefault("connectTimeout", "10");
}

void RemoteManipulator::connect() {
  Impl& d = *impl_;
  const RemoteManipulatorOptions& o = d.options;
  const ros2detail::RemoteArm arm = ros2detail::splitRemote(o.remote);
  d.nameSpace = arm.nameSpace;
  d.object = arm.object;
  d.label = arm.label;
  ros2detail::acquireDomain(o.domain, Ros2Bridge::cycloneConfig(o.interfaces), "RemoteManipulator", joined(o.interfaces));
  d.leased = true;
  d.participant = dds_create_participant(static_cast<dds_domainid_t>(o.domain), nullptr, nullptr);
  if (d.participant < 0)
    throw std::runtime_error("cannot join DDS domain " + std::to_string(o.domain) + ": " + ddsError(d.participant));
  d.description = d.endpoint(std_msgs_msg_dds__String__desc, d.object + "/robot_description", true, true);
  d.state = d.endpoint(std_msgs_msg_dds__String__desc, d.object + "/state", false, true);
  d.jointStates = d.endpoint(sensor_msgs_msg_dds__JointState__desc, "joint_states", false, true);
  d.trajectory = d.endpoint(trajectory_msgs_msg_dds__JointTrajectory__desc, d.object + "/joint_trajectory", false, false);

  // The description (transient-local: the bridge's last sample comes on discovery).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.connectTimeout);
  std::string urdf;
  while (urdf.empty()) {
    void* loan[1] = {nullptr};
    dds_sample_info_t info[1];
    const dds_return_t count = dds_take(d.description, loan, info, 1, 1);
    if (count > 0) {
      const auto& s = *static_cast<const std_msgs_msg_dds__String_*>(loan[0]);
      if (info[0].valid_data && s.data != nullptr) urdf = s.data;
      dds_return_loan(d.description, loan, count);
      continue;
    }
    if (std::chrono::steady_clock::now() > deadline)
      throw std::runtime_error("no robot description on " + Ros2Bridge::ddsTopicName(d.nameSpace, d.object + "/robot_description") +
                               " (domain " + std::to_string(o.domain) + ", interfaces " + joined(o.interfaces) + ") within " +
                               std::to_string(o.connectTimeout) + " s: is the remote arm's process running with a Ros2Bridge?");
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  UrdfOptions urdfOptions;
  urdfOptions.velocityLimitScale = kVelocityReserve;
  d.model = loadUrdfString(urdf, urdfOptions, Ros2Bridge::ddsTopicName(d.nameSpace, d.object + "/robot_description"));
  d.n = d.model->getNumberOfJoints();
  const std::string prefix = d.object + "_";
  for (int i = 0; i < d.n; ++i) {
    const std::string j = d.model->getJointName(i);
    d.jointNames.push_back(j.rfind(prefix, 0) == 0 ? j : prefix + j);
  }
  for (JointVector* v : {&d.q, &d.qd, &d.tau, &d.qLoop, &d.hold}) v->setZero(d.n);
  for (JointVector* v : {&d.setpoint.position, &d.setpoint.velocity, &d.setpoint.acceleration}) v->setZero(d.n);

  // The first joint state and state of the arm.
  bool joints = false;
  while (!joints || !d.haveBaseline) {
    joints = d.takeJointStates() || joints;
    if (!d.badSample.empty()) throw std::runtime_error(d.badSample);
    const std::string fault = d.takeStates();
    if (!fault.empty()) throw std::runtime_error(fault);
    if (joints && d.haveBaseline) break;
    if (std::chrono::steady_clock::now() > deadline)
      throw std::runtime_error(std::string("no ") + (joints ? "state" : "joint_states") + " of the arm on " +
                               Ros2Bridge::ddsTopicName(d.nameSpace, joints ? d.object + "/state" : "joint_states") +
                               " within " + std::to_string(o.connectTimeout) + " s (its description came)");
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  d.qLoop = d.hold = d.setpoint.position = d.q;
  Impl::Joints desired{};
  for (int i = 0; i < d.n; ++i) desired.q[i] = d.q(i);
  d.desired.write(desired);

  // The message: names and the two points' buffers, made once.
  for (const std::string& name : d.jointNames) d.names.push_back(const_cast<char*>(name.c_str()));
  const auto dof = static_cast<uint32_t>(d.n);
  d.message.header.frame_id = const_cast<char*>("");
  d.message.joint_names._buffer = d.names.data();
  d.message.joint_names._length = d.message.joint_names._maximum = dof;
  for (std::size_t k = 0; k < 2; ++k) {
    auto& p = d.points[k];
    p.positions._buffer = d.positions[k].data();
    p.velocities._buffer = d.velocities[k].data();
    p.positions._length = p.positions._maximum = dof;
    p.velocities._length = p.velocities._maximum = dof;
    p.time_from_start = duration(k == 0 ? kHorizon : kHorizon + kStopTime);
  }
  d.message.points._buffer = d.points.data();
  d.message.points._length = d.message.points._maximum = 2;

  setRate(o.rate);
  setThreadMode(ThreadMode::Own);

  // The I/O threads: DDS is theirs from here on, the loop never waits for it.
  d.waitset = dds_create_waitset(d.participant);
  d.wake = dds_create_guardcondition(d.participant);
  if (d.waitset < 0 || d.wake < 0) throw std::runtime_error("RemoteManipulator: cannot create a DDS waitset");
  for (const dds_entity_t r : {d.jointStates, d.state}) {
    const dds_entity_t c = dds_create_readcondition(r, DDS_ANY_STATE);
    if (c < 0 || dds_waitset_attach(d.waitset, c, 0) < 0)
      throw std::runtime_error("RemoteManipulator: cannot wait for samples: " + ddsError(c));
  }
  if (dds_waitset_attach(d.waitset, d.wake, 0) < 0) throw std::runtime_error("RemoteManipulator: cannot wait for samples");
  d.reader = std::thread([this] { impl_->read([this](const std::string& fault) { raiseFault(fault); }); });
  d.writer = std::thread([this] { impl_->write(); });
}

void RemoteManipulator::raiseFault(const std::string& fault) {
  if (impl_->faulted.exchange(true)) return;
  const std::string message = "RemoteManipulator '" + getName() + "': " + fault;
  setError(1, message.c_str());
  ObjectManager::requestSystemShutdown(message.c_str());
}

void RemoteManipulator::control() {
  Impl& d = *impl_;
  // The joints the reader thread took last (no DDS call, lock or allocation in the cycle).
  Impl::Joints received;
  if (d.received.readAsOnlyReader(received))
    for (int i = 0; i < d.n; ++i) d.qLoop(i) = received.q[i];

  TrajectoryGenerator* g = d.generator.load(std::memory_order_acquire);
  const bool changes = g != d.activeGenerator;
  d.activeGenerator = g;
  const bool holdRequested = d.holdHere.exchange(false);
  const bool on = d.streaming.load() && !d.faulted.load() && d.remotePowerFlag.load() && !ObjectManager::isShutdownRequested();
  if (!on || changes || holdRequested) d.hold = d.qLoop;
  d.setpoint.position = d.hold;
  // The cycle's setpoint position for other threads (getDesiredJointPosition()), however the cycle ends.
  struct PublishSetpoint {
    Impl& d;
    ~PublishSetpoint() {
      Impl::Joints desired{};
      for (int i = 0; i < d.n; ++i) desired.q[i] = d.setpoint.position(i);
      d.desired.write(desired);
    }
  } publishSetpoint{d};
  d.setpoint.velocity.setZero();
  d.setpoint.acceleration.setZero();
  if (g == nullptr || !on) return;
  d.executing.store(g, std::memory_order_seq_cst);
  const char* bad = nullptr;
  std::string thrown;
  try {
    if (d.generator.load(std::memory_order_seq_cst) == g && g->getCurrentSetpoint(getTime(), d.setpoint)) {
      if (!(d.setpoint.position.allFinite() && d.setpoint.velocity.allFinite()))
        bad = "the trajectory generator gave a setpoint that is not a number";
      else
        d.hold = d.setpoint.position;
    }
  } catch (const std::exception& e) {
    thrown = std::string("the trajectory generator threw: ") + e.what();
    bad = thrown.c_str();
  }
  d.executing.store(nullptr, std::memory_order_release);
  if (bad != nullptr) {
    raiseFault(bad);
    return;
  }
  // The trajectory for the writer thread: the setpoint at kHorizon, then the stop from there at
  // constant deceleration (a cubic with these ends is exactly that) kStopTime later.
  Impl::Stream& out = d.next;
  ++out.sequence;
  const JointVector& qmin = d.model->getPositionMin();
  const JointVector& qmax = d.model->getPositionMax();
  for (int i = 0; i < d.n; ++i) {
    const double p = d.setpoint.position(i), v = d.setpoint.velocity.size() == d.n ? d.setpoint.velocity(i) : 0.0;
    out.positions[0][i] = p;
    out.velocities[0][i] = v;
    out.positions[1][i] = std::clamp(p + v * kStopTime / 2, qmin(i), qmax(i));
    out.velocities[1][i] = 0;
  }
  d.stream.write(out);
}

const RemoteManipulatorOptions& RemoteManipulator::getOptions() const noexcept { return impl_->options; }

RemoteManipulatorStatistics RemoteManipulator::getStatistics() const {
  const Impl& d = *impl_;
  RemoteManipulatorStatistics s;
  std::vector<double> l;
  {
    std::lock_guard<std::mutex> lock(d.statsMutex);
    s.samples = d.samples;
    s.gaps = d.gaps;
    s.missing = d.missing;
    s.period = d.period;
    s.trajectoriesSent = d.sent;
    s.writeFailures = d.failures;
    s.remoteRefusals = d.refusals;
    l.assign(d.latencies.begin(), d.latencies.begin() + static_cast<std::ptrdiff_t>(std::min(d.latencyCount, kLatencies)));
  }
  if (!l.empty()) {
    std::sort(l.begin(), l.end());
    s.latencyMedian = l[l.size() / 2];
    s.latencyP99 = l[std::min(l.size() - 1, l.size() * 99 / 100)];
    s.latencyMax = l.back();
  }
  return s;
}

std::string RemoteManipulator::getRemoteState() const {
  std::lock_guard<std::mutex> lock(impl_->stateMutex);
  return impl_->remoteState;
}

const ManipulatorModel& RemoteManipulator::getModel() const { return *impl_->model; }

double RemoteManipulator::getServoPeriod() const { return 1.0 / impl_->options.rate; }

JointVector RemoteManipulator::getJointPosition() const {
  std::lock_guard<std::mutex> lock(impl_->stateMutex);
  return impl_->q;
}

JointVector RemoteManipulator::getJointVelocity() const {
  std::lock_guard<std::mutex> lock(impl_->stateMutex);
  return impl_->qd;
}

const Setpoint& RemoteManipulator::getSetpoint() const { return impl_->setpoint; }

JointVector RemoteManipulator::getDesiredJointPosition() const {
  Impl::Joints desired{};
  impl_->desired.read(desired);
  JointVector q(impl_->n);
  for (int i = 0; i < impl_->n; ++i) q(i) = desired.q[i];
  return q;
}

JointVector RemoteManipulator::getControlOutput() const {
  std::lock_guard<std::mutex> lock(impl_->stateMutex);
  return impl_->tau;
}

void RemoteManipulator::setControlOutput(const Eigen::Ref<const Eigen::VectorXd>& torque) {
  (void)torque;
  throw std::logic_error("RemoteManipulator '" + getName() + "': the torques of a remote arm are its own process's");
}

void RemoteManipulator::enableArmPower() {
  if (impl_->faulted) throw std::runtime_error("RemoteManipulator '" + getName() + "': " + getErrorStatus().message);
  if (!impl_->remotePowerFlag)
    throw std::runtime_error("RemoteManipulator '" + getName() + "': the remote arm " + impl_->label +
                             " reports its power off (switch it on in its own process)");
  if (!impl_->streaming.exchange(true)) impl_->holdHere = true;
}

void RemoteManipulator::disableArmPower() { impl_->streaming = false; }

bool RemoteManipulator::isArmPowerOn() const { return impl_->streaming && impl_->remotePowerFlag && !impl_->faulted; }

Transform RemoteManipulator::getEndEffectorTransform() const {
  ManipulatorData data(*impl_->model);
  return forwardKinematics(*impl_->model, data, getJointPosition());
}

void RemoteManipulator::endEffectorForceToJointTorque(const Eigen::Ref<const Eigen::VectorXd>& q,
                                                      const Eigen::Ref<const Eigen::VectorXd>& force,
                                                      Eigen::Ref<Eigen::VectorXd> torque) const {
  ManipulatorData data(*impl_->model);
  const JointVector qv = q;
  rp::endEffectorForceToJointTorque(*impl_->model, data, qv, force, torque, ReferenceFrame::Base);
}

void RemoteManipulator::setTrajectoryGenerator(TrajectoryGenerator& generator) {
  generator.attach(*this);
  connectGenerator(generator);
  TrajectoryGenerator* old = impl_->generator.exchange(&generator);
  if (old != nullptr && old != &generator) {
    while (isRunning() && impl_->executing.load() == old) std::this_thread::yield();
    disconnectGenerator(*old);
    old->detach(*this);
  }
}

void RemoteManipulator::clearTrajectoryGenerator() {
  impl_->holdHere = true;
  TrajectoryGenerator* old = impl_->generator.exchange(nullptr);
  if (old != nullptr) {
    while (isRunning() && impl_->executing.load() == old) std::this_thread::yield();
    disconnectGenerator(*old);
    old->detach(*this);
  }
}

TrajectoryGenerator* RemoteManipulator::getTrajectoryGenerator() const { return impl_->generator.load(); }

void RemoteManipulator::releaseTrajectoryGenerator(TrajectoryGenerator& generator) {
  TrajectoryGenerator* expected = &generator;
  if (impl_->generator.compare_exchange_strong(expected, nullptr)) impl_->holdHere = true;
  while (isRunning() && impl_->executing.load() == &generator) std::this_thread::yield();
  disconnectGenerator(generator);
}

void RemoteManipulator::setServoControl(ServoControl& control) {
  (void)control;
  throw std::logic_error("RemoteManipulator '" + getName() + "': the servo control of a remote arm runs in its own process");
}

ServoControl& RemoteManipulator::getServoControl() const {
  throw std::logic_error("RemoteManipulator '" + getName() + "': the servo control of a remote arm runs in its own process");
}

void RemoteManipulator::releaseServoControl(ServoControl& control) { (void)control; }

void RemoteManipulator::setGravityCompensationOn() {
  throw std::logic_error("RemoteManipulator '" + getName() + "': gravity compensation is the remote arm's process's");
}

void RemoteManipulator::setGravityCompensationOff() { setGravityCompensationOn(); }

bool RemoteManipulator::isGravityCompensationOn() const { return true; }

void RemoteManipulator::setZeroGravityModeOn() {
  throw std::logic_error("RemoteManipulator '" + getName() + "': zero-gravity mode is the remote arm's process's");
}

void RemoteManipulator::setZeroGravityModeOff() {}

bool RemoteManipulator::isZeroGravityModeOn() const { return false; }

void RemoteManipulator::applyExternalWrench(const Vector<6>& wrench) {
  (void)wrench;
  throw std::logic_error("RemoteManipulator '" + getName() + "': external wrenches act on the remote arm's own simulation");
}

void RemoteManipulator::applyExternalWrench(int link, const Vector<3>& point, const Vector<6>& wrench) {
  (void)link;
  (void)point;
  applyExternalWrench(wrench);
}

}  // namespace rp

RP_REGISTER_CLASS_AS(rp::RemoteManipulator, "RemoteManipulator");
