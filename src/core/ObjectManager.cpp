// ObjectManager: object registry, creation by name, system shutdown.
#include "rp/core/ObjectManager.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

#include "Registry.hpp"
#include "rp/core/RoboticPlatform.hpp"
#include "rp/rt/ControlProgram.hpp"
#include "rp/rt/LogWriter.hpp"

namespace rp {

namespace internal {

Registry::Registry() { sem_init(&semaphore, 0, 0); }

Registry& registry() {
  static Registry* r = new Registry;  // never destroyed: the watcher thread and exit handlers use it
  return *r;
}

std::shared_ptr<const Configuration> currentConfiguration() {
  auto& reg = registry();
  std::lock_guard<std::mutex> lock(reg.configMutex);
  return reg.configuration;
}

namespace {

void writeStderr(const std::string& text) {
  std::fputs(text.c_str(), stderr);
  std::fflush(stderr);
}

// The manager's thread: waits for a shutdown request and carries it out.
void watcher() {
  auto& reg = registry();
  for (;;) {
    while (sem_wait(&reg.semaphore) != 0) {
    }
    if (reg.requested.load() == 0) continue;
    while (!reg.reasonReady.load(std::memory_order_acquire)) std::this_thread::yield();
    const std::string reason = reg.reason;
    writeStderr("rp: system shutdown: " + reason + "\n");
    auto pending = ObjectManager().shutdownAllObjects(reason);
    ControlProgram::stopAll();
    LogWriter::closePlatformWriter();
    if (pending.empty()) {
      writeStderr("rp: system shutdown complete\n");
    } else {
      std::string names;
      for (auto& n : pending) names += (names.empty() ? "" : ", ") + n;
      writeStderr("rp: system shutdown timed out waiting for: " + names + "\n");
    }
    {
      std::lock_guard<std::mutex> lock(reg.doneMutex);
      reg.done = true;
      reg.shutdownComplete.store(true);  // (with `done`: a resetShutdown() cannot come between)
    }
    reg.doneCv.notify_all();
    if (int sig = reg.signalNumber.load()) {
      std::fflush(stderr);  // not stdout: a main thread blocked writing to a full pipe may hold its lock
      _exit(128 + sig);
    }
  }
}

}  // namespace

void ensureShutdownWatcher() {
  auto& reg = registry();
  std::call_once(reg.watcherStarted, [] { std::thread(watcher).detach(); });
}

}  // namespace internal

std::vector<RoboticObject*> ObjectManager::getObjects() const {
  auto& reg = internal::registry();
  std::lock_guard<std::recursive_mutex> lock(reg.mutex);
  return reg.objects;
}

RoboticObject* ObjectManager::findObject(const std::string& name) const {
  auto& reg = internal::registry();
  std::lock_guard<std::recursive_mutex> lock(reg.mutex);
  for (RoboticObject* o : reg.objects)
    if (o->getName() == name) return o;
  return nullptr;
}

std::vector<ObjectReference> ObjectManager::getPublishedObjects() const {
  std::vector<ObjectReference> out;
  getPublishedObjects(out);
  return out;
}

void ObjectManager::getPublishedObjects(std::vector<ObjectReference>& out) const {
  out.clear();  // the references held from the last call go before the lock is taken
  auto& reg = internal::registry();
  std::lock_guard<std::recursive_mutex> lock(reg.mutex);  // keeps every listed object's base alive
  out.reserve(reg.objects.size());
  for (RoboticObject* o : reg.objects)
    if (o->tryReference()) out.push_back(ObjectReference(o));
}

ObjectReference ObjectManager::findPublishedObject(const std::string& name) const {
  auto& reg = internal::registry();
  std::lock_guard<std::recursive_mutex> lock(reg.mutex);
  for (RoboticObject* o : reg.objects)
    if (o->getName() == name) return o->tryReference() ? ObjectReference(o) : ObjectReference();
  return {};
}

std::vector<std::string> ObjectManager::getObjectNames() const {
  auto& reg = internal::registry();
  std::lock_guard<std::recursive_mutex> lock(reg.mutex);
  std::vector<std::string> out;
  out.reserve(reg.objects.size());
  for (RoboticObject* o : reg.objects) out.push_back(o->getName());
  return out;
}

std::vector<ObjectInfo> ObjectManager::getObjectList() const {
  std::vector<ObjectInfo> out;
  forEachObject([&](RoboticObject& o) { out.push_back(o.getInfo()); });
  return out;
}

void ObjectManager::forEachObject(const std::function<void(RoboticObject&)>& f) const {
  auto& reg = internal::registry();
  std::lock_guard<std::recursive_mutex> lock(reg.mutex);
  for (RoboticObject* o : reg.objects) f(*o);
}

std::string ObjectManager::demangle(const char* mangled) { return internal::demangleName(mangled); }

const TypeInfo& ObjectManager::checkedClass(const std::string& name, const std::string& baseName,
                                            const std::function<bool(const TypeInfo&)>& derives) const {
  auto cfg = internal::currentConfiguration();
  const ConfigSection* section = cfg->findSection(name);
  const std::string file = cfg->fileName().empty() ? RoboticPlatform::getConfigurationFileName() : cfg->fileName();
  if (!section)
    throw ObjectError(file + ": no section [" + name + "] (sections: " + cfg->sectionNames() + ")");
  const TypeInfo* info = TypeDatabase::instance().find(section->className());
  if (!info)
    throw ObjectError(file + ":" + std::to_string(section->classLine()) + ": class '" + section->className() +
                      "' is not known (known: " + TypeDatabase::instance().knownNames() + ")");
  if (!derives(*info))
    throw ObjectError(file + ":" + std::to_string(section->classLine()) + ": object '" + name + "' is of class " +
                      section->className() + ", which is not a " + baseName);
  return *info;
}

RoboticObject* ObjectManager::create(const TypeInfo& info, const std::string& name) {
  std::unique_ptr<RoboticObject> object(info.create(name));
  RoboticObject* raw = object.get();
  raw->startControlLoop();  // the most-derived constructor has returned: start its threads, publish it
  auto& reg = internal::registry();
  std::lock_guard<std::recursive_mutex> lock(reg.mutex);
  reg.owned.push_back(std::move(object));
  return raw;
}

std::vector<RoboticObject*> ObjectManager::createAllObjects() {
  std::vector<RoboticObject*> out;
  auto cfg = internal::currentConfiguration();
  for (const auto& section : cfg->sections())
    if (!section.isClassSection()) out.push_back(createObject(section.name()));
  return out;
}

RoboticObject* ObjectManager::createClassObject(const std::string& className) {
  const TypeInfo* info = TypeDatabase::instance().find(className);
  if (!info)
    throw ObjectError("class '" + className + "' is not known (known: " + TypeDatabase::instance().knownNames() + ")");
  return create(*info, "");
}

void ObjectManager::deleteObject(RoboticObject* object) {
  std::unique_ptr<RoboticObject> victim;
  {
    auto& reg = internal::registry();
    std::lock_guard<std::recursive_mutex> lock(reg.mutex);
    auto it = std::find_if(reg.owned.begin(), reg.owned.end(), [&](auto& p) { return p.get() == object; });
    if (it == reg.owned.end())
      throw std::invalid_argument("ObjectManager::deleteObject: the object was not created by the object manager");
    victim = std::move(*it);
    reg.owned.erase(it);
  }
  victim->withdrawObject();  // before its destruction begins (waits for other threads' references)
  victim.reset();            // outside the lock: its destructor may stop a thread
}

void ObjectManager::deleteAllObjects() {
  std::vector<std::unique_ptr<RoboticObject>> victims;
  {
    auto& reg = internal::registry();
    std::lock_guard<std::recursive_mutex> lock(reg.mutex);
    victims.swap(reg.owned);
  }
  while (!victims.empty()) {  // newest first
    victims.back()->withdrawObject();
    victims.pop_back();
  }
}

void ObjectManager::requestSystemShutdown(const char* reason) noexcept {
  auto& reg = internal::registry();
  int expected = 0;
  if (!reg.requested.compare_exchange_strong(expected, 1)) return;  // only the first request counts
  std::size_t i = 0;
  if (reason)
    for (; reason[i] != '\0' && i + 1 < sizeof(reg.reason); ++i) reg.reason[i] = reason[i];
  reg.reason[i] = '\0';
  reg.reasonReady.store(true, std::memory_order_release);
  sem_post(&reg.semaphore);  // async-signal-safe, never blocks
}

bool ObjectManager::isShutdownRequested() noexcept { return internal::registry().requested.load() != 0; }

bool ObjectManager::waitForShutdown(double timeoutSeconds) {
  auto& reg = internal::registry();
  internal::ensureShutdownWatcher();
  std::unique_lock<std::mutex> lock(reg.doneMutex);
  if (timeoutSeconds < 0) {
    reg.doneCv.wait(lock, [&] { return reg.done; });
    return true;
  }
  return reg.doneCv.wait_for(lock, std::chrono::duration<double>(timeoutSeconds), [&] { return reg.done; });
}

std::string ObjectManager::getShutdownReason() {
  auto& reg = internal::registry();
  // Under the lock of resetShutdown(): a reason is copied whole, never while a reset begins a new
  // generation (the one request of a generation writes the reason before it is ready).
  std::lock_guard<std::mutex> lock(reg.doneMutex);
  return reg.reasonReady.load(std::memory_order_acquire) ? std::string(reg.reason) : std::string();
}

std::vector<std::string> ObjectManager::shutdownAllObjects(const std::string& reason) {
  (void)reason;
  auto& reg = internal::registry();
  // The registry stays locked, and published objects are held by references: their destruction
  // cannot begin halfway through their shutdown (it waits). Objects being destroyed (withdrawn)
  // are left to their destructors; objects never published are shut down as they are.
  std::lock_guard<std::recursive_mutex> lock(reg.mutex);
  std::vector<ObjectReference> held;
  std::vector<RoboticObject*> objects;
  for (RoboticObject* o : reg.objects) {
    if (o->tryReference()) {
      held.push_back(ObjectReference(o));
      objects.push_back(o);
    } else if (!o->isWithdrawn()) {
      objects.push_back(o);
    }
  }
  for (RoboticObject* o : objects) {
    try {
      o->startShutdown();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "rp: %s: startShutdown failed: %s\n", o->getName().c_str(), e.what());
    }
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(reg.timeoutSeconds.load());
  std::vector<std::string> pending;
  for (;;) {
    pending.clear();
    for (RoboticObject* o : objects)
      if (!o->isShutdownComplete()) pending.push_back(o->getName());
    if (pending.empty() || std::chrono::steady_clock::now() >= deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return pending;
}

void ObjectManager::setShutdownTimeout(double seconds) { internal::registry().timeoutSeconds = seconds; }

void ObjectManager::resetShutdown() {
  auto& reg = internal::registry();
  std::lock_guard<std::mutex> lock(reg.doneMutex);
  reg.done = false;
  reg.shutdownComplete.store(false);
  reg.reasonReady = false;  // the reason's text stays until the next request writes it
  reg.requested = 0;
}

}  // namespace rp
