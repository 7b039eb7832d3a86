#include "rp/io/HwServerIoBoard.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "HwServerShm.hpp"
#include "rp/io/IoException.hpp"

namespace rp {

HwServerIoBoard::HwServerIoBoard(const std::string& name, int staleTimeoutMs)
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
}

HwServerIoBoard::~HwServerIoBoard() {
  if (shm_ != nullptr) ::munmap(shm_, sizeof(internal::HwServerShm));
}

int HwServerIoBoard::numDigitalInputs() const noexcept { return shm_->numDigitalInputs; }
int HwServerIoBoard::numDigitalOutputs() const noexcept { return shm_->numDigitalOutputs; }
int HwServerIoBoard::numAnalogInputs() const noexcept { return shm_->numAnalogInputs; }
int HwServerIoBoard::numAnalogOutputs() const noexcept { return shm_->numAnalogOutputs; }
int HwServerIoBoard::numEncoders() const noexcept { return shm_->numEncoders; }

std::uint64_t HwServerIoBoard::serverCycles() const noexcept { return shm_->cycle.load(); }

IoStatus HwServerIoBoard::checkServer() noexcept {
  if (shm_->state.load() != static_cast<std::int32_t>(internal::HwServerState::kRunning))
    return error_.set(IoStatus::kNotConnected, "hardware server '%s' has stopped", name_.c_str());
  const std::int64_t ageMs = (internal::monotonicNs() - shm_->heartbeatNs.load()) / 1'000'000;
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

IoStatus HwServerIoBoard::readDigitalInput(int line, bool& value) noexcept {
  if (IoStatus s = checked(line, numDigitalInputs(), "digital input"); s != IoStatus::kOk) return s;
  value = shm_->digitalIn[line].load() != 0;
  return IoStatus::kOk;
}

IoStatus HwServerIoBoard::writeDigitalOutput(int line, bool value) noexcept {
  if (IoStatus s = checked(line, numDigitalOutputs(), "digital output"); s != IoStatus::kOk) return s;
  shm_->digitalOut[line].store(value ? 1 : 0);
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
  shm_->analogOut[channel].store(volts);
  return IoStatus::kOk;
}

IoStatus HwServerIoBoard::readEncoder(int encoder, std::int64_t& counts) noexcept {
  if (IoStatus s = checked(encoder, numEncoders(), "encoder"); s != IoStatus::kOk) return s;
  counts = shm_->encoders[encoder].load();
  return IoStatus::kOk;
}

}  // namespace rp
