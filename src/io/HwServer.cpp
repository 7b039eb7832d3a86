#include "rp/io/HwServer.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
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

// An existing segment whose server is gone (killed, crashed) may be replaced. A running server
// holds an exclusive flock on its segment for as long as it lives; the kernel drops that lock when
// the process ends however it ends, so a lock we can take means nobody serves the segment. (The
// pid stored in the segment is not enough: after a reboot or in a fresh container the same pid
// may belong to another, living process.)
bool staleSegment(const std::string& shmName) {
  const int fd = ::shm_open(shmName.c_str(), O_RDONLY | O_CLOEXEC, 0);
  if (fd < 0) return false;
  const bool stale = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
  ::close(fd);  // also drops the lock just taken
  return stale;
}

}  // namespace

HwServer::HwServer(IoBoard& board, const std::string& name, double rateHz, double watchdogMs)
    : board_(board), name_(name), rateHz_(rateHz), watchdogMs_(watchdogMs) {
  if (!validName(name))
    throw IoException("HwServer: name '" + name +
                      "' is invalid (1 to 64 letters, digits, '-', '_' or '.')");
  if (!(rateHz >= 1.0 && rateHz <= 10000.0))
    throw IoException("HwServer: rate = " + std::to_string(rateHz) + " Hz (must be 1 .. 10000)");
  if (!(watchdogMs >= 1.0 && watchdogMs <= 60000.0))
    throw IoException("HwServer: watchdog = " + std::to_string(watchdogMs) + " ms (must be 1 .. 60000)");
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
  int err = errno;
  if (fd < 0 && err == EEXIST && staleSegment(shmName)) {
    ::shm_unlink(shmName.c_str());
    fd = ::shm_open(shmName.c_str(), O_CREAT | O_EXCL | O_RDWR | O_CLOEXEC, 0600);
    err = errno;
  }
  if (fd < 0)
    throw IoException("HwServer '" + name_ + "': cannot create shared memory " + shmName + ": " +
                      std::strerror(err) + (err == EEXIST ? " (another server of this name is running)" : ""));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {  // held until stop() or the process ends
    const int err = errno;
    ::close(fd);
    throw IoException("HwServer '" + name_ + "': cannot lock shared memory " + shmName + ": " + std::strerror(err) +
                      " (another server of this name is starting)");
  }
  if (::ftruncate(fd, sizeof(internal::HwServerShm)) != 0) {
    const int err = errno;
    ::close(fd);
    ::shm_unlink(shmName.c_str());
    throw IoException("HwServer '" + name_ + "': cannot size shared memory: " + std::strerror(err));
  }
  void* p = ::mmap(nullptr, sizeof(internal::HwServerShm), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (p == MAP_FAILED) {
    const int err = errno;
    ::close(fd);
    ::shm_unlink(shmName.c_str());
    errno = err;
    throw IoException("HwServer '" + name_ + "': cannot map shared memory: " + std::strerror(errno));
  }
  lockFd_ = fd;
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
  shm_->watchdogNs.store(static_cast<std::int64_t>(std::llround(watchdogMs_ * 1e6)));
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
  finalTrips_ = shm_->watchdogTrips.load();
  finalTripPid_ = shm_->lastTripPid.load();
  finalTripSilenceNs_ = shm_->lastTripSilenceNs.load();
  ::munmap(shm_, sizeof(internal::HwServerShm));
  shm_ = nullptr;
  ::shm_unlink(internal::hwServerShmName(name_).c_str());
  ::close(lockFd_);  // unlinked first: a new server of this name creates a fresh segment
  lockFd_ = -1;
}

std::uint64_t HwServer::cycles() const noexcept { return shm_ ? shm_->cycle.load() : finalCycles_; }
std::uint64_t HwServer::overruns() const noexcept { return shm_ ? shm_->overruns.load() : finalOverruns_; }
IoStatus HwServer::boardStatus() const noexcept {
  return shm_ ? static_cast<IoStatus>(shm_->boardStatus.load()) : IoStatus::kOk;
}
std::uint64_t HwServer::watchdogTrips() const noexcept { return shm_ ? shm_->watchdogTrips.load() : finalTrips_; }
int HwServer::lastWatchdogTrip(double& silenceMs) const noexcept {
  silenceMs = static_cast<double>(shm_ ? shm_->lastTripSilenceNs.load() : finalTripSilenceNs_) / 1e6;
  return shm_ ? shm_->lastTripPid.load() : finalTripPid_;
}

namespace {

using internal::HwClientState;

bool processGone(std::int32_t pid) { return pid <= 0 || (::kill(pid, 0) != 0 && errno == ESRCH); }

// A board answer that means the connection is lost (the rest of the cycle would only time out too),
// as opposed to a refusal of one operation.
bool connectionFailure(IoStatus s) {
  return s == IoStatus::kNotConnected || s == IoStatus::kTimeout || s == IoStatus::kProtocolError;
}

}  // namespace

bool HwServer::ownsOutputThatIsOn(int slot) const noexcept {
  const auto tag = static_cast<std::int8_t>(slot + 1);
  for (int i = 0; i < counts_[1]; ++i)
    if (shm_->digitalOutOwner[i].load() == tag && shm_->digitalOut[i].load() != 0) return true;
  for (int i = 0; i < counts_[3]; ++i)
    if (shm_->analogOutOwner[i].load() == tag && shm_->analogOut[i].load() != 0.0) return true;
  return false;
}

// The watchdog: a client silent for longer than the watchdog time with an output on is expired
// (its outputs go off below); a silent client whose process is gone is closed.
void HwServer::watchClients(std::int64_t now) {
  const std::int64_t limit = shm_->watchdogNs.load();
  const bool checkProcesses = shm_->cycle.load() % 64 == 0;  // kill(pid, 0) now and then, not every cycle
  for (int k = 0; k < internal::kHwServerMaxClients; ++k) {
    internal::HwClientSlot& c = shm_->clients[k];
    auto state = c.state.load();
    if (state == static_cast<std::int32_t>(HwClientState::kAttached)) {
      const std::int64_t silence = now - c.heartbeatNs.load();
      if (silence <= limit) continue;
      if (ownsOutputThatIsOn(k)) {
        if (c.state.compare_exchange_strong(state, static_cast<std::int32_t>(HwClientState::kExpired))) {
          shm_->lastTripPid.store(c.pid.load());
          shm_->lastTripSilenceNs.store(silence);
          shm_->watchdogTrips.fetch_add(1);
        }
      } else if (checkProcesses && processGone(c.pid.load())) {
        c.state.compare_exchange_strong(state, static_cast<std::int32_t>(HwClientState::kClosed));
      }
    } else if (state == static_cast<std::int32_t>(HwClientState::kExpired) && checkProcesses &&
               processGone(c.pid.load())) {
      c.state.compare_exchange_strong(state, static_cast<std::int32_t>(HwClientState::kClosed));
    }
  }
}

// An output whose owner is no longer attached (closed, expired, gone) is switched off in shared
// memory and loses its owner. The value is read before the owner: a client stores the owner
// first, so a value written by a client that has just expired is seen with that client's tag.
template <typename T>
bool HwServer::forceOffIfOrphaned(std::atomic<T>& value, std::atomic<std::int8_t>& owner, T& v) noexcept {
  v = value.load();
  std::int8_t o = owner.load();
  if (o <= 0 || o > internal::kHwServerMaxClients) return false;
  if (shm_->clients[o - 1].state.load() == static_cast<std::int32_t>(HwClientState::kAttached)) return false;
  T expected = v;
  value.compare_exchange_strong(expected, T{});  // fails only if a live client wrote meanwhile
  owner.compare_exchange_strong(o, 0);
  v = T{};  // off this cycle in any case; a live client's new value follows in the next
  return true;
}

void HwServer::reportWrite(std::atomic<std::uint32_t>& done, std::atomic<std::int32_t>& result, std::uint32_t request,
                           IoStatus status) noexcept {
  if (done.load() == request) return;
  if (status != IoStatus::kOk) {
    shm_->writeMessageSeq.fetch_add(1, std::memory_order_acq_rel);  // sequence lock, as for `message`
    std::snprintf(shm_->writeMessage, sizeof shm_->writeMessage, "%s", board_.lastError());
    shm_->writeMessageSeq.fetch_add(1, std::memory_order_release);
  }
  result.store(static_cast<std::int32_t>(status));
  done.store(request, std::memory_order_release);  // the client reads done, then result
}

void HwServer::cycle(bool writeAll) {
  watchClients(internal::monotonicNs());
  IoStatus status = IoStatus::kOk;  // the first connection failure of this cycle
  // Outputs first (a client's command reaches the board as early as possible), then inputs.
  // After a connection failure the board is not touched again this cycle (a board that is gone
  // would otherwise cost one timeout per line), and pending writes are answered with it.
  for (int i = 0; i < counts_[1]; ++i) {
    const std::uint32_t request = shm_->digitalOutRequest[i].load(std::memory_order_acquire);
    std::uint8_t raw = 0;
    forceOffIfOrphaned(shm_->digitalOut[i], shm_->digitalOutOwner[i], raw);
    const bool v = raw != 0;
    const bool retry = request != shm_->digitalOutDone[i].load() && lastDigitalResult_[i] != IoStatus::kOk;
    IoStatus s = status;
    if (s == IoStatus::kOk && (writeAll || v != lastDigitalOut_[i] || retry)) {
      s = board_.writeDigitalOutput(i, v);
      lastDigitalResult_[i] = s;
      if (s == IoStatus::kOk) {
        lastDigitalOut_[i] = v;
        shm_->digitalOutApplied[i].store(v ? 1 : 0);
      } else if (connectionFailure(s)) {
        status = s;
      }
    }
    reportWrite(shm_->digitalOutDone[i], shm_->digitalOutResult[i], request, s);
  }
  for (int i = 0; i < counts_[3]; ++i) {
    const std::uint32_t request = shm_->analogOutRequest[i].load(std::memory_order_acquire);
    double v = 0;
    forceOffIfOrphaned(shm_->analogOut[i], shm_->analogOutOwner[i], v);
    const bool retry = request != shm_->analogOutDone[i].load() && lastAnalogResult_[i] != IoStatus::kOk;
    IoStatus s = status;
    if (s == IoStatus::kOk && (writeAll || v != lastAnalogOut_[i] || retry)) {
      s = board_.writeAnalogOutput(i, v);
      lastAnalogResult_[i] = s;
      if (s == IoStatus::kOk) {
        lastAnalogOut_[i] = v;
        shm_->analogOutApplied[i].store(v);
      } else if (connectionFailure(s)) {
        status = s;
      }
    }
    reportWrite(shm_->analogOutDone[i], shm_->analogOutResult[i], request, s);
  }
  // Closed clients own no line any more (switched off above): their slots are free again.
  for (auto& c : shm_->clients) {
    auto closed = static_cast<std::int32_t>(HwClientState::kClosed);
    c.state.compare_exchange_strong(closed, static_cast<std::int32_t>(HwClientState::kFree));
  }
  auto ok = [&](IoStatus s) {
    if (s != IoStatus::kOk && status == IoStatus::kOk) status = s;
    return s == IoStatus::kOk;
  };
  shm_->inputSeq.fetch_add(1, std::memory_order_acq_rel);  // odd: the inputs are being stored
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
  // Stamped when the reads have returned: a read held up (a slow board, the server descheduled)
  // returns the inputs of when it returned, not of when it began.
  shm_->inputTimeNs.store(internal::monotonicNs());
  shm_->inputSeq.fetch_add(1, std::memory_order_release);
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
