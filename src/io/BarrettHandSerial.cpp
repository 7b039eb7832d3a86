#include "rp/io/BarrettHandSerial.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <sstream>

#include "rp/io/IoException.hpp"

namespace rp {

namespace {

speed_t baudConstant(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    default: return B0;
  }
}

// The prompt the hand prints when it is ready (refdata/07: '=> ').
constexpr const char* kPrompt = "=> ";
constexpr std::size_t kMaxReply = 4096;

// Shows the start of a reply with non-printable bytes escaped, for error messages.
std::string printable(const std::string& bytes) {
  std::string out;
  for (std::size_t i = 0; i < bytes.size() && i < 40; ++i) {
    const auto c = static_cast<unsigned char>(bytes[i]);
    if (c == '\r') out += "\\r";
    else if (c == '\n') out += "\\n";
    else if (c >= 32 && c < 127) out += static_cast<char>(c);
    else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    }
  }
  if (bytes.size() > 40) out += "...";
  return out;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \r\n\t");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \r\n\t");
  return s.substr(b, e - b + 1);
}

}  // namespace

BarrettHandSerial::BarrettHandSerial(const Config& config) : config_(config) {
  if (baudConstant(config.baud) == B0)
    throw IoException("BarrettHandSerial: baud = " + std::to_string(config.baud) +
                      " (must be 9600, 19200, 38400, 57600 or 115200)");
  if (config.timeoutMs <= 0 || config.motionTimeoutMs <= 0)
    throw IoException("BarrettHandSerial: timeoutMs and motionTimeoutMs must be positive");
}

BarrettHandSerial::~BarrettHandSerial() { close(); }

IoStatus BarrettHandSerial::open() noexcept {
  close();
  const int fd = ::open(config_.port.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0)
    return error_.set(IoStatus::kNotConnected, "BarrettHand %s: cannot open serial port: %s", config_.port.c_str(),
                      std::strerror(errno));
  termios tio{};
  if (::tcgetattr(fd, &tio) != 0) {
    const int err = errno;
    ::close(fd);
    return error_.set(IoStatus::kNotConnected, "BarrettHand %s: not a serial port: %s", config_.port.c_str(),
                      std::strerror(err));
  }
  // 8N1, raw, no flow control (refdata/07, physical layer).
  ::cfmakeraw(&tio);
  tio.c_cflag &= ~static_cast<tcflag_t>(PARENB | CSTOPB | CSIZE | CRTSCTS);
  tio.c_cflag |= CS8 | CLOCAL | CREAD;
  tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  ::cfsetispeed(&tio, baudConstant(config_.baud));
  ::cfsetospeed(&tio, baudConstant(config_.baud));
  if (::tcsetattr(fd, TCSANOW, &tio) != 0) {
    const int err = errno;
    ::close(fd);
    return error_.set(IoStatus::kNotConnected, "BarrettHand %s: cannot configure serial port: %s",
                      config_.port.c_str(), std::strerror(err));
  }
  fd_ = fd;
  error_.clear();
  return IoStatus::kOk;
}

void BarrettHandSerial::close() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

IoStatus BarrettHandSerial::command(const std::string& cmd, std::string* reply, int timeoutMs) {
  lastErrorCode_ = 0;
  if (fd_ < 0)
    return error_.set(IoStatus::kNotConnected, "BarrettHand %s: '%s' failed: port not open", config_.port.c_str(),
                      cmd.c_str());
  if (cmd.empty() || cmd.size() > 120 ||
      cmd.find_first_of("\r\n") != std::string::npos)
    return error_.set(IoStatus::kProtocolError, "BarrettHand %s: invalid command '%s'", config_.port.c_str(),
                      printable(cmd).c_str());
  if (timeoutMs <= 0) timeoutMs = config_.timeoutMs;

  ::tcflush(fd_, TCIFLUSH);  // drop what is left of an earlier (truncated or late) reply
  const std::string line = cmd + "\r";
  std::size_t sent = 0;
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::milliseconds(timeoutMs);
  auto remainingMs = [&] {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    return left < 0 ? 0 : static_cast<int>(left);
  };
  while (sent < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + sent, line.size() - sent);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) {
      const int err = errno;
      close();
      return error_.set(IoStatus::kNotConnected, "BarrettHand %s: '%s' failed: write: %s", config_.port.c_str(),
                        cmd.c_str(), std::strerror(err));
    }
    pollfd p{fd_, POLLOUT, 0};
    if (::poll(&p, 1, remainingMs()) == 0)
      return error_.set(IoStatus::kTimeout, "BarrettHand %s: '%s' failed: cannot send within %d ms",
                        config_.port.c_str(), cmd.c_str(), timeoutMs);
  }

  std::string buffer;
  while (buffer.size() < kMaxReply) {
    if (buffer.size() >= 3 && buffer.compare(buffer.size() - 3, 3, kPrompt) == 0) break;
    const int wait = remainingMs();
    pollfd p{fd_, POLLIN, 0};
    const int rc = wait > 0 ? ::poll(&p, 1, wait) : 0;
    if (rc < 0 && errno == EINTR) continue;
    if (rc == 0) {
      if (buffer.empty())
        return error_.set(IoStatus::kTimeout, "BarrettHand %s: '%s' failed: no reply within %d ms",
                          config_.port.c_str(), cmd.c_str(), timeoutMs);
      return error_.set(IoStatus::kTimeout, "BarrettHand %s: '%s' failed: truncated reply (no prompt within %d ms): '%s'",
                        config_.port.c_str(), cmd.c_str(), timeoutMs, printable(buffer).c_str());
    }
    char chunk[256];
    const ssize_t n = ::read(fd_, chunk, sizeof chunk);
    if (n > 0) {
      buffer.append(chunk, static_cast<std::size_t>(n));
    } else if (n == 0 || (errno != EAGAIN && errno != EINTR) || (p.revents & (POLLHUP | POLLERR))) {
      const int err = n == 0 ? 0 : errno;
      close();
      return error_.set(IoStatus::kNotConnected, "BarrettHand %s: '%s' failed: device disconnected (%s)",
                        config_.port.c_str(), cmd.c_str(), err ? std::strerror(err) : "end of file");
    }
  }
  if (buffer.size() < 3 || buffer.compare(buffer.size() - 3, 3, kPrompt) != 0)
    return error_.set(IoStatus::kProtocolError, "BarrettHand %s: '%s' failed: reply longer than %zu bytes without prompt",
                      config_.port.c_str(), cmd.c_str(), kMaxReply);
  // The hand echoes the command first (refdata/07: drivers read and discard the echo).
  if (buffer.compare(0, cmd.size(), cmd) != 0)
    return error_.set(IoStatus::kProtocolError, "BarrettHand %s: '%s' failed: garbled reply '%s'",
                      config_.port.c_str(), cmd.c_str(), printable(buffer).c_str());
  const std::string text = trim(buffer.substr(cmd.size(), buffer.size() - cmd.size() - 3));
  if (text.rfind("ERR", 0) == 0) {
    // The code whole, as a number that fits (sscanf's %d is undefined on overflow: ERR
    // 99999999999999999999 came out as -1, every error bit).
    errno = 0;
    char* end = nullptr;
    const long parsed = std::strtol(text.c_str() + 3, &end, 10);
    const bool whole = end != text.c_str() + 3 && trim(std::string(end)).empty();
    if (!whole || errno == ERANGE || parsed < 0 || parsed > 65535)
      return error_.set(IoStatus::kProtocolError, "BarrettHand %s: '%s' failed: unreadable error reply '%s'",
                        config_.port.c_str(), cmd.c_str(), printable(text).c_str());
    const int code = static_cast<int>(parsed);
    lastErrorCode_ = code;
    return error_.set(IoStatus::kDeviceError, "BarrettHand %s: '%s' failed: ERR %d (%s)", config_.port.c_str(),
                      cmd.c_str(), code, describeErrorCode(code).c_str());
  }
  // A command whose reply the caller does not take (HI, GC, GO, T: motions and settings) answers
  // with the prompt alone; text there is not this protocol (it was reported as success).
  if (reply == nullptr && !text.empty())
    return error_.set(IoStatus::kProtocolError, "BarrettHand %s: '%s' failed: unexpected reply '%s'",
                      config_.port.c_str(), cmd.c_str(), printable(text).c_str());
  if (reply != nullptr) *reply = text;
  return IoStatus::kOk;
}

IoStatus BarrettHandSerial::readPositions(std::array<int, 4>& counts) {
  std::string reply;
  if (IoStatus s = command("FGET P", &reply); s != IoStatus::kOk) return s;
  std::istringstream in(reply);
  std::array<int, 4> values{};
  bool ok = true;
  for (int& v : values) ok = ok && static_cast<bool>(in >> v);
  if (ok) in >> std::ws;
  if (!ok || !in.eof())  // four numbers and nothing after them ("100 200 300 400abc" was taken)
    return error_.set(IoStatus::kProtocolError, "BarrettHand %s: 'FGET P' failed: expected 4 positions, got '%s'",
                      config_.port.c_str(), printable(reply).c_str());
  counts = values;
  return IoStatus::kOk;
}

std::string BarrettHandSerial::describeErrorCode(int code) {
  // Bit meanings from refdata/07 (libgripper barrett_error.h).
  static const struct {
    int bit;
    const char* text;
  } kBits[] = {{1, "no motor board found"},   {2, "no motor found"},
               {4, "motor not initialized"},  {16, "couldn't reach position"},
               {32, "unknown command"},       {64, "unknown parameter name"},
               {128, "invalid value"},        {256, "write to read-only parameter"},
               {1024, "too many arguments"},  {2048, "invalid RealTime header"},
               {4096, "invalid motor prefix"}, {8192, "overtemperature fault"},
               {16384, "Ctrl-C abort"}};
  std::string out;
  int known = 0;
  for (const auto& b : kBits)
    if (code & b.bit) {
      if (!out.empty()) out += ", ";
      out += b.text;
      known |= b.bit;
    }
  if (code & ~known) {
    if (!out.empty()) out += ", ";
    out += "unknown error";
  }
  return out.empty() ? "unknown error" : out;
}

}  // namespace rp
