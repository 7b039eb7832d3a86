#include "rp/io/HwServerIoBoard.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>

#include "HwServerShm.hpp"
#include "rp/io/IoException.hpp"

namespace rp {

using internal::HwClientState;

HwServerIoBoard::HwServerIoBoard(const std::string& name, int staleTimeoutMs, Heartbeat heartbeat)
    : name_(name), staleTimeoutMs_(staleTimeoutMs) {
  if (staleTimeoutMs <= 0)
    throw IoException("HwServerIoBoard '" + name + "': staleTimeoutMs must be positive");
  const std::string shmName = internal::hwServerShmName(name);
  const int fd = ::shm_open(shmName.c_str(), O_RDWR | O_CLOEXEC, 0);
  if (fd < 0)
    throw IoException("HwServerIoBoard: no hardware server '" + name + "' (" + shmName + ": " +
                      std::strerror(errno) + "); start it with rp-hwserver -name " + name);
  struct stat st {};
  if (::fstat(fd, &st) != 0 || static_cast<std::size_t>(st.st_size) < sizeof(internal::HwServerShm)) {
    ::close(fd);
    throw IoException("HwServerIoBoard: " + shmName + " is not a hardware-server segment (wrong size)");
  }
  void* p = ::mmap(nullptr, sizeof(internal::HwServerShm), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  if (p == MAP_FAILED)
    throw IoException("HwServerIoBoard: cannot map " + shmName + ": " + std::strerror(errno));
  shm_ = static_cast<internal::HwServerShm*>(p);
  const auto state = shm_->state.load(std::memory_order_acquire);  // pairs with the server's release
  if (state == static_cast<std::int32_t>(internal::HwServerState::kStarting) || shm_->magic != internal::kHwServerMagic || shm_->version != internal::kHwServerVersion ||
      shm_->size != sizeof(internal::HwServerShm)) {
    ::munmap(shm_, sizeof(internal::HwServerShm));
    shm_ = nullptr;
    throw IoException("HwServerIoBoard: " + shmName +
                      " is not a running hardware server of this version (starting, or a different build)");
  }
  try {
    claimSlot();
    waitForGoneClientsOutputsOff();
  } catch (...) {
    if (slot_ >= 0) shm_->clients[slot_].state.store(static_cast<std::int32_t>(HwClientState::kClosed));
    ::munmap(shm_, sizeof(internal::HwServerShm));
    shm_ = nullptr;
    throw;
  }
  if (heartbeat == Heartbeat::kBackgroundThread) keepAlive_ = std::thread([this] { keepAlive(); });
}

HwServerIoBoard::~HwServerIoBoard() {
  if (keepAlive_.joinable()) {
    {
      std::lock_guard lock(keepAliveMutex_);
      stopKeepAlive_ = true;
    }
    keepAliveWake_.notify_all();
    keepAlive_.join();
  }
  if (shm_ == nullptr) return;
  // Detach: the server switches this client's outputs off in its next cycle and frees the slot.
  shm_->clients[slot_].state.store(static_cast<std::int32_t>(HwClientState::kClosed));
  ::munmap(shm_, sizeof(internal::HwServerShm));
}

void HwServerIoBoard::claimSlot() {
  for (int k = 0; k < internal::kHwServerMaxClients; ++k) {
    internal::HwClientSlot& c = shm_->clients[k];
    auto expected = static_cast<std::int32_t>(HwClientState::kFree);
    if (!c.state.compare_exchange_strong(expected, static_cast<std::int32_t>(HwClientState::kClaiming))) continue;
    c.pid.store(static_cast<std::int32_t>(::getpid()));
    c.heartbeatNs.store(internal::monotonicNs());
    c.state.store(static_cast<std::int32_t>(HwClientState::kAttached));
    slot_ = k;
    return;
  }
  throw IoException("HwServerIoBoard: hardware server '" + name_ + "' has " +
                    std::to_string(internal::kHwServerMaxClients) + " clients already");
}

// An output that is on while its owner is not a live client (detached, killed, silent) belongs to
// a client that is gone; the server switches it off within its watchdog time. Wait for that.
void HwServerIoBoard::waitForGoneClientsOutputsOff() {
  const std::int64_t watchdog = shm_->watchdogNs.load();
  const std::int64_t deadline = internal::monotonicNs() + watchdog + std::int64_t{staleTimeoutMs_} * 1'000'000;
  auto live = [&](std::int8_t owner, std::int64_t now) {
    if (owner <= 0 || owner > internal::kHwServerMaxClients) return false;
    const internal::HwClientSlot& c = shm_->clients[owner - 1];
    if (c.state.load() != static_cast<std::int32_t>(HwClientState::kAttached) || now - c.heartbeatNs.load() > watchdog)
      return false;
    const std::int32_t pid = c.pid.load();
    return pid > 0 && !(::kill(pid, 0) != 0 && errno == ESRCH);  // a killed client's beat is recent but it is gone
  };
  while (true) {
    const std::int64_t now = internal::monotonicNs();
    int stillOn = -1;
    const char* kind = "";
    for (int i = 0; i < shm_->numDigitalOutputs && stillOn < 0; ++i) {
      if (shm_->digitalOutApplied[i].load() != 0 && !live(shm_->digitalOutOwner[i].load(), now)) {
        stillOn = i;
        kind = "digital";
      }
    }
    for (int i = 0; i < shm_->numAnalogOutputs && stillOn < 0; ++i) {
      if (shm_->analogOutApplied[i].load() != 0.0 && !live(shm_->analogOutOwner[i].load(), now)) {
        stillOn = i;
        kind = "analog";
      }
    }
    if (stillOn < 0) return;
    if (shm_->state.load() != static_cast<std::int32_t>(internal::HwServerState::kRunning) || now > deadline)
      throw IoException("HwServerIoBoard: hardware server '" + name_ + "' still has " + kind + " output " +
                        std::to_string(stillOn) + " on for a client that is gone (the server does not switch it off)");
    shm_->clients[slot_].heartbeatNs.store(now);
    ::usleep(500);
  }
}

void HwServerIoBoard::keepAlive() {
  // A few beats per watchdog time, at most every 10 ms.
  const auto period =
      std::chrono::nanoseconds(std::clamp<std::int64_t>(shm_->watchdogNs.load() / 4, 100'000, 10'000'000));
  std::unique_lock lock(keepAliveMutex_);
  while (!stopKeepAlive_) {
    shm_->clients[slot_].heartbeatNs.store(internal::monotonicNs());
    keepAliveWake_.wait_for(lock, period, [this] { return stopKeepAlive_; });
  }
}

void HwServerIoBoard::heartbeat() noexcept { shm_->clients[slot_].heartbeatNs.store(internal::monotonicNs()); }

double HwServerIoBoard::watchdogMs() const noexcept { return static_cast<double>(shm_->watchdogNs.load()) / 1e6; }
std::uint64_t HwServerIoBoard::watchdogTrips() const noexcept { return shm_->watchdogTrips.load(); }

IoStatus HwServerIoBoard::readAppliedDigitalOutput(int line, bool& value) noexcept {
  if (IoStatus s = checkIndex(line, numDigitalOutputs(), "digital output"); s != IoStatus::kOk) return s;
  value = shm_->digitalOutApplied[line].load() != 0;
  return IoStatus::kOk;
}

IoStatus HwServerIoBoard::readAppliedAnalogOutput(int channel, double& volts) noexcept {
  if (IoStatus s = checkIndex(channel, numAnalogOutputs(), "analog output"); s != IoStatus::kOk) return s;
  volts = shm_->analogOutApplied[channel].load();
  return IoStatus::kOk;
}

int HwServerIoBoard::numDigitalInputs() const noexcept { return shm_->numDigitalInputs; }
int HwServerIoBoard::numDigitalOutputs() const noexcept { return shm_->numDigitalOutputs; }
int HwServerIoBoard::numAnalogInputs() const noexcept { return shm_->numAnalogInputs; }
int HwServerIoBoard::numAnalogOutputs() const noexcept { return shm_->numAnalogOutputs; }
int HwServerIoBoard::numEncoders() const noexcept { return shm_->numEncoders; }

std::uint64_t HwServerIoBoard::serverCycles() const noexcept { return shm_->cycle.load(); }

std::int64_t HwServerIoBoard::inputSampleTime() const noexcept {
  if ((shm_->inputSeq.load(std::memory_order_acquire) & 1u) != 0) return -1;
  return shm_->inputTimeNs.load(std::memory_order_acquire);
}

IoStatus HwServerIoBoard::checkServer() noexcept {
  const std::int64_t now = internal::monotonicNs();
  internal::HwClientSlot& me = shm_->clients[slot_];
  me.heartbeatNs.store(now);
  if (me.state.load() != static_cast<std::int32_t>(HwClientState::kAttached))
    return error_.set(IoStatus::kNotConnected,
                      "hardware server '%s' switched this client's outputs off: it was silent for more than the "
                      "watchdog time (%.0f ms); attach again",
                      name_.c_str(), watchdogMs());
  if (shm_->state.load() != static_cast<std::int32_t>(internal::HwServerState::kRunning))
    return error_.set(IoStatus::kNotConnected, "hardware server '%s' has stopped", name_.c_str());
  const std::int64_t ageMs = (now - shm_->heartbeatNs.load()) / 1'000'000;
  if (ageMs > staleTimeoutMs_)
    return error_.set(IoStatus::kNotConnected, "hardware server '%s' is not responding (last cycle %ld ms ago)",
                      name_.c_str(), static_cast<long>(ageMs));
  const auto board = static_cast<IoStatus>(shm_->boardStatus.load());
  if (board != IoStatus::kOk) {
    char message[sizeof shm_->message];
    for (int attempt = 0; attempt < 8; ++attempt) {  // sequence lock, bounded retries
      const std::uint32_t before = shm_->messageSeq.load(std::memory_order_acquire);
      std::memcpy(message, shm_->message, sizeof message);
      if ((before & 1u) == 0 && shm_->messageSeq.load(std::memory_order_acquire) == before) break;
    }
    message[sizeof message - 1] = '\0';
    return error_.set(IoStatus::kDeviceError, "hardware server '%s': board error (%s): %s", name_.c_str(),
                      toString(board), message);
  }
  return IoStatus::kOk;
}

IoStatus HwServerIoBoard::checked(int index, int count, const char* what) noexcept {
  if (IoStatus s = checkIndex(index, count, what); s != IoStatus::kOk) return s;
  return checkServer();
}

IoStatus HwServerIoBoard::waitForCycle(int timeoutMs) noexcept {
  const std::uint64_t start = shm_->cycle.load();
  const std::int64_t deadline = internal::monotonicNs() + static_cast<std::int64_t>(timeoutMs) * 1'000'000;
  // Two increments guarantee a whole cycle ran after the call started.
  while (shm_->cycle.load() < start + 2) {
    if (IoStatus s = checkServer(); s == IoStatus::kNotConnected) return s;
    if (internal::monotonicNs() > deadline)
      return error_.set(IoStatus::kTimeout, "hardware server '%s' did not cycle within %d ms", name_.c_str(),
                        timeoutMs);
    ::usleep(200);
  }
  return IoStatus::kOk;
}

// The server's answer to this client's last request on a line: kOk, a failure, or kTimeout if not
// handled yet (the caller waits). Request numbers wrap; "done" counts as reached when it is at most
// 2^31 requests ahead.
IoStatus HwServerIoBoard::writeResult(bool digital, int line) noexcept {
  const std::uint32_t mine = digital ? digitalRequest_[line] : analogRequest_[line];
  if (mine == 0) return IoStatus::kOk;
  const std::uint32_t done =
      (digital ? shm_->digitalOutDone[line] : shm_->analogOutDone[line]).load(std::memory_order_acquire);
  if (static_cast<std::int32_t>(done - mine) < 0) return IoStatus::kTimeout;
  const auto result =
      static_cast<IoStatus>((digital ? shm_->digitalOutResult[line] : shm_->analogOutResult[line]).load());
  if (result == IoStatus::kOk) return IoStatus::kOk;
  char message[sizeof shm_->writeMessage];
  for (int attempt = 0; attempt < 8; ++attempt) {  // sequence lock, bounded retries
    const std::uint32_t before = shm_->writeMessageSeq.load(std::memory_order_acquire);
    std::memcpy(message, shm_->writeMessage, sizeof message);
    if ((before & 1u) == 0 && shm_->writeMessageSeq.load(std::memory_order_acquire) == before) break;
  }
  message[sizeof message - 1] = '\0';
  return error_.set(result, "hardware server '%s': %s output %d: %s: %s", name_.c_str(), digital ? "digital" : "analog",
                    line, toString(result), message);
}

IoStatus HwServerIoBoard::confirmWrites(int timeoutMs) noexcept {
  const std::int64_t deadline = internal::monotonicNs() + static_cast<std::int64_t>(timeoutMs) * 1'000'000;
  while (true) {
    if (IoStatus s = checkServer(); s == IoStatus::kNotConnected) return s;
    bool pending = false;
    for (int d = 0; d < 2; ++d) {
      const bool digital = d == 0;
      const int count = digital ? numDigitalOutputs() : numAnalogOutputs();
      for (int i = 0; i < count; ++i) {
        const IoStatus s = writeResult(digital, i);
        if (s == IoStatus::kTimeout) pending = true;
        else if (s != IoStatus::kOk) return s;
      }
    }
    if (!pending) return IoStatus::kOk;
    if (internal::monotonicNs() > deadline)
      return error_.set(IoStatus::kTimeout, "hardware server '%s' did not write the outputs within %d ms",
                        name_.c_str(), timeoutMs);
    ::usleep(200);
  }
}

IoStatus HwServerIoBoard::readDigitalInput(int line, bool& value) noexcept {
  if (IoStatus s = checked(line, numDigitalInputs(), "digital input"); s != IoStatus::kOk) return s;
  value = shm_->digitalIn[line].load() != 0;
  return IoStatus::kOk;
}

IoStatus HwServerIoBoard::writeDigitalOutput(int line, bool value) noexcept {
  if (IoStatus s = checked(line, numDigitalOutputs(), "digital output"); s != IoStatus::kOk) return s;
  // Owner, value, request number: in this order (the server reads them in the reverse order).
  shm_->digitalOutOwner[line].store(static_cast<std::int8_t>(slot_ + 1));
  shm_->digitalOut[line].store(value ? 1 : 0);
  digitalRequest_[line] = shm_->digitalOutRequest[line].fetch_add(1, std::memory_order_acq_rel) + 1;
  return IoStatus::kOk;
}

IoStatus HwServerIoBoard::readDigitalOutput(int line, bool& value) noexcept {
  if (IoStatus s = checked(line, numDigitalOutputs(), "digital output"); s != IoStatus::kOk) return s;
  value = shm_->digitalOut[line].load() != 0;
  return IoStatus::kOk;
}

IoStatus HwServerIoBoard::readAnalogInput(int channel, double& volts) noexcept {
  if (IoStatus s = checked(channel, numAnalogInputs(), "analog input"); s != IoStatus::kOk) return s;
  volts = shm_->analogIn[channel].load();
  return IoStatus::kOk;
}

IoStatus HwServerIoBoard::writeAnalogOutput(int channel, double volts) noexcept {
  if (IoStatus s = checked(channel, numAnalogOutputs(), "analog output"); s != IoStatus::kOk) return s;
  if (IoStatus s = checkVolts(channel, volts); s != IoStatus::kOk) return s;  // the server's board clamps
  shm_->analogOutOwner[channel].store(static_cast<std::int8_t>(slot_ + 1));
  shm_->analogOut[channel].store(volts);
  analogRequest_[channel] = shm_->analogOutRequest[channel].fetch_add(1, std::memory_order_acq_rel) + 1;
  return IoStatus::kOk;
}

IoStatus HwServerIoBoard::readEncoder(int encoder, std::int64_t& counts) noexcept {
  if (IoStatus s = checked(encoder, numEncoders(), "encoder"); s != IoStatus::kOk) return s;
  counts = shm_->encoders[encoder].load();
  return IoStatus::kOk;
}

}  // namespace rp
