// Helper for Signal_test: a platform program logging one control program until it is signalled.
#include <unistd.h>

#include <cstdio>

#include "rp/core/RoboticPlatform.hpp"
#include "rp/rt/ControlProgram.hpp"

namespace {
class Counter : public rp::ControlProgram {
 public:
  Counter() : rp::ControlProgram("child") {
    registerLogVariable("count", count_);
    registerLogVariable("v", v_, 2, "m");
  }
  ~Counter() override { stop(); }

 protected:
  void control() override {
    count_ = static_cast<double>(getCycleCount());
    v_[0] = 2 * count_;
    v_[1] = -count_;
  }

 private:
  double count_ = 0;
  double v_[2] = {0, 0};
};
}  // namespace

int main(int argc, char** argv) {
  rp::RoboticPlatform::init(argc, argv);
  Counter counter;
  counter.start();
  std::puts("ready");
  std::fflush(stdout);
  for (;;) pause();
}
