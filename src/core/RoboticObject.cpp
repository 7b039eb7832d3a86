// RoboticObject: registration, name, error status, commands, shutdown, GUI defaults.
#include "rp/core/RoboticObject.hpp"

#include <cxxabi.h>
#include <pthread.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <cmath>
#include <stdexcept>
#include <thread>
#include <typeindex>

#include "Registry.hpp"
#include "rp/core/Configuration.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/core/PhysicalObject.hpp"
#include "rp/core/TypeDatabase.hpp"
#include "rp/rt/ControlProgram.hpp"

namespace rp {

namespace internal {

std::string demangleName(const char* mangled) {
  int status = 0;
  char* d = abi::__cxa_demangle(mangled, nullptr, nullptr, &status);
  std::string name = (status == 0 && d) ? d : mangled;
  std::free(d);
  // Drop namespaces (but keep template arguments intact).
  std::size_t angle = name.find('<');
  std::size_t colon = name.rfind("::", angle == std::string::npos ? std::string::npos : angle);
  if (colon != std::string::npos) name = name.substr(colon + 2);
  return name;
}

// The references the calling thread holds (withdrawObject() does not wait for its own thread's).
thread_local std::vector<const RoboticObject*> heldReferences;

}  // namespace internal

struct RoboticObject::Impl {
  std::string name;
  bool automatic = false;
  std::uint64_t id = 0;
  std::shared_ptr<const Configuration> configuration;  // keeps `section` alive
  const ConfigSection* section = nullptr;
  std::string configuredClass;  // named by the constructor (ClassSection), or empty

  // Error status: a tiny spin lock taken with a bounded number of attempts by writers.
  mutable std::atomic_flag errorLock = ATOMIC_FLAG_INIT;
  std::atomic<int> errorCode{0};
  char errorMessage[256] = {};

  std::atomic<bool> shuttingDown{false};
  std::atomic<bool> shutdownComplete{false};

  // Publication to other threads: 0 not yet published, 1 published, 2 withdrawn. `references`
  // counts the ObjectReferences held; withdrawObject() waits for it to drop (Registry::referenceCv).
  std::atomic<int> publication{0};
  std::atomic<int> references{0};
  std::thread::id constructor;           // the thread that constructed the object
  const RoboticObject* parent = nullptr;  // published with this object (with the registry lock)

  // Additional threads (addThread()): started by startControlLoop(), stopped by stopControlLoop().
  struct ExtraThread {
    std::string name;
    std::function<void(const std::atomic<bool>&)> body;
    std::thread thread;
  };
  mutable std::mutex threadMutex;
  std::vector<ExtraThread> threads;
  std::atomic<bool> threadsStarted{false};
  std::atomic<bool> stopThreads{false};

  std::atomic<bool> qmotorApplied{false};  // applyQMotorConfigFile() has run

  std::mutex commandMutex;
  struct Command {
    std::string name, description;
    std::function<std::string()> action;
  };
  std::vector<Command> commands;
};

RoboticObject::RoboticObject(const std::string& name) : impl_(std::make_unique<Impl>()) {
  auto& reg = internal::registry();
  impl_->automatic = name.empty();
  impl_->configuration = internal::currentConfiguration();
  // The section named after the object wins; without one, the section named after its class.
  if (const char* className = ClassSection::claim()) impl_->configuredClass = className;
  if (!name.empty()) impl_->section = impl_->configuration->findSection(name);
  if (impl_->section == nullptr && !impl_->configuredClass.empty())
    impl_->section = impl_->configuration->findClassSection(impl_->configuredClass);
  {
    std::lock_guard<std::recursive_mutex> lock(reg.mutex);
    if (!name.empty())
      for (RoboticObject* o : reg.objects)
        if (o->impl_->name == name)
          throw std::invalid_argument("RoboticObject: an object named '" + name + "' already exists");
    impl_->id = reg.nextId.fetch_add(1);
    impl_->constructor = std::this_thread::get_id();
    // Automatic names do not depend on the class: other threads may list the object while it is
    // still being constructed, when its dynamic class is not yet known.
    impl_->name = name.empty() ? "object_" + std::to_string(impl_->id) : name;
    reg.objects.push_back(this);
  }
  internal::ensureShutdownWatcher();
}

RoboticObject::~RoboticObject() {
  withdrawObject();  // normally done already by the most-derived destructor
  stopThreads();     // likewise (by stopControlLoop())
  auto& reg = internal::registry();
  std::lock_guard<std::recursive_mutex> lock(reg.mutex);
  reg.objects.erase(std::remove(reg.objects.begin(), reg.objects.end(), this), reg.objects.end());
}

void RoboticObject::declareSettings(SettingSchema&) {}

std::string RoboticObject::getName() const { return impl_->name; }

bool RoboticObject::hasAutomaticName() const noexcept { return impl_->automatic; }

std::string RoboticObject::getClassName() const {
  if (const TypeInfo* info = TypeDatabase::instance().find(std::type_index(typeid(*this)))) return info->name;
  return internal::demangleName(typeid(*this).name());
}

const ConfigSection* RoboticObject::configSection() const noexcept { return impl_->section; }

std::string RoboticObject::getConfiguredClass() const { return impl_->configuredClass; }

void RoboticObject::setError(int code, const char* message) noexcept {
  // Bounded attempts: a real-time writer never waits long for a non-real-time one.
  for (int attempt = 0; attempt < 1000; ++attempt) {
    if (!impl_->errorLock.test_and_set(std::memory_order_acquire)) {
      std::size_t n = message ? std::strlen(message) : 0;
      n = std::min(n, sizeof(impl_->errorMessage) - 1);
      if (n) std::memcpy(impl_->errorMessage, message, n);
      impl_->errorMessage[n] = '\0';
      impl_->errorCode.store(code, std::memory_order_relaxed);
      impl_->errorLock.clear(std::memory_order_release);
      return;
    }
  }
  impl_->errorCode.store(code, std::memory_order_relaxed);  // message dropped, code kept
}

int RoboticObject::getErrorCode() const noexcept { return impl_->errorCode.load(std::memory_order_relaxed); }

ErrorStatus RoboticObject::getErrorStatus() const {
  while (impl_->errorLock.test_and_set(std::memory_order_acquire)) std::this_thread::yield();
  ErrorStatus status{impl_->errorCode.load(std::memory_order_relaxed), impl_->errorMessage};
  impl_->errorLock.clear(std::memory_order_release);
  return status;
}

void RoboticObject::addCommand(const std::string& name, std::function<void()> action, const std::string& description) {
  if (!action) throw std::invalid_argument("addCommand: no action for '" + name + "' of " + getName());
  addCommandWithResult(name, [action = std::move(action)] {
    action();
    return std::string("done");
  }, description);
}

void RoboticObject::addCommandWithResult(const std::string& name, std::function<std::string()> action,
                                         const std::string& description) {
  if (!action) throw std::invalid_argument("addCommand: no action for '" + name + "' of " + getName());
  std::lock_guard<std::mutex> lock(impl_->commandMutex);
  for (const auto& c : impl_->commands)
    if (c.name == name) throw std::invalid_argument("addCommand: '" + name + "' is already a command of " + getName());
  impl_->commands.push_back({name, description, std::move(action)});
}

bool RoboticObject::removeCommand(const std::string& name) {
  std::lock_guard<std::mutex> lock(impl_->commandMutex);
  auto& commands = impl_->commands;
  const auto it = std::find_if(commands.begin(), commands.end(), [&](const auto& c) { return c.name == name; });
  if (it == commands.end()) return false;
  commands.erase(it);
  return true;
}

std::vector<CommandInfo> RoboticObject::getCommands() const {
  std::lock_guard<std::mutex> lock(impl_->commandMutex);
  std::vector<CommandInfo> out;
  for (const auto& c : impl_->commands) out.push_back({c.name, c.description});
  return out;
}

std::string RoboticObject::commandResult(bool ok, const std::string& done) const {
  if (ok) return done;
  const ErrorStatus status = getErrorStatus();
  throw std::runtime_error(status.message.empty() ? getName() + ": the device did not carry the command out"
                                                  : status.message);
}

std::string RoboticObject::executeCommand(const std::string& name) {
  std::function<std::string()> action;
  {
    std::lock_guard<std::mutex> lock(impl_->commandMutex);
    std::string known;
    for (const auto& c : impl_->commands) {
      if (c.name == name) action = c.action;
      known += (known.empty() ? "" : ", ") + c.name;
    }
    if (!action)
      throw std::invalid_argument("executeCommand: " + getName() + " has no command '" + name +
                                  "' (known: " + (known.empty() ? "none" : known) + ")");
  }
  return action();
}

void RoboticObject::startShutdown() {
  impl_->shuttingDown.store(true);
  if (ControlProgram* p = getControlProgram()) p->requestStop();
  setShutdownComplete();
}

bool RoboticObject::isShutdownComplete() const { return impl_->shutdownComplete.load(); }

bool RoboticObject::isShuttingDown() const noexcept { return impl_->shuttingDown.load(); }

void RoboticObject::setShutdownComplete() noexcept {
  impl_->shuttingDown.store(true);
  impl_->shutdownComplete.store(true);
}

void RoboticObject::requestSystemShutdown(const char* reason) noexcept { ObjectManager::requestSystemShutdown(reason); }

ControlPanel RoboticObject::getControlPanel() const {
  ControlPanel panel;
  panel.title = getName() + " (" + getClassName() + ")";
  ControlPanelField error;
  error.name = "errorCode";
  error.label = "Error code";
  error.kind = FieldKind::Number;
  panel.fields.push_back(error);
  // The tunable parameters of the object's control loop, editable through setParameter().
  if (ControlProgram* program = const_cast<RoboticObject*>(this)->getControlProgram()) {
    for (const ParameterInfo& p : program->getParameters()) {
      panel.fields.push_back(ControlPanelField{p.name, p.description.empty() ? p.name : p.description,
                                               p.size > 1 ? FieldKind::Vector : FieldKind::Number,
                                               static_cast<int>(p.size), p.unit, p.min, p.max, true, -1, {}});
    }
  }
  return panel;
}

bool RoboticObject::getStateSnapshot(StateSnapshot&) const { return false; }

bool RoboticObject::handleMessage(const std::string&, const std::string&, std::string& reply) {
  reply.clear();
  return false;
}

void RoboticObject::applyQMotorConfigFile() {
  if (impl_->qmotorApplied.exchange(true)) return;
  const ConfigSection* section = configSection();
  if (section == nullptr) return;
  // The executor settings (`thread own|shared`, `cpu N`): only for an object with a control program.
  for (const char* name : {"thread", "cpu"}) {
    const ConfigSetting* line = section->find(name);
    if (line == nullptr) continue;
    ControlProgram* p = getControlProgram();
    if (p == nullptr)
      throw section->errorAt(*line, std::string("setting '") + name + "': " + getName() + " (" + getClassName() +
                                        ") runs no control program, so it has no thread to choose or pin");
    if (std::string(name) == "thread") {
      p->setThreadMode(line->values.at(0) == "own" ? ThreadMode::Own : ThreadMode::Shared);
    } else {
      p->setCpuAffinity(std::stoi(line->values.at(0)));
    }
  }
  if (section->qmotorConfig() == nullptr) return;
  ControlProgram* p = getControlProgram();
  if (p == nullptr) {
    const ConfigSetting* line = section->find("qmotorConfig");
    const std::string what = "setting 'qmotorConfig': " + getName() + " (" + getClassName() +
                             ") runs no control program, so nothing would apply '" +
                             section->qmotorConfig()->fileName() +
                             "' (only a class that runs one, e.g. derived from ControlProgram, takes the file)";
    if (line != nullptr) throw section->errorAt(*line, what);
    throw ConfigError(section->fileName(), section->line(), what);
  }
  p->applyQMotorConfig(*section->qmotorConfig());
}

std::string RoboticObject::getQMotorConfigFile() const {
  const ConfigSection* section = configSection();
  return section != nullptr && section->qmotorConfig() != nullptr ? section->qmotorConfig()->fileName() : std::string();
}

std::string RoboticObject::getQMotorConfigFolder() const {
  const std::string file = getQMotorConfigFile();
  const ConfigSection* section = configSection();
  const std::string from = !file.empty() ? file : section != nullptr ? section->fileName() : std::string();
  if (from.empty()) return {};
  std::filesystem::path folder = std::filesystem::path(from).parent_path();
  if (folder.empty()) folder = ".";
  return folder.string();
}

namespace {
ControlProgram& programOf(RoboticObject& o) {
  ControlProgram* p = o.getControlProgram();
  if (p == nullptr) throw std::invalid_argument(o.getName() + " (" + o.getClassName() + ") runs no control program");
  return *p;
}
}  // namespace

std::string RoboticObject::stopControlProgram() {
  ControlProgram& p = programOf(*this);
  if (!p.isRunning()) throw std::logic_error(getName() + ": the control program is not running");
  p.stop();
  return getName() + ": control program stopped after " + std::to_string(p.getCycleCount()) + " cycles";
}

std::string RoboticObject::startControlProgram() {
  ControlProgram& p = programOf(*this);
  if (p.isRunning()) throw std::logic_error(getName() + ": the control program is running already");
  if (ObjectManager::isShutdownRequested())
    throw std::logic_error(getName() + ": the system is shutting down (" + ObjectManager::getShutdownReason() + ")");
  if (isShuttingDown()) throw std::logic_error(getName() + ": the object is shutting down");
  if (!isObjectPublished()) throw std::logic_error(getName() + ": the object is being constructed or destroyed");
  if (const ErrorStatus e = getErrorStatus(); e.code != 0)
    throw std::logic_error(getName() + ": the object has an error (" + std::to_string(e.code) + ": " + e.message + ")");
  p.start();
  return getName() + ": control program started at " + std::to_string(static_cast<long long>(std::lround(p.getRate()))) +
         " Hz";
}

std::string RoboticObject::restartControlProgram() {
  ControlProgram& p = programOf(*this);
  std::string stopped;
  if (p.isRunning()) stopped = stopControlProgram() + "; ";
  return stopped + startControlProgram();
}

void RoboticObject::startControlLoop() {
  if (ControlProgram* p = getControlProgram())
    if (p->getProgramName() == "control" && !p->isRunning()) p->setProgramName(getName());
  applyQMotorConfigFile();
  if (ControlProgram* p = getControlProgram()) {
    if (!p->isRunning() && !impl_->threadsStarted.load()) p->start();  // once: a stopped loop stays stopped
  }
  startThreads();
  publishObject();  // the most-derived constructor calls this last: the object is complete
}

void RoboticObject::stopControlLoop() {
  beforeControlLoopStops();  // e.g. a manipulator's hold until the arm is at rest
  withdrawObject();  // the destructors call this first: other threads keep off from here on
  if (ControlProgram* p = getControlProgram()) p->stop();
  stopThreads();
}

namespace {
void runThread(const std::string& name, const std::function<void(const std::atomic<bool>&)>& body,
               const std::atomic<bool>& stop, RoboticObject& object) {
  const std::string shortName = name.substr(0, 15);
  pthread_setname_np(pthread_self(), shortName.c_str());
  try {
    body(stop);
  } catch (const std::exception& e) {
    object.setError(1, (object.getName() + ": thread '" + name + "' failed: " + e.what()).c_str());
  } catch (...) {
    object.setError(1, (object.getName() + ": thread '" + name + "' failed").c_str());
  }
}
}  // namespace

void RoboticObject::addThread(const std::string& name, std::function<void(const std::atomic<bool>& stop)> body) {
  if (!body) throw std::invalid_argument("addThread: no function for thread '" + name + "' of " + getName());
  std::lock_guard<std::mutex> lock(impl_->threadMutex);
  impl_->threads.push_back({name, std::move(body), {}});
  if (impl_->threadsStarted.load() && !impl_->stopThreads.load()) {
    auto& t = impl_->threads.back();
    t.thread = std::thread(runThread, t.name, t.body, std::cref(impl_->stopThreads), std::ref(*this));
  }
}

void RoboticObject::addPeriodicThread(const std::string& name, double periodSeconds, std::function<void()> cycle) {
  if (!(periodSeconds > 0 && periodSeconds <= 3600))
    throw std::invalid_argument("addPeriodicThread: the period of thread '" + name + "' of " + getName() +
                                " must be more than 0 and at most 3600 s, got " + std::to_string(periodSeconds));
  if (!cycle) throw std::invalid_argument("addPeriodicThread: no function for thread '" + name + "' of " + getName());
  const long long periodNs = static_cast<long long>(periodSeconds * 1e9) > 0 ? static_cast<long long>(periodSeconds * 1e9) : 1;
  addThread(name, [periodNs, cycle = std::move(cycle)](const std::atomic<bool>& stop) {
    timespec next{};
    clock_gettime(CLOCK_MONOTONIC, &next);
    auto advance = [&](timespec& t) {
      const long long ns = static_cast<long long>(t.tv_nsec) + periodNs;
      t.tv_sec += static_cast<time_t>(ns / 1000000000LL);
      t.tv_nsec = static_cast<long>(ns % 1000000000LL);
    };
    while (!stop.load(std::memory_order_acquire)) {
      cycle();
      advance(next);
      timespec now{};
      clock_gettime(CLOCK_MONOTONIC, &now);
      if (now.tv_sec > next.tv_sec || (now.tv_sec == next.tv_sec && now.tv_nsec > next.tv_nsec)) {
        next = now;  // late: the next cycle starts now, the missed ones are not repeated
        continue;
      }
      // Sleep in slices of at most 50 ms, so a stop request is seen soon even with a long period.
      while (!stop.load(std::memory_order_acquire)) {
        timespec slice = now;
        const long long ns = static_cast<long long>(slice.tv_nsec) + 50000000LL;
        slice.tv_sec += static_cast<time_t>(ns / 1000000000LL);
        slice.tv_nsec = static_cast<long>(ns % 1000000000LL);
        const bool last = slice.tv_sec > next.tv_sec || (slice.tv_sec == next.tv_sec && slice.tv_nsec >= next.tv_nsec);
        const timespec until = last ? next : slice;
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &until, nullptr) == EINTR) {
        }
        if (last) break;
        now = until;
      }
    }
  });
}

std::vector<std::string> RoboticObject::getThreadNames() const {
  std::lock_guard<std::mutex> lock(impl_->threadMutex);
  std::vector<std::string> names;
  for (const auto& t : impl_->threads) names.push_back(t.name);
  return names;
}

bool RoboticObject::areThreadsRunning() const noexcept {
  return impl_->threadsStarted.load() && !impl_->stopThreads.load();
}

void RoboticObject::startThreads() {
  std::lock_guard<std::mutex> lock(impl_->threadMutex);
  if (impl_->threadsStarted.exchange(true) || impl_->stopThreads.load()) return;
  for (auto& t : impl_->threads)
    if (!t.thread.joinable())
      t.thread = std::thread(runThread, t.name, t.body, std::cref(impl_->stopThreads), std::ref(*this));
}

void RoboticObject::stopThreads() noexcept {
  std::vector<std::thread> running;
  {
    std::lock_guard<std::mutex> lock(impl_->threadMutex);
    impl_->stopThreads.store(true, std::memory_order_release);
    for (auto& t : impl_->threads)
      if (t.thread.joinable()) running.push_back(std::move(t.thread));
  }
  for (auto& t : running)
    if (t.get_id() != std::this_thread::get_id()) t.join();
    else t.detach();  // a thread stopping its own object
}

void RoboticObject::publishObject() noexcept {
  auto& reg = internal::registry();
  const std::thread::id self = std::this_thread::get_id();
  std::lock_guard<std::recursive_mutex> lock(reg.mutex);
  if (impl_->constructor == self) {
    // Objects this thread registered after this one and has not published are complete (they
    // were constructed inside this object's constructor, e.g. its members, or after it): they
    // are published with it, and withdrawn with it.
    for (RoboticObject* o : reg.objects)
      if (o->impl_->id > impl_->id && o->impl_->constructor == self && o->impl_->publication.load() == 0) {
        o->impl_->parent = this;
        o->impl_->publication.store(1, std::memory_order_seq_cst);
      }
  }
  impl_->publication.store(1, std::memory_order_seq_cst);
}

void RoboticObject::withdrawObject() noexcept {
  auto& reg = internal::registry();
  std::vector<RoboticObject*> withdrawn{this};
  {
    std::lock_guard<std::recursive_mutex> lock(reg.mutex);
    impl_->publication.store(2, std::memory_order_seq_cst);
    for (RoboticObject* o : reg.objects)  // the objects published with this one go with it
      if (o->impl_->parent == this && o->impl_->publication.load() == 1) {
        o->impl_->publication.store(2, std::memory_order_seq_cst);
        withdrawn.push_back(o);
      }
  }
  // Every reference taken before the stores is released before we go on; a reference attempted
  // after them sees `2` and is given back at once (tryReference: increment, then check).
  const auto& held = internal::heldReferences;
  std::unique_lock<std::mutex> lock(reg.referenceMutex);
  for (RoboticObject* o : withdrawn) {
    const int own = static_cast<int>(std::count(held.begin(), held.end(), o));
    reg.referenceCv.wait(lock, [&] { return o->impl_->references.load(std::memory_order_seq_cst) <= own; });
  }
}

bool RoboticObject::isObjectPublished() const noexcept { return impl_->publication.load() == 1; }

bool RoboticObject::isWithdrawn() const noexcept { return impl_->publication.load() == 2; }

bool RoboticObject::tryReference() noexcept {
  impl_->references.fetch_add(1, std::memory_order_seq_cst);
  if (impl_->publication.load(std::memory_order_seq_cst) != 1) {
    auto& reg = internal::registry();
    {
      std::lock_guard<std::mutex> lock(reg.referenceMutex);
      impl_->references.fetch_sub(1, std::memory_order_seq_cst);
    }
    reg.referenceCv.notify_all();
    return false;
  }
  try {
    internal::heldReferences.push_back(this);
  } catch (...) {
    releaseReference();
    return false;
  }
  return true;
}

void RoboticObject::releaseReference() noexcept {
  auto& held = internal::heldReferences;
  auto it = std::find(held.rbegin(), held.rend(), this);
  if (it != held.rend()) held.erase(std::next(it).base());
  auto& reg = internal::registry();
  {
    // Under the mutex: a withdrawing thread checks the count under it too, so it cannot go on
    // (and destroy the object) before this decrement is done.
    std::lock_guard<std::mutex> lock(reg.referenceMutex);
    impl_->references.fetch_sub(1, std::memory_order_seq_cst);
  }
  reg.referenceCv.notify_all();  // the object may be gone now: only the registry is used
}

ObjectInfo RoboticObject::getInfo() {
  return ObjectInfo{getName(), getClassName(), dynamic_cast<PhysicalObject*>(this) != nullptr, needsControlLoop()};
}

}  // namespace rp
