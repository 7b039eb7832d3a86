// dds_bench: the ROS 2 bridge (rp::Ros2Bridge) on Cyclone DDS, next to Cyclone DDS's own ddsperf
// in the same run on the same machine and the same loopback configuration.
//
// 1. Latency and throughput: a simulated Puma 560 at 1 kHz on the real clock and a Ros2Bridge at
//    the servo rate (`rate servo`: it publishes each servo cycle's state when the cycle ends). A
//    plain Cyclone DDS reader in a process of its own (this program with --reader, woken by a
//    waitset) takes every joint_states sample and measures its age: the wall clock when it is
//    taken minus the sample's stamp, which is the time at which the servo cycle read the joints
//    (StateSnapshot::readTime; ros2_control stamps joint states so too). So the latency runs from
//    the servo cycle's read to the remote reader: the rest of the servo cycle, the hand-over to the
//    bridge's thread, the message, DDS and loopback. The servo thread's own wake-up latency comes
//    before the read (rp-latency measures it; docs/realtime.md). Median, p99, max, samples per
//    second.
// 2. ddsperf (Debian's cyclonedds-tools): `ddsperf pong waitset` in one process, `ddsperf ping
//    1kHz waitset` in another, for the same time (woken by waitsets, as our reader); the one-way
//    latency is half the round trip of its per-second reports (median of their medians and of
//    their 99th percentiles).
//    The figure to watch: our median minus ddsperf's one-way median (the goal: < 20 us).
// 3. Load: four simulated Pumas at 1 kHz, first with no bridge, then with the bridge publishing all
//    four at the servo rate to a reader in another process: servo overruns (missed deadlines) and
//    the executor's wake-up p99 in each window. The bridge must not add overruns.
//
// Output (one line each):
//   rp_latency_us median M p99 P max X samples S samples_per_s R
//   ddsperf_one_way_us median M p99 P
//   added_median_us D
//   load no_bridge overruns O cycles C wakeup_p99_us W
//   load bridge overruns O cycles C wakeup_p99_us W samples S
//
// Usage: dds_bench [--seconds S] (default 5 per part)
#include <dds/dds.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "rp/RoboticPlatform.hpp"
#include "sensor_msgs.h"

namespace {

using Clock = std::chrono::system_clock;

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

// The reader process: takes every joint_states sample on DOMAIN/NS for SECONDS after the first
// one and prints `samples N median M p99 P max X` (ages in microseconds) and `seconds T`.
int reader(int domain, const std::string& ns, double seconds) {
  const std::string config = rp::Ros2Bridge::cycloneConfig({"lo"});
  if (dds_create_domain(static_cast<dds_domainid_t>(domain), config.c_str()) < 0) {
    std::fprintf(stderr, "dds_bench reader: cannot create domain %d\n", domain);
    return 1;
  }
  const dds_entity_t participant = dds_create_participant(static_cast<dds_domainid_t>(domain), nullptr, nullptr);
  const dds_entity_t topic =
      dds_create_topic(participant, &sensor_msgs_msg_dds__JointState__desc, ("rt/" + ns + "/joint_states").c_str(), nullptr, nullptr);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 10);
  const dds_entity_t r = dds_create_reader(participant, topic, qos, nullptr);
  dds_delete_qos(qos);
  const dds_entity_t condition = dds_create_readcondition(r, DDS_ANY_STATE);
  const dds_entity_t waitset = dds_create_waitset(participant);
  dds_waitset_attach(waitset, condition, 0);
  std::printf("ready\n");
  std::fflush(stdout);
  std::vector<double> ages;
  ages.reserve(static_cast<std::size_t>(seconds * 5000) + 1000);
  auto first = std::chrono::steady_clock::time_point{};
  const auto giveUp = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds + 20);
  constexpr int kBatch = 64;
  void* samples[kBatch];
  dds_sample_info_t info[kBatch];
  for (;;) {
    const auto now = std::chrono::steady_clock::now();
    if (ages.empty() ? now > giveUp : now - first > std::chrono::duration<double>(seconds)) break;
    dds_waitset_wait(waitset, nullptr, 0, DDS_MSECS(100));
    std::fill(samples, samples + kBatch, nullptr);
    const dds_return_t n = dds_take(r, samples, info, kBatch, kBatch);
    const auto taken = Clock::now().time_since_epoch();
    for (dds_return_t i = 0; i < n; ++i) {
      if (!info[i].valid_data) continue;
      const auto& m = *static_cast<const sensor_msgs_msg_dds__JointState_*>(samples[i]);
      const double stamp = static_cast<double>(m.header.stamp.sec) * 1e9 + static_cast<double>(m.header.stamp.nanosec);
      if (ages.empty()) first = std::chrono::steady_clock::now();
      ages.push_back((static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(taken).count()) - stamp) * 1e-3);
    }
    if (n > 0) dds_return_loan(r, samples, n);
  }
  std::printf("samples %zu median %.1f p99 %.1f max %.1f\n", ages.size(), percentile(ages, 0.5), percentile(ages, 0.99),
              ages.empty() ? 0.0 : *std::max_element(ages.begin(), ages.end()));
  std::fflush(stdout);
  dds_delete(DDS_CYCLONEDDS_HANDLE);
  return ages.empty() ? 1 : 0;
}

// A reader process started with popen(); its "ready" line read.
struct ReaderProcess {
  FILE* pipe = nullptr;
  ReaderProcess(const char* self, int domain, const std::string& ns, double seconds) {
    const std::string command = std::string(self) + " --reader " + std::to_string(domain) + " " + ns + " " + std::to_string(seconds);
    pipe = popen(command.c_str(), "r");
    char line[256] = "";
    if (pipe == nullptr || std::fgets(line, sizeof line, pipe) == nullptr || std::strcmp(line, "ready\n") != 0) {
      std::fprintf(stderr, "dds_bench: the reader did not start\n");
      std::exit(1);
    }
  }
  // Its result line (samples ... median ... p99 ... max ...), once it has ended.
  std::string result() {
    std::string out;
    char line[512];
    while (std::fgets(line, sizeof line, pipe) != nullptr) out += line;
    const int status = pclose(pipe);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      std::fprintf(stderr, "dds_bench: the reader failed: %s\n", out.c_str());
      std::exit(1);
    }
    return out;
  }
};

double field(const std::string& text, const std::string& name) {
  const std::size_t at = text.find(name + " ");
  return at == std::string::npos ? -1 : std::atof(text.c_str() + at + name.size() + 1);
}

// ddsperf ping at 1 kHz against ddsperf pong for `seconds`, on the loopback configuration, both
// taking their samples when a waitset wakes them, as the reader of part 1 does (and a ROS 2
// executor does); ddsperf's default, a listener called in DDS's receive thread, saves a thread
// switch on each side (about 5 us one way here). Returns the medians of its per-second 50% and 99%
// round trips, halved [us].
std::pair<double, double> ddsperf(int domain, double seconds) {
  setenv("CYCLONEDDS_URI", rp::Ros2Bridge::cycloneConfig({"lo"}).c_str(), 1);
  const std::string d = std::to_string(domain), s = std::to_string(static_cast<int>(seconds + 2));
  FILE* pong = popen(("ddsperf -i " + d + " -D " + s + " pong waitset 2>&1").c_str(), "r");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  FILE* ping =
      popen(("ddsperf -i " + d + " -D " + std::to_string(static_cast<int>(seconds)) + " ping 1kHz waitset 2>&1").c_str(), "r");
  if (pong == nullptr || ping == nullptr) {
    std::fprintf(stderr, "dds_bench: cannot run ddsperf (Debian's cyclonedds-tools)\n");
    std::exit(1);
  }
  std::vector<double> p50, p99;
  char line[1024];
  while (std::fgets(line, sizeof line, ping) != nullptr) {
    const std::string l = line;
    const double a = field(l, "50%"), b = field(l, "99%");
    if (a > 0 && b > 0) {
      p50.push_back(a);
      p99.push_back(b);
    }
  }
  pclose(ping);
  while (std::fgets(line, sizeof line, pong) != nullptr) {
  }
  pclose(pong);
  unsetenv("CYCLONEDDS_URI");
  if (p50.empty()) {
    std::fprintf(stderr, "dds_bench: ddsperf reported no round trip\n");
    std::exit(1);
  }
  return {percentile(p50, 0.5) / 2, percentile(p99, 0.5) / 2};
}

struct Window {
  std::uint64_t overruns = 0, cycles = 0;
  double wakeupP99 = 0;
};

// Servo overruns of `arms` over `seconds` (after a second's warm-up) and the executors' wake-up p99.
Window servoWindow(const std::vector<std::unique_ptr<rp::Puma560>>& arms, double seconds) {
  std::vector<rp::ControlStatistics> before;
  for (const auto& a : arms) before.push_back(a->getStatistics());
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  Window w;
  for (std::size_t i = 0; i < arms.size(); ++i) {
    const rp::ControlStatistics s = arms[i]->getStatistics();
    w.overruns += s.overruns - before[i].overruns;
    w.cycles += s.cycles - before[i].cycles;
    w.wakeupP99 = std::max(w.wakeupP99, s.wakeupLatency.p99);
  }
  return w;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 5 && std::string(argv[1]) == "--reader") return reader(std::atoi(argv[2]), argv[3], std::atof(argv[4]));
  double seconds = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--seconds" && i + 1 < argc) {
      seconds = std::atof(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: dds_bench [--seconds S]\n");
      return 2;
    }
  }
  if (seconds <= 0) {
    std::fprintf(stderr, "dds_bench: --seconds must be > 0\n");
    return 2;
  }
  rp::RoboticPlatform::setSimulationModeOn();  // real clock, simulated arms
  const int domain = 100 + static_cast<int>(getpid() % 100);
  const std::string ns = "bench" + std::to_string(getpid());

  // 1. Latency from the servo cycle to a reader in another process.
  {
    ReaderProcess r(argv[0], domain, ns, seconds);
    rp::Puma560 puma("puma");
    rp::Ros2BridgeOptions options;
    options.domain = domain;
    options.nameSpace = ns;
    options.rate = rp::Ros2BridgeOptions::kServoRate;
    rp::Ros2Bridge bridge("ros", options);
    const std::string out = r.result();
    const double samples = field(out, "samples");
    std::printf("rp_latency_us median %.1f p99 %.1f max %.1f samples %.0f samples_per_s %.0f\n", field(out, "median"),
                field(out, "p99"), field(out, "max"), samples, samples / seconds);
    std::fflush(stdout);
    // 2. ddsperf on the same configuration, now.
    const auto [median, p99] = ddsperf(domain + 1, seconds);
    std::printf("ddsperf_one_way_us median %.1f p99 %.1f\n", median, p99);
    std::printf("added_median_us %.1f\n", field(out, "median") - median);
    std::fflush(stdout);
  }

  // 3. Four arms at 1 kHz without and with the bridge.
  std::vector<std::unique_ptr<rp::Puma560>> arms;
  for (int i = 0; i < 4; ++i) arms.push_back(std::make_unique<rp::Puma560>("load" + std::to_string(i)));
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const Window quiet = servoWindow(arms, seconds);
  std::printf("load no_bridge overruns %llu cycles %llu wakeup_p99_us %.1f\n", static_cast<unsigned long long>(quiet.overruns),
              static_cast<unsigned long long>(quiet.cycles), quiet.wakeupP99);
  std::fflush(stdout);
  {
    ReaderProcess r(argv[0], domain + 2, ns, seconds + 1);
    rp::Ros2BridgeOptions options;
    options.domain = domain + 2;
    options.nameSpace = ns;
    options.rate = rp::Ros2BridgeOptions::kServoRate;
    rp::Ros2Bridge bridge("ros", options);
    std::this_thread::sleep_for(std::chrono::seconds(1));
    const Window loaded = servoWindow(arms, seconds);
    const std::string out = r.result();
    std::printf("load bridge overruns %llu cycles %llu wakeup_p99_us %.1f samples %.0f\n",
                static_cast<unsigned long long>(loaded.overruns), static_cast<unsigned long long>(loaded.cycles),
                loaded.wakeupP99, field(out, "samples"));
  }
  return 0;
}
