#include "rp/io/HwServer.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "HwServerShm.hpp"
#include "rp/io/IoException.hpp"

namespace rp {

namespace {

bool validName(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' ||
           c == '.';
  });
}

// An existing segment whose server process is gone (killed) may be replaced.
bool staleSegment(const std::string& shmName) {
  const int fd = ::shm_open(shmName.c_str(), O_RDONLY, 0);
  if (fd < 0) return false;
  bool stale = false;
  void* p = ::mmap(nullptr, sizeof(internal::HwServerShm), PROT_READ, MAP_SHARED, fd, 0);
  if (p != MAP_FAILED) {
    const auto* shm = static_cast<const internal::HwServerShm*>(p);
    const int pid = shm->serverPid.load();
    stale = shm->magic != internal::kHwServerMagic || pid <= 0 || (::kill(pid, 0) != 0 && errno == ESRCH) ||
            shm->state.load() == static_cast<std::int32_t>(internal::HwServerState::kStopped);
    ::munmap(p, sizeof(internal::HwServerShm));
  }
  ::close(fd);
  return stale;
}

}  // namespace

HwServer::HwServer(IoBoard& board, const std::string& name, double rateHz) : board_(board), name_(name), rateHz_(rateHz) {
  if (!validName(name))
    throw IoException("HwServer: name '" + name +
                      "' is invalid (1 to 64 letters, digits, '-', '_' or '.')");
  if (!(rateHz >= 1.0 && rateHz <= 10000.0))
    throw IoException("HwServer: rate = " + std::to_string(rateHz) + " Hz (must be 1 .. 10000)");
  counts_[0] = std::min(board.numDigitalInputs(), internal::kHwServerMaxLines);
  counts_[1] = std::min(board.numDigitalOutputs(), internal::kHwServerMaxLines);
  counts_[2] = std::min(board.numAnalogInputs(), internal::kHwServerMaxLines);
  counts_[3] = std::min(board.numAnalogOutputs(), internal::kHwServerMaxLines);
  counts_[4] = std::min(board.numEncoders(), internal::kHwServerMaxLines);
}

HwServer::~HwServer() { stop(); }

void HwServer::start() {
  if (shm_ != nullptr) return;
  const std::string shmName = internal::hwServerShmName(name_);
  int fd = ::shm_open(shmName.c_str(), O_CREAT | O_EXCL | O_RDWR | O_CLOEXEC, 0600);
  if (fd < 0 && errno == EEXIST && staleSegment(shmName)) {
    ::shm_unlink(shmName.c_str());
    fd = ::shm_open(shmName.c_str(), O_CREAT | O_EXCL | O_RDWR | O_CLOEXEC, 0600);
  }
  if (fd < 0)
    throw IoException("HwServer '" + name_ + "': cannot create shared memory " + shmName + ": " +
                      std::strerror(errno) + (errno == EEXIST ? " (another server of this name is running)" : ""));
  if (::ftruncate(fd, sizeof(internal::HwServerShm)) != 0) {
    const int err = errno;
    ::close(fd);
    ::shm_unlink(shmName.c_str());
    throw IoException("HwServer '" + name_ + "': cannot size shared memory: " + std::strerror(err));
  }
  void* p = ::mmap(nullptr, sizeof(internal::HwServerShm), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  if (p == MAP_FAILED) {
    ::shm_unlink(shmName.c_str());
    throw IoException("HwServer '" + name_ + "': cannot map shared memory: " + std::strerror(errno));
  }
  shm_ = static_cast<internal::HwServerShm*>(p);  // zero-filled by ftruncate: every atomic starts at 0
  shm_->version = internal::kHwServerVersion;
  shm_->size = sizeof(internal::HwServerShm);
  shm_->numDigitalInputs = counts_[0];
  shm_->numDigitalOutputs = counts_[1];
  shm_->numAnalogInputs = counts_[2];
  shm_->numAnalogOutputs = counts_[3];
  shm_->numEncoders = counts_[4];
  shm_->rateHz = rateHz_;
  shm_->serverPid.store(static_cast<std::int32_t>(::getpid()));
  cycle(true);  // inputs valid and outputs at zero before the first client looks
  shm_->magic = internal::kHwServerMagic;
  // Publishes everything above: clients read `state` (acquire) before any other field.
  shm_->state.store(static_cast<std::int32_t>(internal::HwServerState::kRunning), std::memory_order_release);
  stopRequested_.store(false);
  thread_ = std::thread([this] { run(); });
}

void HwServer::stop() {
  if (shm_ == nullptr) return;
  stopRequested_.store(true);
  if (thread_.joinable()) thread_.join();
  // Leave the hardware in a safe state: every output off.
  for (int i = 0; i < counts_[1]; ++i) board_.writeDigitalOutput(i, false);
  for (int i = 0; i < counts_[3]; ++i) board_.writeAnalogOutput(i, 0.0);
  shm_->state.store(static_cast<std::int32_t>(internal::HwServerState::kStopped));
  finalCycles_ = shm_->cycle.load();
  finalOverruns_ = shm_->overruns.load();
  ::munmap(shm_, sizeof(internal::HwServerShm));
  shm_ = nullptr;
  ::shm_unlink(internal::hwServerShmName(name_).c_str());
}

std::uint64_t HwServer::cycles() const noexcept { return shm_ ? shm_->cycle.load() : finalCycles_; }
std::uint64_t HwServer::overruns() const noexcept { return shm_ ? shm_->overruns.load() : finalOverruns_; }
IoStatus HwServer::boardStatus() const noexcept {
  return shm_ ? static_cast<IoStatus>(shm_->boardStatus.load()) : IoStatus::kOk;
}

void HwServer::cycle(bool writeAll) {
  IoStatus status = IoStatus::kOk;
  auto ok = [&](IoStatus s) {
    if (s != IoStatus::kOk && status == IoStatus::kOk) status = s;
    return s == IoStatus::kOk;
  };
  // Outputs first (a client's command reaches the board as early as possible), then inputs.
  // After the first failure the rest of the cycle is skipped: a board that is gone would
  // otherwise cost one timeout per line.
  for (int i = 0; i < counts_[1] && status == IoStatus::kOk; ++i) {
    const bool v = shm_->digitalOut[i].load() != 0;
    if ((writeAll || v != lastDigitalOut_[i]) && ok(board_.writeDigitalOutput(i, v))) lastDigitalOut_[i] = v;
  }
  for (int i = 0; i < counts_[3] && status == IoStatus::kOk; ++i) {
    const double v = shm_->analogOut[i].load();
    if ((writeAll || v != lastAnalogOut_[i]) && ok(board_.writeAnalogOutput(i, v))) lastAnalogOut_[i] = v;
  }
  for (int i = 0; i < counts_[0] && status == IoStatus::kOk; ++i) {
    bool v = false;
    if (ok(board_.readDigitalInput(i, v))) shm_->digitalIn[i].store(v ? 1 : 0);
  }
  for (int i = 0; i < counts_[2] && status == IoStatus::kOk; ++i) {
    double v = 0;
    if (ok(board_.readAnalogInput(i, v))) shm_->analogIn[i].store(v);
  }
  for (int i = 0; i < counts_[4] && status == IoStatus::kOk; ++i) {
    std::int64_t v = 0;
    if (ok(board_.readEncoder(i, v))) shm_->encoders[i].store(v);
  }
  if (status != IoStatus::kOk) {
    // Sequence lock: odd while the message is being written.
    shm_->messageSeq.fetch_add(1, std::memory_order_acq_rel);
    std::snprintf(shm_->message, sizeof shm_->message, "%s", board_.lastError());
    shm_->messageSeq.fetch_add(1, std::memory_order_release);
  }
  shm_->boardStatus.store(static_cast<std::int32_t>(status));
  shm_->heartbeatNs.store(internal::monotonicNs());
  shm_->cycle.fetch_add(1);
}

void HwServer::run() {
  const auto periodNs = static_cast<std::int64_t>(std::llround(1e9 / rateHz_));
  std::int64_t next = internal::monotonicNs();
  while (!stopRequested_.load()) {
    next += periodNs;
    timespec ts{static_cast<time_t>(next / 1'000'000'000), static_cast<long>(next % 1'000'000'000)};
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
    if (stopRequested_.load()) break;
    const std::int64_t now = internal::monotonicNs();
    if (now > next + periodNs) {  // a whole period late: count it and do not try to catch up
      shm_->overruns.fetch_add(1);
      next = now;
    }
    cycle(false);
  }
}

}  // namespace rp
