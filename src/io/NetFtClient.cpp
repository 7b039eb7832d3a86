#include "rp/io/NetFtClient.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>

#include "rp/io/IoException.hpp"

namespace rp {

namespace {
constexpr std::size_t kRecordSize = 36;  // refdata/08: RDT record, 36 bytes
constexpr int kMaxDatagramsPerCall = 4096;

std::uint32_t be32(const std::uint8_t* p) {
  return (static_cast<std::uint32_t>(p[0]) << 24) | (static_cast<std::uint32_t>(p[1]) << 16) |
         (static_cast<std::uint32_t>(p[2]) << 8) | static_cast<std::uint32_t>(p[3]);
}
}  // namespace

NetFtClient::NetFtClient(const Config& config) : config_(config) {
  in_addr probe{};
  if (::inet_pton(AF_INET, config.address.c_str(), &probe) != 1)
    throw IoException("NetFtClient: address '" + config.address + "' is not an IPv4 address");
  if (config.port < 1 || config.port > 65535)
    throw IoException("NetFtClient: port = " + std::to_string(config.port) + " (must be 1 .. 65535)");
  if (!(config.countsPerForce > 0.0) || !(config.countsPerTorque > 0.0))
    throw IoException("NetFtClient: countsPerForce and countsPerTorque must be positive");
}

NetFtClient::~NetFtClient() { close(); }

IoStatus NetFtClient::open() noexcept {
  close();
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0)
    return error_.set(IoStatus::kNotConnected, "NetFt %s:%d: socket: %s", config_.address.c_str(), config_.port,
                      std::strerror(errno));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(config_.port));
  ::inet_pton(AF_INET, config_.address.c_str(), &addr.sin_addr);
  // A connected UDP socket only accepts datagrams from the sensor and reports ICMP
  // "port unreachable" (no sensor listening) as ECONNREFUSED.
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    const int err = errno;
    ::close(fd);
    return error_.set(IoStatus::kNotConnected, "NetFt %s:%d: connect: %s", config_.address.c_str(), config_.port,
                      std::strerror(err));
  }
  fd_ = fd;
  error_.clear();
  return IoStatus::kOk;
}

void NetFtClient::close() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void NetFtClient::encodeRequest(Command command, std::uint32_t sampleCount, std::uint8_t* bytes) noexcept {
  const auto cmd = static_cast<std::uint16_t>(command);
  bytes[0] = 0x12;
  bytes[1] = 0x34;
  bytes[2] = static_cast<std::uint8_t>(cmd >> 8);
  bytes[3] = static_cast<std::uint8_t>(cmd);
  // All 32 bits of the count (the ROS drivers' pack() loses the upper 16, refdata/08).
  bytes[4] = static_cast<std::uint8_t>(sampleCount >> 24);
  bytes[5] = static_cast<std::uint8_t>(sampleCount >> 16);
  bytes[6] = static_cast<std::uint8_t>(sampleCount >> 8);
  bytes[7] = static_cast<std::uint8_t>(sampleCount);
}

NetFtRecord NetFtClient::decode(const std::uint8_t* bytes, double countsPerForce, double countsPerTorque) noexcept {
  NetFtRecord r;
  r.rdtSequence = be32(bytes);
  r.ftSequence = be32(bytes + 4);
  r.status = be32(bytes + 8);
  for (int i = 0; i < 6; ++i) r.counts[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(be32(bytes + 12 + 4 * i));
  for (int i = 0; i < 3; ++i) {
    r.force[i] = r.counts[static_cast<std::size_t>(i)] / countsPerForce;
    r.torque[i] = r.counts[static_cast<std::size_t>(i + 3)] / countsPerTorque;
  }
  return r;
}

IoStatus NetFtClient::sendRequest(Command command, std::uint32_t sampleCount) noexcept {
  if (fd_ < 0)
    return error_.set(IoStatus::kNotConnected, "NetFt %s:%d: socket not open", config_.address.c_str(), config_.port);
  std::uint8_t request[8];
  encodeRequest(command, sampleCount, request);
  if (::send(fd_, request, sizeof request, MSG_NOSIGNAL) != static_cast<ssize_t>(sizeof request))
    return error_.set(IoStatus::kNotConnected, "NetFt %s:%d: send request 0x%04x: %s", config_.address.c_str(),
                      config_.port, static_cast<unsigned>(command), std::strerror(errno));
  return IoStatus::kOk;
}

IoStatus NetFtClient::startStreaming(std::uint32_t sampleCount) noexcept {
  haveSequence_ = false;
  missing_ = 0;
  received_ = lost_ = outOfOrder_ = malformed_ = 0;
  return sendRequest(Command::kStartRealtime, sampleCount);
}

IoStatus NetFtClient::receive(NetFtRecord& record, int timeoutMs) noexcept {
  if (fd_ < 0)
    return error_.set(IoStatus::kNotConnected, "NetFt %s:%d: socket not open", config_.address.c_str(), config_.port);
  const std::uint64_t lostBefore = lost_, outOfOrderBefore = outOfOrder_;
  bool accepted = false, anyMalformed = false;
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::milliseconds(timeoutMs > 0 ? timeoutMs : 0);
  std::uint8_t newest[kRecordSize];
  alignas(8) std::uint8_t buffer[kRecordSize * 40];
  for (int i = 0; i < kMaxDatagramsPerCall; ++i) {
    const ssize_t n = ::recv(fd_, buffer, sizeof buffer, MSG_DONTWAIT | MSG_TRUNC);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN || errno == EWOULDBLOCK) {
        if (accepted || anyMalformed) break;
        // Nothing new yet (or only stale records): wait for the rest of the timeout.
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
        if (left <= 0) break;
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, static_cast<int>(left)) <= 0) break;
        continue;
      }
      return error_.set(IoStatus::kNotConnected, "NetFt %s:%d: receive: %s%s", config_.address.c_str(), config_.port,
                        std::strerror(errno), errno == ECONNREFUSED ? " (no sensor at this address and port)" : "");
    }
    const auto size = static_cast<std::size_t>(n);
    if (size == 0 || size % kRecordSize != 0 || size > sizeof buffer) {
      ++malformed_;
      anyMalformed = true;
      continue;
    }
    for (std::size_t off = 0; off < size; off += kRecordSize) {
      const std::uint32_t seq = be32(buffer + off);
      if (haveSequence_) {
        const auto diff = static_cast<std::int32_t>(seq - lastSequence_);  // modulo 2^32 (refdata/08)
        if (diff <= 0) {
          ++outOfOrder_;
          // A late record whose sequence number was counted as a gap is out of order, not lost.
          const std::uint32_t back = lastSequence_ - seq;  // 0 = a duplicate of the newest
          if (back >= 1 && back <= 64 && (missing_ >> (back - 1) & 1u) != 0) {
            missing_ &= ~(std::uint64_t{1} << (back - 1));
            --lost_;
          }
          continue;
        }
        lost_ += static_cast<std::uint64_t>(diff - 1);
        // Bit i stands for sequence number seq - 1 - i: the old bits move up by diff, the gap
        // (seq - 1 down to lastSequence_ + 1) fills the lowest diff - 1 bits.
        const auto gap = static_cast<unsigned>(diff - 1);
        missing_ = (diff >= 64 ? 0 : missing_ << diff) | (gap >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << gap) - 1);
      }
      haveSequence_ = true;
      lastSequence_ = seq;
      ++received_;
      std::memcpy(newest, buffer + off, kRecordSize);
      accepted = true;
    }
  }
  if (!accepted) {
    if (anyMalformed)
      return error_.set(IoStatus::kProtocolError, "NetFt %s:%d: malformed datagram (not a multiple of %zu bytes)",
                        config_.address.c_str(), config_.port, kRecordSize);
    return error_.set(IoStatus::kTimeout, "NetFt %s:%d: no new record within %d ms (%llu stale records discarded)",
                      config_.address.c_str(), config_.port, timeoutMs,
                      static_cast<unsigned long long>(outOfOrder_ - outOfOrderBefore));
  }
  record = decode(newest, config_.countsPerForce, config_.countsPerTorque);
  if (record.status != 0)
    return error_.set(IoStatus::kDeviceError, "NetFt %s:%d: sensor status 0x%08x", config_.address.c_str(),
                      config_.port, record.status);
  if (lost_ != lostBefore || outOfOrder_ != outOfOrderBefore)
    return error_.set(IoStatus::kDataLoss, "NetFt %s:%d: %llu records lost, %llu out of order since the last read",
                      config_.address.c_str(), config_.port,
                      static_cast<unsigned long long>(lost_ > lostBefore ? lost_ - lostBefore : 0),
                      static_cast<unsigned long long>(outOfOrder_ - outOfOrderBefore));
  return IoStatus::kOk;
}

}  // namespace rp
