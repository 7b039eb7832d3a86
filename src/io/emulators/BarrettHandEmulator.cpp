#include "BarrettHandEmulator.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <stdexcept>

namespace rp::emulator {

BarrettHandEmulator::BarrettHandEmulator() : BarrettHandEmulator(Config{}) {}
BarrettHandEmulator::BarrettHandEmulator(const Config& config) : config_(config) {}
BarrettHandEmulator::~BarrettHandEmulator() { stop(); }

void BarrettHandEmulator::start() {
  if (thread_.joinable()) return;
  master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master_ < 0 || ::grantpt(master_) != 0 || ::unlockpt(master_) != 0)
    throw std::runtime_error(std::string("BarrettHandEmulator: cannot create a pseudo-terminal: ") +
                             std::strerror(errno));
  char name[128];
  if (::ptsname_r(master_, name, sizeof name) != 0)
    throw std::runtime_error("BarrettHandEmulator: ptsname failed");
  path_ = name;
  slave_ = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (slave_ < 0) throw std::runtime_error("BarrettHandEmulator: cannot open " + path_);
  termios tio{};
  ::tcgetattr(slave_, &tio);
  ::cfmakeraw(&tio);  // no line-discipline echo or translation: the emulator echoes like the hand
  ::tcsetattr(slave_, TCSANOW, &tio);
  stopRequested_.store(false);
  thread_ = std::thread([this] { serve(); });
}

void BarrettHandEmulator::stop() {
  if (!thread_.joinable()) return;
  stopRequested_.store(true);
  thread_.join();
  ::close(slave_);
  ::close(master_);
  slave_ = master_ = -1;
}

std::array<int, 4> BarrettHandEmulator::positions() const {
  std::lock_guard lock(mutex_);
  return positions_;
}

std::vector<std::string> BarrettHandEmulator::commands() const {
  std::lock_guard lock(mutex_);
  return commands_;
}

void BarrettHandEmulator::send(const std::string& bytes) {
  std::size_t sent = 0;
  for (int tries = 0; sent < bytes.size() && tries < 100; ++tries) {
    const ssize_t n = ::write(master_, bytes.data() + sent, bytes.size() - sent);
    if (n > 0) sent += static_cast<std::size_t>(n);
    else if (n < 0 && errno != EAGAIN && errno != EINTR) return;
  }
}

void BarrettHandEmulator::serve() {
  std::string line;
  while (!stopRequested_.load()) {
    pollfd p{master_, POLLIN, 0};
    if (::poll(&p, 1, 20) <= 0) continue;
    char buf[256];
    const ssize_t n = ::read(master_, buf, sizeof buf);
    if (n <= 0) continue;
    const Fault fault = fault_.load();
    for (ssize_t i = 0; i < n; ++i) {
      const char c = buf[i];
      if (c != '\r') {
        if (line.size() < 256) line += c;
        if (fault != Fault::kSilent && fault != Fault::kGarbled) send(std::string(1, c));  // echo
        continue;
      }
      const std::string cmd = line;
      line.clear();
      {
        std::lock_guard lock(mutex_);
        commands_.push_back(cmd);
      }
      switch (fault) {
        case Fault::kSilent:
          break;
        case Fault::kGarbled:
          send(std::string("\x15\xfe#\x7f%q\n\r=> "));
          break;
        case Fault::kTruncated:
          send("\n\r");
          break;
        case Fault::kWrongText: {
          std::string reply = "\n\r";
          {
            std::lock_guard lock(mutex_);
            reply.append(wrongText_);
          }
          reply.append("\n\r=> ");
          send(reply);
          break;
        }
        case Fault::kError: {
          std::string reply = "\n\rERR ";
          reply.append(std::to_string(errorCode_.load()));
          reply.append("\n\r=> ");
          send(reply);
          break;
        }
        case Fault::kNone: {
          std::string reply = "\n\r";
          const std::string text = execute(cmd);
          if (!text.empty()) {
            reply.append(text);
            reply.append("\n\r");
          }
          reply.append("=> ");
          send(reply);
          break;
        }
      }
    }
  }
}

std::string BarrettHandEmulator::execute(const std::string& line) {
  // Motor prefix: 1, 2, 3 fingers, 4 or S spread, G fingers 1+2+3; none = all (refdata/07).
  std::size_t i = 0;
  std::vector<int> motors;
  while (i < line.size() && std::strchr("1234SG", line[i]) != nullptr && line[i] != '\0') {
    const char c = line[i];
    if (c == 'G') motors.insert(motors.end(), {0, 1, 2});
    else if (c == 'S' || c == '4') motors.push_back(3);
    else motors.push_back(c - '1');
    ++i;
  }
  // "SHOME": S then HOME, but "S" alone is not a command.
  std::istringstream in(line.substr(i));
  std::string name;
  in >> name;
  if (motors.empty()) motors = {0, 1, 2, 3};
  std::sort(motors.begin(), motors.end());
  motors.erase(std::unique(motors.begin(), motors.end()), motors.end());

  auto move = [&](int fingerTarget, int spreadTarget) -> std::string {
    if (config_.requireInit && !initialized_.load()) return "ERR 4";
    if (config_.moveTimeMs > 0) ::usleep(static_cast<useconds_t>(config_.moveTimeMs) * 1000);
    std::lock_guard lock(mutex_);
    for (int m : motors) positions_[static_cast<std::size_t>(m)] = m == 3 ? spreadTarget : fingerTarget;
    return "";
  };

  if (name == "HI" && i == 0) {
    if (config_.moveTimeMs > 0) ::usleep(static_cast<useconds_t>(config_.moveTimeMs) * 1000);
    std::lock_guard lock(mutex_);
    positions_ = {0, 0, 0, 0};
    initialized_.store(true);
    return "";
  }
  if (name == "C") {
    const int closed = config_.objectAt >= 0 ? std::min(config_.objectAt, config_.fingerClosed) : config_.fingerClosed;
    return move(closed, 3150);
  }
  if (name == "O" || name == "HOME") return move(0, 0);
  if (name == "M") {
    int target = 0;
    if (!(in >> target)) target = 0;
    if (target < 0 || target > 17500) return "ERR 128";
    return move(target, std::min(target, 3150));
  }
  if (name == "T") return "";  // motors off: positions stay
  if (name == "FGET") {
    std::string prop;
    in >> prop;
    if (prop != "P") return "ERR 64";
    std::lock_guard lock(mutex_);
    std::string out;
    for (int m : motors) {
      if (!out.empty()) out.push_back(' ');
      out.append(std::to_string(positions_[static_cast<std::size_t>(m)]));
    }
    return out;
  }
  if (name == "PGET" && i == 0) {
    std::string prop;
    in >> prop;
    if (prop == "TEMP") return "285";
    return "ERR 64";
  }
  if (name == "RESET" && i == 0) {
    initialized_.store(false);
    return "BarrettHand Firmware 4.4 (emulated)";
  }
  return "ERR 32";
}

}  // namespace rp::emulator
