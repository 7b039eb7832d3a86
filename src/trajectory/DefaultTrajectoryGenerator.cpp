// The default trajectory generator's non-inline parts (rp/trajectory/DefaultTrajectoryGenerator.hpp).
#include "rp/trajectory/DefaultTrajectoryGenerator.hpp"

#include "CartesianPath.hpp"
#include "rp/core/TypeDatabase.hpp"
#include "rp/manipulator/Manipulator.hpp"
#include "rp/model/InverseKinematics.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/Puma560Model.hpp"

#include <array>
#include <cmath>

#include "../core/ShortNumber.hpp"

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
  if (const auto* puma = dynamic_cast<const Puma560Model*>(&model)) {
    // Closed form: stay on the branch (shoulder, elbow, wrist) the arm is on at the start.
    std::array<Puma560IkSolution, 8> start, goal;
    const Transform from = forwardKinematics(model, data, seed);
    if (puma->inverseKinematicsAll(from, start) == IkStatus::Solved &&
        puma->inverseKinematicsAll(pose, goal) == IkStatus::Solved) {
      int branch = -1;
      double best = INFINITY;
      for (int b = 0; b < 8; ++b) {
        const double d = (start[static_cast<std::size_t>(b)].q - seed).cwiseAbs().maxCoeff();
        if (d < best) {
          best = d;
          branch = b;
        }
      }
      if (branch >= 0 && goal[static_cast<std::size_t>(branch)].withinLimits) return goal[static_cast<std::size_t>(branch)].q;
    }
    if (puma->inverseKinematicsClosest(pose, seed, q) == IkStatus::Solved) return q;
    const Vector<3> p = getPosition(pose);
    throw std::invalid_argument(getName() + ": '" + m.getName() + "' cannot reach the pose at (" + internal::shortNumber(p(0)) +
                                ", " + internal::shortNumber(p(1)) + ", " + internal::shortNumber(p(2)) +
                                ") m with any of its eight configurations within the joint limits");
  }
  IkOptions options;
  options.positionTolerance = 1e-7;
  options.orientationTolerance = 1e-7;
  if (inverseKinematics(model, data, pose, seed, q, options) != IkStatus::Solved) {
    const Vector<3> p = getPosition(pose);
    throw std::invalid_argument(getName() + ": '" + m.getName() + "' cannot reach the pose at (" +
                                internal::shortNumber(p(0)) + ", " + internal::shortNumber(p(1)) + ", " + internal::shortNumber(p(2)) +
                                ") m within its joint limits");
  }
  return q;
}

template <int N>
void DefaultTrajectoryGenerator<N>::queuePose(const Transform& pose) {
  Manipulator& m = getPlanningManipulator();
  const ManipulatorModel& model = m.getModel();
  if (model.getNumberOfJoints() >= 6 && !internal::isSingular(model, getLastTarget())) {
    queueCartesianMotion(pose);
  } else {
    queueJointMotion(solvePose(pose));
  }
}

template class DefaultTrajectoryGenerator<Dynamic>;
template class DefaultTrajectoryGenerator<6>;
template class DefaultTrajectoryGenerator<7>;
template class DefaultTrajectoryGenerator<4>;

}  // namespace rp

RP_REGISTER_CLASS_AS(rp::DefaultTrajectoryGenerator<>, "DefaultTrajectoryGenerator");
