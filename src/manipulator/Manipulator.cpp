// Connection bookkeeping between manipulators, servo controls and trajectory generators.
#include "rp/manipulator/Manipulator.hpp"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include "rp/control/ServoControl.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/trajectory/TrajectoryGenerator.hpp"

namespace rp {

Manipulator::~Manipulator() {
  ObjectManager om;
  for (ServoControl* control : om.getDerivedObjects<ServoControl>()) {
    if (control->d_manipulator == this) control->d_manipulator = nullptr;
  }
  for (TrajectoryGenerator* generator : om.getDerivedObjects<TrajectoryGenerator>()) disconnectGenerator(*generator);
}

Transform Manipulator::getFrameTransform(const std::string& frame) const {
  const ManipulatorModel& model = getModel();
  const int n = model.getNumberOfJoints();
  if (frame == "base") return model.getBaseTransform();
  int link = 0;
  if (frame != "endEffector") {
    char* end = nullptr;
    const long k = frame.rfind("link", 0) == 0 && frame.size() > 4 ? std::strtol(frame.c_str() + 4, &end, 10) : 0;
    if (end == nullptr || *end != '\0' || k < 1 || k > n)
      throw std::invalid_argument("manipulator '" + getName() + "' has no frame '" + frame + "' (base, link1..link" +
                                  std::to_string(n) + ", endEffector)");
    link = static_cast<int>(k);
  }
  ManipulatorData data(model);
  const Transform endEffector = forwardKinematics(model, data, getJointPosition());
  return link == 0 ? endEffector : data.linkTransforms[static_cast<std::size_t>(link - 1)];
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
