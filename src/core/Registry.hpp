// Process-wide state shared by RoboticObject, ObjectManager and RoboticPlatform (never destroyed,
// so threads and atexit handlers may use it at any time).
#pragma once
#include <semaphore.h>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "rp/core/Configuration.hpp"
#include "rp/core/RoboticObject.hpp"

namespace rp::internal {

struct Registry {
  std::recursive_mutex mutex;  // recursive: shutdown hooks may look objects up
  std::vector<RoboticObject*> objects;
  std::vector<std::unique_ptr<RoboticObject>> owned;  // created by ObjectManager
  std::atomic<std::uint64_t> nextId{1};
  // Object references (RoboticObject::withdrawObject waits here; never destroyed, so a releasing
  // thread may notify after the object it released is gone).
  std::mutex referenceMutex;
  std::condition_variable referenceCv;

  // System shutdown.
  std::atomic<int> requested{0};
  std::atomic<bool> reasonReady{false};
  char reason[256] = {};
  std::atomic<int> signalNumber{0};
  sem_t semaphore;
  std::once_flag watcherStarted;
  std::mutex doneMutex;
  std::condition_variable doneCv;
  bool done = false;
  std::atomic<bool> shutdownComplete{false};  // `done`, for a signal handler (no lock there)
  std::atomic<double> timeoutSeconds{5.0};

  // Global configuration (replaced as a whole).
  std::mutex configMutex;
  std::shared_ptr<const Configuration> configuration = std::make_shared<Configuration>();

  Registry();
};

Registry& registry();
std::shared_ptr<const Configuration> currentConfiguration();
void ensureShutdownWatcher();
std::string demangleName(const char* mangled);

}  // namespace rp::internal
