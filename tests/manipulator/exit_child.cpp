// Helper for ExitPath_test: a platform program whose Puma ("puma", so that rp.cfg can put it
// behind a hardware server) is moving when the program ends in the way MODE names:
//   return    main returns while the arm moves
//   fault     a runaway control law drives joint 1 into its velocity limit (a system shutdown)
//   throw     the servo control throws in calculate()
//   signal    waits for SIGINT or SIGTERM
//   uncaught  main throws an exception nobody catches
// It prints "ready" once the arm moves; stderr goes to stdout so that the test reads both.
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

#include "rp/RoboticPlatform.hpp"

namespace {

class Runaway : public rp::ServoControl {
 public:
  explicit Runaway(bool throws) : throws_(throws) {}
  ~Runaway() override { releaseFromManipulator(); }
  void calculate() override {
    if (throws_ && ++calls_ > 50) throw std::runtime_error("encoder cable cut");
    rp::JointVector t = rp::JointVector::Zero(d_manipulator->getNumberOfJoints());
    t(0) = 60;
    d_manipulator->setControlOutput(t);
  }

 private:
  bool throws_;
  int calls_ = 0;
};

}  // namespace

int main(int argc, char* argv[]) {
  ::dup2(1, 2);
  const std::string mode = argc > 1 ? argv[1] : "";
  rp::RoboticPlatform::init(argc, argv, "exit_child MODE: return|fault|throw|signal|uncaught");
  rp::Puma560 puma("puma");
  rp::DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);
  rp::Vector<6> q;
  q = 30, 90, -90, 0, 0, 0;  // degrees: joint 1 turns 30 degrees from the ready pose
  tragen.move(q);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  std::cout << "ready" << std::endl;
  std::optional<Runaway> runaway;  // destroyed only after the shutdown manager is done with it
  if (mode == "fault" || mode == "throw") {
    runaway.emplace(mode == "throw");
    puma.setServoControl(*runaway);
    rp::ObjectManager::waitForShutdown(20);
  } else if (mode == "signal") {
    while (!rp::ObjectManager::isShutdownRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  } else if (mode == "uncaught") {
    throw std::runtime_error("the work piece is not where it should be");
  } else if (mode != "return") {
    std::cerr << "exit_child: unknown mode '" << mode << "'" << std::endl;
    return 2;
  }
  if (rp::ObjectManager::isShutdownRequested()) {
    std::cout << "exit_child: stopped by a system shutdown: " << rp::ObjectManager::getShutdownReason() << std::endl;
    return rp::RoboticPlatform::kExitAfterShutdown;
  }
  std::cout << "exit_child: done" << std::endl;
  return 0;
}
