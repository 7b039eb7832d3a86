// Connection bookkeeping between manipulators, servo controls and trajectory generators.
#include "rp/manipulator/Manipulator.hpp"

#include <algorithm>

#include "rp/control/ServoControl.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/trajectory/TrajectoryGenerator.hpp"

namespace rp {

Manipulator::~Manipulator() {
  ObjectManager om;
  for (ServoControl* control : om.getDerivedObjects<ServoControl>()) {
    if (control->d_manipulator == this) control->d_manipulator = nullptr;
  }
  for (TrajectoryGenerator* generator : om.getDerivedObjects<TrajectoryGenerator>()) disconnectGenerator(*generator);
}

void Manipulator::connectGenerator(TrajectoryGenerator& generator) {
  std::lock_guard<std::mutex> lock(generator.manipulatorsMutex_);
  if (std::find(generator.manipulators_.begin(), generator.manipulators_.end(), this) == generator.manipulators_.end())
    generator.manipulators_.push_back(this);
}

void Manipulator::disconnectGenerator(TrajectoryGenerator& generator) {
  std::lock_guard<std::mutex> lock(generator.manipulatorsMutex_);
  auto& v = generator.manipulators_;
  v.erase(std::remove(v.begin(), v.end(), this), v.end());
}

ServoControl::~ServoControl() { releaseFromManipulator(); }

void ServoControl::releaseFromManipulator() {
  if (d_manipulator != nullptr) d_manipulator->releaseServoControl(*this);
}

TrajectoryGenerator::~TrajectoryGenerator() { releaseFromManipulators(); }

void TrajectoryGenerator::releaseFromManipulators() {
  for (Manipulator* m : getManipulators()) m->releaseTrajectoryGenerator(*this);
}

std::vector<Manipulator*> TrajectoryGenerator::getManipulators() const {
  std::lock_guard<std::mutex> lock(manipulatorsMutex_);
  return manipulators_;
}

}  // namespace rp
