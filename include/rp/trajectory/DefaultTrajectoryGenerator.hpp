#pragma once
/// @file
/// The default trajectory generator: joint-space and Cartesian target points (paper section 3.3,
/// Figures 21 and 23).

#include <Eigen/Core>

#include <numbers>
#include <stdexcept>
#include <string>

#include "rp/math/Transform.hpp"
#include "rp/trajectory/QueueTrajectoryGenerator.hpp"

namespace rp {

/// Queues motions to joint targets (move(), in degrees as the paper's Figure 23 writes them) and
/// to end-effector poses (moveTo(), a Transform in metres as in Figure 21).
///
/// move() is a jerk-limited joint motion within each joint's velocity, acceleration and jerk
/// limits (the model's, or setJointLimits()); by default (Synchronization::Time) all joints start
/// and finish together at the slowest joint's minimum time, each on its own profile;
/// setSynchronization() offers the straight line in joint space (Synchronization::Phase) and
/// unsynchronised joints (Synchronization::None). moveTo() is a straight line
/// of the end-effector with the shortest-arc rotation, its joints found by inverse kinematics that
/// follows the arm's configuration (IK branch) from the previous target. Arms with fewer than six
/// joints, which cannot follow an arbitrary line, and arms that start from a singular
/// configuration (such as the Puma's ready pose, arm straight up and wrist stretched), from which
/// no straight line is defined, move there in joint space instead (inverse kinematics on the
/// previous target's configuration). Motions blend at via points (on by default; radius 0 stops
/// there; see QueueTrajectoryGenerator). A target outside the joint limits, or a pose the arm cannot
/// reach along the line, is refused with std::invalid_argument when it is queued, before the arm
/// moves.
///
/// Use it as `DefaultTrajectoryGenerator<6> tragen;` (Figure 21: checked against a 6-joint
/// manipulator when connected) or `DefaultTrajectoryGenerator tragen;` (Figure 23: any number of
/// joints).
/// @tparam N  number of joints, or `Dynamic` (the default) for any
template <int N = Dynamic>
class DefaultTrajectoryGenerator : public QueueTrajectoryGenerator {
 public:
  /// Creates an empty generator and publishes it to other threads (the Scene Viewer lists it;
  /// see RoboticObject::publishObject()).
  /// @param[in] name  object name; empty for an automatic name
  explicit DefaultTrajectoryGenerator(const std::string& name = "")
      : QueueTrajectoryGenerator(ClassSection(name, "DefaultTrajectoryGenerator")) {
    publishObject();
  }
  /// Withdraws the generator from other threads, finishes the queue (see
  /// QueueTrajectoryGenerator), then disconnects from the manipulators.
  ~DefaultTrajectoryGenerator() override {
    withdrawObject();
    waitUntilDone();
    releaseFromManipulators();
  }

  /// Checks the number of joints, then connects.
  /// @param[in] manipulator  the manipulator that will follow this generator
  /// @throws std::invalid_argument if N is fixed and differs from its number of joints
  void attach(Manipulator& manipulator) override {
    if (N != Dynamic && manipulatorJoints(manipulator) != N) {
      throw std::invalid_argument(getName() + ": a DefaultTrajectoryGenerator<" + std::to_string(N) +
                                  "> cannot drive a manipulator with " + std::to_string(manipulatorJoints(manipulator)) +
                                  " joints");
    }
    QueueTrajectoryGenerator::attach(manipulator);
  }

  /// Queues a motion to the joint angles `targetDegrees` [deg] (one per joint).
  /// @throws std::invalid_argument on a wrong count or a target outside the joint limits
  void move(const Eigen::Ref<const Eigen::VectorXd>& targetDegrees) {
    JointVector q(targetDegrees.size());
    for (Eigen::Index i = 0; i < targetDegrees.size(); ++i) q(i) = targetDegrees(i) * (std::numbers::pi / 180);
    queueJointMotion(q);
  }
  /// Queues a motion to the joint angles `target` [rad].
  /// @throws std::invalid_argument on a wrong count or a target outside the joint limits
  void moveRadians(const JointVector& target) { queueJointMotion(target); }
  /// Queues a straight-line motion that brings the end-effector to `pose` (world frame, metres);
  /// see the class description.
  /// @throws std::invalid_argument if the arm cannot get there along the line within its limits
  void moveTo(const Transform& pose) { queuePose(pose); }
  /// Queues a joint-space motion (synchronised as move() is) to the inverse
  /// kinematics solution of `pose` on the previous target's configuration.
  /// @throws std::invalid_argument if the inverse kinematics finds no solution within the limits
  void moveToThroughJointSpace(const Transform& pose) { queueJointMotion(solvePose(pose)); }

 private:
  static int manipulatorJoints(Manipulator& manipulator);
  JointVector solvePose(const Transform& pose);
  void queuePose(const Transform& pose);
};

/// The generator for any number of joints (`DefaultTrajectoryGenerator<>`).
extern template class DefaultTrajectoryGenerator<Dynamic>;
/// The generator for six joints (`DefaultTrajectoryGenerator<6>`).
extern template class DefaultTrajectoryGenerator<6>;
/// The generator for seven joints (`DefaultTrajectoryGenerator<7>`).
extern template class DefaultTrajectoryGenerator<7>;
/// The generator for four joints (`DefaultTrajectoryGenerator<4>`).
extern template class DefaultTrajectoryGenerator<4>;

}  // namespace rp
