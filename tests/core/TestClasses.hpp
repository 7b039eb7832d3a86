// Classes registered only in the core tests: a physical and a functional object with settings of
// every kind, and stand-ins for the paper's Figure 9 classes when the library has none yet.
#pragma once
#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "ScratchDirectory.hpp"
#include "rp/core/Core.hpp"

namespace rp::test {

class TestArm : public PhysicalObject {
 public:
  explicit TestArm(const std::string& name = "") : PhysicalObject(name) {
    if (const ConfigSection* s = configSection(); s && s->has("port")) port = s->getWord("port");
  }
  static void declareSettings(SettingSchema& schema) {
    PhysicalObject::declareSettings(schema);
    schema.addWord("port", "serial device");
    schema.addNumbers("gain", 2, "N/m", "kp kd");
    schema.addChoice("mode", {"fast", "slow"}, "speed");
    schema.addInteger("count", "how many");
  }
  std::string port;
};

class TestFunction : public FunctionalObject {
 public:
  explicit TestFunction(const std::string& name = "") : FunctionalObject(name) {}
};

// Completes its shutdown only after isShutdownComplete() has been asked `delay` times.
class SlowShutdown : public PhysicalObject {
 public:
  explicit SlowShutdown(const std::string& name = "") : PhysicalObject(name) {}
  void startShutdown() override { started = true; }
  bool isShutdownComplete() const override { return started && ++polls >= 3; }
  std::atomic<bool> started{false};
  mutable std::atomic<int> polls{0};
};


// A directory of the temporary folder, empty at first, removed at the end of the test.
// perProcess false: the same folder in a death test's child (see ScratchDirectory).
inline ScratchDirectory scratchDirectory(const std::string& name, bool perProcess = true) {
  return ScratchDirectory("rp_core_test_", name, perProcess);
}

inline void writeFile(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

}  // namespace rp::test
