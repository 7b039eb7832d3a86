#include "NetFtEmulator.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace rp::emulator {

namespace {
void put32(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 24);
  p[1] = static_cast<std::uint8_t>(v >> 16);
  p[2] = static_cast<std::uint8_t>(v >> 8);
  p[3] = static_cast<std::uint8_t>(v);
}
}  // namespace

NetFtEmulator::NetFtEmulator() : NetFtEmulator(Config{}) {}
NetFtEmulator::NetFtEmulator(const Config& config) : config_(config) {
  if (!(config.rateHz > 0.0 && config.rateHz <= 10000.0))
    throw std::invalid_argument("NetFtEmulator: rateHz must be in (0, 10000]");
}
NetFtEmulator::~NetFtEmulator() { stop(); }

void NetFtEmulator::encode(std::uint32_t rdtSequence, std::uint32_t ftSequence, std::uint32_t status,
                           const std::array<std::int32_t, 6>& counts, std::uint8_t* bytes) {
  put32(bytes, rdtSequence);
  put32(bytes + 4, ftSequence);
  put32(bytes + 8, status);
  for (int i = 0; i < 6; ++i) put32(bytes + 12 + 4 * i, static_cast<std::uint32_t>(counts[static_cast<std::size_t>(i)]));
}

void NetFtEmulator::start() {
  if (thread_.joinable()) return;
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(config_.port));
  if (fd_ < 0 || ::inet_pton(AF_INET, config_.address.c_str(), &addr.sin_addr) != 1 ||
      ::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    const std::string why = std::strerror(errno);
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    throw std::runtime_error("NetFtEmulator: cannot bind UDP " + config_.address + ":" +
                             std::to_string(config_.port) + ": " + why);
  }
  socklen_t len = sizeof addr;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  stopRequested_.store(false);
  thread_ = std::thread([this] { serve(); });
}

void NetFtEmulator::stop() {
  if (!thread_.joinable()) return;
  stopRequested_.store(true);
  thread_.join();
  ::close(fd_);
  fd_ = -1;
  streaming_.store(false);
}

void NetFtEmulator::setWrench(const std::array<double, 6>& wrench) {
  std::lock_guard lock(mutex_);
  wrench_ = wrench;
  script_ = nullptr;
}

void NetFtEmulator::setScript(Script script) {
  std::lock_guard lock(mutex_);
  script_ = std::move(script);
}

void NetFtEmulator::setFaults(const Faults& faults) {
  std::lock_guard lock(mutex_);
  faults_ = faults;
}

void NetFtEmulator::serve() {
  using Clock = std::chrono::steady_clock;
  const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / config_.rateHz));
  sockaddr_in client{};
  std::uint32_t remaining = 0;  // records left in a finite stream (0 = infinite)
  std::uint32_t ftSequence = 0;
  auto streamStart = Clock::now();
  auto next = Clock::now();
  std::array<std::int32_t, 6> bias{};
  std::array<std::int32_t, 6> lastRaw{};
  bool haveHeld = false;
  std::uint8_t held[36];

  auto sendBytes = [&](const std::uint8_t* bytes, std::size_t n) {
    ::sendto(fd_, bytes, n, 0, reinterpret_cast<const sockaddr*>(&client), sizeof client);
  };

  while (!stopRequested_.load()) {
    int waitMs = 20;
    if (streaming_.load()) {
      const auto left = std::chrono::duration_cast<std::chrono::microseconds>(next - Clock::now()).count();
      waitMs = left <= 0 ? 0 : static_cast<int>((left + 999) / 1000);
      if (waitMs > 20) waitMs = 20;
    }
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, waitMs) > 0 && (p.revents & POLLIN)) {
      std::uint8_t req[64];
      sockaddr_in from{};
      socklen_t fromLen = sizeof from;
      const ssize_t n = ::recvfrom(fd_, req, sizeof req, 0, reinterpret_cast<sockaddr*>(&from), &fromLen);
      Faults faults;
      {
        std::lock_guard lock(mutex_);
        faults = faults_;
      }
      if (n == 8 && req[0] == 0x12 && req[1] == 0x34 && !faults.silent) {
        requests_.fetch_add(1);
        const unsigned command = (static_cast<unsigned>(req[2]) << 8) | req[3];
        const std::uint32_t count = (static_cast<std::uint32_t>(req[4]) << 24) |
                                    (static_cast<std::uint32_t>(req[5]) << 16) |
                                    (static_cast<std::uint32_t>(req[6]) << 8) | req[7];
        if (command == 0x0002 || command == 0x0003) {
          client = from;
          remaining = count;
          sequence_.store(0);
          haveHeld = false;
          streamStart = next = Clock::now();
          streaming_.store(true);
        } else if (command == 0x0000) {
          streaming_.store(false);
        } else if (command == 0x0042) {
          bias = lastRaw;
          biasRequests_.fetch_add(1);
        }
      }
    }
    if (!streaming_.load() || Clock::now() < next) continue;
    next += period;
    Faults faults;
    std::array<double, 6> wrench;
    {
      std::lock_guard lock(mutex_);
      faults = faults_;
      const double t = std::chrono::duration<double>(Clock::now() - streamStart).count();
      wrench = script_ ? script_(t) : wrench_;
    }
    if (faults.silent) {
      streaming_.store(false);
      continue;
    }
    std::array<std::int32_t, 6> counts{};
    for (std::size_t i = 0; i < 6; ++i) {
      const double scale = i < 3 ? config_.countsPerForce : config_.countsPerTorque;
      lastRaw[i] = static_cast<std::int32_t>(std::lround(wrench[i] * scale));
      counts[i] = lastRaw[i] - bias[i];
    }
    const std::uint32_t seq = sequence_.fetch_add(1) + 1;  // first record = 1 (refdata/08)
    ftSequence += static_cast<std::uint32_t>(std::max(1.0, std::round(7000.0 / config_.rateHz)));
    std::uint8_t record[36];
    encode(seq, ftSequence, faults.status, counts, record);
    auto every = [seq](int k) { return k > 0 && seq % static_cast<std::uint32_t>(k) == 0; };
    bool justHeld = false;
    if (every(faults.dropEvery)) {
      // lost on the way
    } else if (every(faults.garbleEvery)) {
      std::uint8_t junk[40];
      for (int i = 0; i < 40; ++i) junk[i] = static_cast<std::uint8_t>(0xA5 ^ (i * 37));
      sendBytes(junk, sizeof junk);
    } else if (every(faults.truncateEvery)) {
      sendBytes(record, 20);
    } else if (every(faults.reorderEvery) && !haveHeld) {
      std::memcpy(held, record, sizeof record);  // sent after its successor
      haveHeld = justHeld = true;
    } else {
      sendBytes(record, sizeof record);
    }
    if (haveHeld && !justHeld) {
      sendBytes(held, sizeof held);
      haveHeld = false;
    }
    if (remaining > 0 && --remaining == 0) {
      if (haveHeld) sendBytes(held, sizeof held);
      haveHeld = false;
      streaming_.store(false);
    }
  }
}

}  // namespace rp::emulator
