#pragma once
// ATI Net F/T emulator: answers RDT requests on UDP (refdata/08) and streams 36-byte big-endian
// records of a scripted wrench, with fault injection. For tests and `rp-emulate netft`.

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

namespace rp::emulator {

class NetFtEmulator {
 public:
  struct Config {
    std::string address = "127.0.0.1";
    int port = 0;                     // 0 = an ephemeral port, see port()
    double rateHz = 1000.0;           // records per second while streaming
    double countsPerForce = 1000000.0;
    double countsPerTorque = 1000000.0;
  };
  // Wrench [Fx Fy Fz (N), Tx Ty Tz (N m)] as a function of the time since streaming started [s].
  using Script = std::function<std::array<double, 6>(double t)>;
  struct Faults {
    int dropEvery = 0;      // do not send records whose sequence number is a multiple of this
    int reorderEvery = 0;   // send such a record after its successor
    int garbleEvery = 0;    // send 40 bytes of junk instead of such a record
    int truncateEvery = 0;  // send only the first 20 bytes of such a record
    bool silent = false;    // ignore requests and stop streaming (a hung sensor)
    std::uint32_t status = 0;  // status word of every record
  };

  explicit NetFtEmulator(const Config& config);
  NetFtEmulator();
  ~NetFtEmulator();
  NetFtEmulator(const NetFtEmulator&) = delete;
  NetFtEmulator& operator=(const NetFtEmulator&) = delete;

  void start();  // binds and starts the thread; throws std::runtime_error on failure
  void stop();   // closes the socket (as if the sensor were switched off)
  int port() const { return port_; }

  void setWrench(const std::array<double, 6>& wrench);
  void setScript(Script script);
  void setFaults(const Faults& faults);
  bool streaming() const { return streaming_.load(); }
  long requestsReceived() const { return requests_.load(); }
  long biasRequests() const { return biasRequests_.load(); }
  std::uint32_t recordsGenerated() const { return sequence_.load(); }

  // Encodes one record (exposed for tests).
  static void encode(std::uint32_t rdtSequence, std::uint32_t ftSequence, std::uint32_t status,
                     const std::array<std::int32_t, 6>& counts, std::uint8_t* bytes);

 private:
  void serve();

  Config config_;
  int fd_ = -1;
  int port_ = 0;
  std::atomic<bool> stopRequested_{false};
  std::atomic<bool> streaming_{false};
  std::atomic<long> requests_{0};
  std::atomic<long> biasRequests_{0};
  std::atomic<std::uint32_t> sequence_{0};
  std::mutex mutex_;
  Script script_;
  std::array<double, 6> wrench_{};
  Faults faults_;
  std::thread thread_;
};

}  // namespace rp::emulator
