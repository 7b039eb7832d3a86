// The default trajectory generator's non-inline parts (rp/trajectory/DefaultTrajectoryGenerator.hpp).
#include "rp/trajectory/DefaultTrajectoryGenerator.hpp"

#include "rp/core/TypeDatabase.hpp"
#include "rp/manipulator/Manipulator.hpp"
#include "rp/model/InverseKinematics.hpp"
#include "rp/model/Kinematics.hpp"

namespace rp {

template <int N>
int DefaultTrajectoryGenerator<N>::manipulatorJoints(Manipulator& manipulator) {
  return manipulator.getNumberOfJoints();
}

template <int N>
JointVector DefaultTrajectoryGenerator<N>::solvePose(const Transform& pose) {
  Manipulator& m = getPlanningManipulator();
  const ManipulatorModel& model = m.getModel();
  ManipulatorData data(model);
  const JointVector seed = getLastTarget();
  JointVector q(model.getNumberOfJoints());
  IkOptions options;
  options.positionTolerance = 1e-7;
  options.orientationTolerance = 1e-7;
  if (inverseKinematics(model, data, pose, seed, q, options) != IkStatus::Solved) {
    const Vector<3> p = getPosition(pose);
    throw std::invalid_argument(getName() + ": '" + m.getName() + "' cannot reach the pose at (" +
                                std::to_string(p(0)) + ", " + std::to_string(p(1)) + ", " + std::to_string(p(2)) +
                                ") m within its joint limits");
  }
  return q;
}

template class DefaultTrajectoryGenerator<Dynamic>;
template class DefaultTrajectoryGenerator<6>;
template class DefaultTrajectoryGenerator<7>;
template class DefaultTrajectoryGenerator<4>;

}  // namespace rp

RP_REGISTER_CLASS_AS(rp::DefaultTrajectoryGenerator<>, "DefaultTrajectoryGenerator");
