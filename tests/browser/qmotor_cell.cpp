// Test program for QMotor's browser tests: a Puma 560 ("puma") powered and holding its pose with
// gravity compensation (no trajectory generator), and a user's object ("wave") whose control
// program has a log variable `ramp` (seconds since the program started) and `wave` = sin(pi ramp),
// and a tunable `gain`. Both are configured by the rp.cfg named with -config. Runs until SIGTERM.
#include <cmath>
#include <iostream>
#include <thread>

#include "RoboticPlatform.hpp"

namespace {

class Wave : public PhysicalObject, public ControlProgram {
 public:
  explicit Wave(const std::string& name = "") : PhysicalObject(name), ControlProgram(name) {
    registerLogVariable("ramp", ramp_, "s");
    registerLogVariable("wave", wave_);
    registerParameter("gain", gain_, 0, 100, "", "amplitude of the wave");
    setRate(500);
    startControlLoop();  // applies its qmotorConfig, starts the loop, publishes it
  }
  ~Wave() override { stopControlLoop(); }
  ControlProgram* getControlProgram() override { return this; }

 protected:
  void enterControl() override { start_ = -1; }
  void control() override {
    if (start_ < 0) start_ = getTime();
    ramp_ = getTime() - start_;
    wave_ = gain_ * std::sin(M_PI * ramp_);
  }

 private:
  double ramp_ = 0, wave_ = 0, gain_ = 1, start_ = -1;
};

}  // namespace

RP_REGISTER_CLASS_AS(Wave, "Wave");  // a user's class: configured in rp.cfg as `class Wave`

int main(int argc, char* argv[]) {
  RoboticPlatform::init(argc, argv, "qmotor_cell: a holding Puma 560 and a wave program for QMotor's tests");
  Puma560 puma("puma");
  puma.setGravityCompensationOn();
  puma.enableArmPower();
  Wave wave("wave");
  std::cout << "qmotor_cell: running" << std::endl;
  while (!ObjectManager::isShutdownRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  return 0;  // after SIGTERM, RoboticPlatform::finish() makes it 143
}
