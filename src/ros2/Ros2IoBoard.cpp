#include "rp/ros2/Ros2IoBoard.hpp"

#include <dds/dds.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <thread>

#include <nlohmann/json.hpp>

#include "../rt/CycleSignal.hpp"
#include "Ros2Common.hpp"
#include "rp/io/IoException.hpp"
#include "rp/model/ManipulatorModel.hpp"
#include "rp/ros2/Ros2Bridge.hpp"
#include "rp/rt/TripleBuffer.hpp"
#include "sensor_msgs.h"
#include "std_msgs.h"

namespace rp {

namespace {

using ros2detail::ddsError;
using ros2detail::steadyNanoseconds;

constexpr double kVoltLimit = 10.0;  // the analog outputs' range, +-10 V, as an amplifier's input
constexpr double kWriterWakeup = 0.01;  // the longest sleep of the writer thread [s]
constexpr std::uint64_t kRateSamples = 20;  // samples that measure the remote rate at connection
constexpr double kLongestSampleInterval = 0.005;  // [s] the slowest joint_states a torque loop takes
constexpr std::int64_t kLongestStampStep = 1000000000;  // [ns] a longer step between stamps is a clock step
constexpr double kStaleSample = 0.01;  // [s] torques computed from an older sample are not sent
constexpr std::int64_t kOffsetSlew = 1000;  // [ns] the most the stamps' offset to this clock moves in a sample
constexpr int kMaxWriteFailures = 10;             // effort commands that fail in a row before it is a fault

// A bridge's refusal ("refused: why") without its prefix.
std::string withoutRefusedPrefix(std::string why) {
  if (why.rfind("refused: ", 0) == 0) why.erase(0, 9);
  return why;
}

std::string seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%g s", s);
  return text;
}

}  // namespace

struct Ros2IoBoard::Impl {
  Ros2IoBoardOptions options;
  std::string nameSpace, object, label;  // label: "NS/OBJECT" for messages
  int n = 0;
  std::vector<std::string> jointNames;  // `<object>_<joint>`, as in joint_states
  std::vector<double> newtonMetresPerVolt;
  bool leased = false;  // the DDS domain (ros2detail::acquireDomain())
  dds_entity_t participant = 0, jointStates = 0, state = 0, effort = 0;

  // Cyclone's receive thread (the listeners) -> the servo thread: a sequence lock. sampleTime is
  // the stored sample's time on CLOCK_MONOTONIC (its stamp plus stampToLocal) [ns], -1 while one
  // is stored, 0 before the first.
  std::atomic<std::int64_t> sampleTime{0};
  std::int64_t stampToLocal = 0;  // the listener's own: this clock minus the stamps [ns]
  std::int64_t lowestSeen = 0;    // the listener's own: the least (receipt - stamp) of late [ns]
  std::array<std::atomic<std::int64_t>, kMaxJoints> counts{};
  std::atomic<std::int64_t> lastReceipt{0};  // steady clock [ns] of the last sample of the arm
  std::int64_t lastStamp = 0;                // the listener's own: the last sample time stored
  std::int64_t lastRemoteStamp = 0;          // the listener's own: the last sample's stamp
  std::int64_t goodStep = 1000000;           // the listener's own: the last plausible stamp step [ns]
  std::atomic<std::int64_t> firstStamp{0}, latestStamp{0};  // of the arm's samples, for the connection's rate check
  std::array<int, kMaxJoints> column{};      // the listener's own: model joint -> joint_states column
  std::atomic<bool> haveState{false}, remotePower{false};
  // A fault of the remote arm, the first one only: 0 none, 1 its text being written (by the thread
  // that claimed it), 2 written.
  std::atomic<int> remoteFault{0};
  char faultText[300] = {};
  std::uint64_t refusedBaseline = 0;  // the listener's own: the remote effortsRefused when connected
  bool haveBaseline = false;

  // The servo thread's outputs, handed to the writer thread after digital output 0.
  struct Command {
    std::uint64_t sequence;
    bool power;
    double tau[kMaxJoints];
  };
  Command next{};
  bool enabled = false;  // digital output 0 as last written (next.power: and the sample fresh)
  TripleBuffer<Command> commands;
  std::thread writer;
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> samples{0}, sent{0}, failures{0};

  // The message the writer sends (its buffer made once).
  std::vector<double> data;
  std_msgs_msg_dds__Float64MultiArray_ message{};

  ~Impl() {
    stop = true;
    if (writer.joinable()) writer.join();
    if (participant > 0) dds_delete(participant);  // waits for listeners under way
    if (leased) ros2detail::releaseDomain(options.domain);
  }

  dds_entity_t endpoint(const dds_topic_descriptor_t& desc, const std::string& topic, bool isReader, dds_listener_t* listener) {
    const std::string full = Ros2Bridge::ddsTopicName(nameSpace, topic);
    const dds_entity_t t = dds_create_topic(participant, &desc, full.c_str(), nullptr, nullptr);
    if (t < 0) throw IoException("Ros2IoBoard: cannot create topic " + full + ": " + ddsError(t));
    dds_qos_t* qos = ros2detail::rosQos(false);
    const dds_entity_t e = isReader ? dds_create_reader(participant, t, qos, listener) : dds_create_writer(participant, t, qos, nullptr);
    dds_delete_qos(qos);
    if (e < 0) throw IoException("Ros2IoBoard: cannot create an endpoint on " + full + ": " + ddsError(e));
    return e;
  }

  // Records the first fault (the listeners and the writer thread may find one at once).
  void setFault(const std::string& text) {
    int none = 0;
    if (!remoteFault.compare_exchange_strong(none, 1)) return;
    std::snprintf(faultText, sizeof faultText, "%s", text.c_str());
    remoteFault.store(2, std::memory_order_release);
  }
  bool faulted() const noexcept { return remoteFault.load(std::memory_order_acquire) == 2; }

  // Listener of joint_states (Cyclone's receive thread): stores the arm's samples.
  void takeJointStates() {
    ros2detail::takeEach<sensor_msgs_msg_dds__JointState_>(jointStates, [&](const sensor_msgs_msg_dds__JointState_& js, const dds_sample_info_t&) {
      bool ours = js.position._length == js.name._length;
      for (int i = 0; i < n && ours; ++i) {  // each of the arm's joints named in it
        int c = -1;
        for (uint32_t k = 0; k < js.name._length && c < 0; ++k)
          if (js.name._buffer[k] != nullptr && jointNames[static_cast<std::size_t>(i)] == js.name._buffer[k]) c = static_cast<int>(k);
        ours = c >= 0;
        column[static_cast<std::size_t>(i)] = c;
      }
      if (ours) {
        // The sample's time: the remote cycles' stamps, so that the velocity is differentiated over
        // the remote arm's own cycle times (receipt times carry the network's jitter). Where a stamp
        // does not follow on (the remote wall clock stepped back, or ahead by more than a second),
        // the step is the last good one: one remote cycle. A stamp that comes again is the same
        // sample again (an arm's hardware sample its server has not renewed yet): nothing new, so
        // the reader sees no new sample rather than joints standing still for a cycle (and, the
        // sample growing old, no torque is sent on it, and the silence becomes a fault).
        const std::int64_t remoteStamp = static_cast<std::int64_t>(js.header.stamp.sec) * 1000000000 + js.header.stamp.nanosec;
        std::int64_t step = remoteStamp - lastRemoteStamp;
        if (step == 0 && lastStamp != 0) return;
        if (step < 0 || step > kLongestStampStep)
          step = goodStep;
        else
          goodStep = step;
        lastRemoteStamp = remoteStamp;
        const std::int64_t stamp = lastStamp == 0 ? std::max<std::int64_t>(remoteStamp, 1) : lastStamp + step;
        // On this machine's CLOCK_MONOTONIC (IoBoard::inputSampleTime()): the stamp plus an offset
        // that follows the least delayed samples' receipt minus stamp (`lowestSeen`, which rises by
        // the slew a sample so that it follows a remote clock slower than this one). The offset
        // moves by at most kOffsetSlew (1 us) a sample, and less than half the step: a first
        // sample that came late and the clocks' different rates (parts per million) are taken out
        // while the steps stay the remote cycles' to 0.1 % of a 1 ms cycle, and never go back.
        const std::int64_t seen = steadyNanoseconds() - stamp;
        if (lastStamp == 0) {
          stampToLocal = lowestSeen = seen;
        } else if (samples.load(std::memory_order_relaxed) < kRateSamples) {
          stampToLocal = lowestSeen = std::min(lowestSeen, seen);  // connecting: no reader yet, no slew
        } else {
          lowestSeen = std::min(lowestSeen + kOffsetSlew, seen);
          const std::int64_t slew = std::min(kOffsetSlew, step / 2);
          stampToLocal += std::clamp(lowestSeen - stampToLocal, -slew, slew);
        }
        lastStamp = stamp;
        // The rate is measured from the second sample on: the first may be old (a sample the
        // remote published before this board joined, delivered late), and its gap to the next
        // is no remote cycle.
        if (samples.load(std::memory_order_relaxed) == 1) firstStamp.store(stamp);
        latestStamp.store(stamp);
        // A sequence lock without fences (ThreadSanitizer has none): the counts are stored with
        // release after the -1, and read with acquire before the second look at sampleTime.
        sampleTime.store(-1, std::memory_order_relaxed);
        for (int i = 0; i < n; ++i) {
          const double q = js.position._buffer[static_cast<uint32_t>(column[static_cast<std::size_t>(i)])];
          counts[static_cast<std::size_t>(i)].store(std::isfinite(q) ? std::llround(q * kCountsPerRadian) : 0,
                                                    std::memory_order_release);
          if (!std::isfinite(q)) setFault("the remote arm " + label + " sent a joint position that is not a number");
        }
        sampleTime.store(stamp + stampToLocal, std::memory_order_release);  // never 0 or -1
        lastReceipt.store(steadyNanoseconds(), std::memory_order_release);
        ++samples;
      }
    });
  }

  // Listener of `<object>/state` (Cyclone's receive thread): the remote arm's power and faults.
  void takeStates() {
    ros2detail::takeEach<std_msgs_msg_dds__String_>(state, [&](const std_msgs_msg_dds__String_& s, const dds_sample_info_t&) {
      if (s.data == nullptr) return;
      const nlohmann::json j = nlohmann::json::parse(s.data, nullptr, false);
      if (j.is_object()) {
        try {
          const auto refused = j.value("effortsRefused", std::uint64_t{0});
          if (!haveBaseline) {
            refusedBaseline = refused;
            haveBaseline = true;
          }
          remotePower.store(j.value("power", false));
          haveState.store(true, std::memory_order_release);
          if (j.value("errorCode", 0) != 0)
            setFault("the remote arm " + label + " reports an error: " + j.value("error", std::string()));
          else if (j.value("shutdown", false))
            setFault("the remote arm " + label + " is shutting down: " + j.value("shutdownReason", std::string()));
          else if (refused > refusedBaseline)
            setFault("the remote arm " + label + " refused the effort commands: " + withoutRefusedPrefix(j.value("effort", std::string())));
        } catch (const std::exception& e) {
          setFault("the remote arm " + label + "'s state: " + e.what());
        }
      }
    });
  }

  // The writer thread: after each cycle of a loop, the outputs it handed over, if new and on.
  void write() {
    std::uint64_t seen = internal::cyclesEnded(), written = 0;
    Command c{};
    bool on = false;  // the last command written drives the arm
    int failedInARow = 0;
    while (!stop.load()) {
      seen = internal::waitForCycleEnd(seen, kWriterWakeup);
      if (!commands.readAsOnlyReader(c) || c.sequence == written) continue;
      written = c.sequence;
      if (!c.power && !on) continue;  // amplifiers off: nothing is commanded (the remote bridge holds the arm)
      // Amplifiers going off: one empty command, on which the remote bridge holds the arm at once.
      message.data._length = c.power ? static_cast<uint32_t>(n) : 0;
      std::copy(c.tau, c.tau + n, data.begin());
      on = c.power;
      if (dds_write(effort, &message) >= 0) {
        ++sent;
        failedInARow = 0;
      } else {
        ++failures;
        if (++failedInARow == kMaxWriteFailures)
          setFault("the effort commands to the remote arm " + label + " cannot be written (" + std::to_string(kMaxWriteFailures) +
                   " failures in a row)");
      }
    }
    if (on) {  // the board goes (the program ends) while on: let go of the arm
      message.data._length = 0;
      (void)dds_write(effort, &message);
    }
  }
};

Ros2IoBoard::Ros2IoBoard(const Ros2IoBoardOptions& options, const std::vector<std::string>& jointNames,
                         const std::vector<double>& newtonMetresPerVolt)
    : impl_(std::make_unique<Impl>()) {
  if (const std::string why = checkOptions(options); !why.empty()) throw std::invalid_argument("Ros2IoBoard: " + why);
  if (jointNames.empty() || jointNames.size() > static_cast<std::size_t>(kMaxJoints) || newtonMetresPerVolt.size() != jointNames.size())
    throw std::invalid_argument("Ros2IoBoard: 1 .. 16 joint names and as many torques per volt");
  Impl& d = *impl_;
  d.options = options;
  const ros2detail::RemoteArm arm = ros2detail::splitRemote(options.remote);
  d.nameSpace = arm.nameSpace;
  d.object = arm.object;
  d.label = arm.label;
  d.n = static_cast<int>(jointNames.size());
  for (const std::string& j : jointNames) d.jointNames.push_back(d.object + "_" + j);
  d.newtonMetresPerVolt = newtonMetresPerVolt;

  try {
    ros2detail::acquireDomain(options.domain, Ros2Bridge::cycloneConfig(options.interfaces), "Ros2IoBoard",
                              ros2detail::joined(options.interfaces));
    d.leased = true;
  } catch (const std::exception& e) {
    throw IoException(e.what());
  }
  d.participant = dds_create_participant(static_cast<dds_domainid_t>(options.domain), nullptr, nullptr);
  if (d.participant < 0)
    throw IoException("Ros2IoBoard: cannot join DDS domain " + std::to_string(options.domain) + ": " + ddsError(d.participant));
  dds_listener_t* listener = dds_create_listener(&d);
  dds_lset_data_available(listener, [](dds_entity_t, void* arg) { static_cast<Impl*>(arg)->takeJointStates(); });
  d.jointStates = d.endpoint(sensor_msgs_msg_dds__JointState__desc, "joint_states", true, listener);
  dds_lset_data_available(listener, [](dds_entity_t, void* arg) { static_cast<Impl*>(arg)->takeStates(); });
  d.state = d.endpoint(std_msgs_msg_dds__String__desc, d.object + "/state", true, listener);
  dds_delete_listener(listener);
  d.effort = d.endpoint(std_msgs_msg_dds__Float64MultiArray__desc, d.object + "/effort_commands", false, nullptr);

  // The first joint_states and state of the arm.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(options.connectTimeout);
  while (d.sampleTime.load() <= 0 || !d.haveState.load()) {
    if (std::chrono::steady_clock::now() > deadline) {
      const bool joints = d.sampleTime.load() > 0;
      throw IoException("Ros2IoBoard: no " + std::string(joints ? "state" : "joint_states naming " + d.jointNames[0]) +
                        " of the remote arm on " +
                        Ros2Bridge::ddsTopicName(d.nameSpace, joints ? d.object + "/state" : "joint_states") + " (domain " +
                        std::to_string(options.domain) + ", interfaces " + ros2detail::joined(options.interfaces) + ") within " +
                        seconds(options.connectTimeout) + ": is the remote arm's process running with a Ros2Bridge?");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  // The remote bridge must publish every servo cycle (`rate servo`): a torque loop closed over
  // samples tens of milliseconds apart would be unstable. Measured over the first samples.
  while (d.samples.load() < kRateSamples && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const std::uint64_t counted = d.samples.load();
  const double interval = counted >= 3 ? 1e-9 * static_cast<double>(d.latestStamp.load() - d.firstStamp.load()) / static_cast<double>(counted - 2)
                                       : std::numeric_limits<double>::infinity();
  if (interval > kLongestSampleInterval) {
    char text[200];
    std::snprintf(text, sizeof text, "%.1f ms", 1e3 * interval);
    throw IoException("Ros2IoBoard: the remote arm " + d.label + "'s joint_states come every " + text +
                      ": an arm driven by torque needs them every servo cycle (rate servo in the remote Ros2Bridge's section)");
  }
  if (d.faulted()) throw IoException(std::string("Ros2IoBoard: ") + d.faultText);

  // The effort message, its buffer made once.
  d.data.assign(static_cast<std::size_t>(d.n), 0.0);
  d.message.data._buffer = d.data.data();
  d.message.data._length = d.message.data._maximum = static_cast<uint32_t>(d.n);
  d.writer = std::thread([this] {
    ros2detail::scheduleIoThread(impl_->options.priority, "Ros2IoBoard");
    impl_->write();
  });
}

Ros2IoBoard::~Ros2IoBoard() = default;

std::string Ros2IoBoard::checkOptions(const Ros2IoBoardOptions& o) {
  if (std::string why = ros2detail::checkRemote(o.remote, o.domain, o.interfaces); !why.empty()) return why;
  if (!(o.timeout >= 0.005 && o.timeout <= 60)) return "timeout must be 0.005 .. 60 s";
  if (!(o.connectTimeout >= 0.1 && o.connectTimeout <= 600)) return "connectTimeout must be 0.1 .. 600 s";
  if (o.priority < 0 || o.priority > 98) return "priority must be 0 (normal scheduling) .. 98";
  return "";
}

const Ros2IoBoardOptions& Ros2IoBoard::getOptions() const noexcept { return impl_->options; }

Ros2IoBoardStatistics Ros2IoBoard::getStatistics() const noexcept {
  return {impl_->samples.load(), impl_->sent.load(), impl_->failures.load()};
}

int Ros2IoBoard::numAnalogOutputs() const noexcept { return impl_->n; }

int Ros2IoBoard::numEncoders() const noexcept { return impl_->n; }

IoStatus Ros2IoBoard::readDigitalInput(int line, bool& value) noexcept {
  (void)value;
  return checkIndex(line, 0, "digital input");
}

IoStatus Ros2IoBoard::writeDigitalOutput(int line, bool value) noexcept {
  if (const IoStatus s = checkIndex(line, 1, "digital output"); s != IoStatus::kOk) return s;
  Impl& d = *impl_;
  IoStatus status = IoStatus::kOk;
  if (value && !d.remotePower.load(std::memory_order_relaxed)) {
    value = false;  // nothing is commanded to an arm whose power is off
    status = error_.set(IoStatus::kDeviceError, "the remote arm %.100s's power is off (switch it on in its own process)",
                        d.label.c_str());
  }
  d.enabled = value;
  // Torques computed from a sample this old are not sent: the remote arm holds (one empty command)
  // until samples come again, rather than taking torques computed from where it was. (With no
  // sample for `timeout`, the reads fail and the servo loop shuts down.)
  const double age = 1e-9 * static_cast<double>(steadyNanoseconds() - d.lastReceipt.load(std::memory_order_acquire));
  d.next.power = value && age <= kStaleSample;
  ++d.next.sequence;
  d.commands.write(d.next);
  return status;
}

IoStatus Ros2IoBoard::readDigitalOutput(int line, bool& value) noexcept {
  if (const IoStatus s = checkIndex(line, 1, "digital output"); s != IoStatus::kOk) return s;
  value = impl_->enabled;
  return IoStatus::kOk;
}

IoStatus Ros2IoBoard::readAnalogInput(int channel, double& volts) noexcept {
  (void)volts;
  return checkIndex(channel, 0, "analog input");
}

IoStatus Ros2IoBoard::writeAnalogOutput(int channel, double volts) noexcept {
  if (const IoStatus s = checkIndex(channel, impl_->n, "analog output"); s != IoStatus::kOk) return s;
  if (const IoStatus s = checkVolts(channel, volts); s != IoStatus::kOk) return s;
  const auto c = static_cast<std::size_t>(channel);
  impl_->next.tau[c] = std::clamp(volts, -kVoltLimit, kVoltLimit) * impl_->newtonMetresPerVolt[c];
  return IoStatus::kOk;
}

IoStatus Ros2IoBoard::readEncoder(int encoder, std::int64_t& counts) noexcept {
  Impl& d = *impl_;
  if (const IoStatus s = checkIndex(encoder, d.n, "encoder"); s != IoStatus::kOk) return s;
  if (d.faulted()) return error_.set(IoStatus::kDeviceError, "%s", d.faultText);
  const double silence = 1e-9 * static_cast<double>(steadyNanoseconds() - d.lastReceipt.load(std::memory_order_acquire));
  if (silence > d.options.timeout)
    return error_.set(IoStatus::kTimeout, "no joint_states from %.100s for %.3f s: the remote arm or its process is gone",
                      d.label.c_str(), silence);
  counts = d.counts[static_cast<std::size_t>(encoder)].load(std::memory_order_acquire);  // before the next sampleTime load
  return IoStatus::kOk;
}

std::int64_t Ros2IoBoard::inputSampleTime() const noexcept {
  // (readEncoder()'s acquire loads keep the encoder reads before this one: a sequence lock's check.)
  return impl_->sampleTime.load(std::memory_order_acquire);
}

}  // namespace rp
