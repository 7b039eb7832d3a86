// Two arms carry one work piece: cooperating robots in one process (the paper's argument for one
// process, section 1), with the servo loops of both arms stepped by one executor thread.
//
// A leader Puma 560 at the origin is driven by the trajectory generator; a follower Puma 560 1 m
// away, facing it, holds the other end of a 0.3 m bar with a rigid grasp: in every servo cycle its
// setpoint is the inverse kinematics of the leader's measured end-effector pose of that same cycle
// times the grasp (the pose of the follower's end-effector relative to the leader's, taken when
// both had grasped the bar). Both arms' servo loops run in one executor (the default): the
// follower's control reads the leader's joints of the same cycle, without a lock and without a
// cycle's delay, whatever the order the arms were made in (docs/realtime.md, Executors). The bar
// is drawn in the Scene Viewer on the leader's end-effector. The program prints the worst error
// of the relative pose during the carry (position [mm] and orientation [deg]) and exits.
//
// Run: build/bin/two_arms_one_object [-simclock] [-nogui] [-log two_arms.csv]
#include "RoboticPlatform.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iostream>

namespace {

// The follower's trajectory: the leader's measured end-effector pose times the grasp, through the
// Puma's closed-form inverse kinematics in the world (the branch closest to where the follower
// is; the follower's model includes its base pose); the
// velocity from the change since the last cycle. Also records the worst relative-pose error.
class RigidGrasp : public TrajectoryGenerator {
 public:
  RigidGrasp(Puma560& leader, Puma560& follower, const Transform& grasp)
      : leader_(leader),
        follower_(follower),
        grasp_(grasp),
        model_(dynamic_cast<const Puma560Model&>(follower.getModel())) {}
  ~RigidGrasp() override {
    withdrawObject();  // first: a system shutdown's thread keeps off from here on
    releaseFromManipulators();
  }

  // Called in the follower's servo cycle (its control phase): the leader's joints were read in
  // this cycle's read phase.
  bool getCurrentSetpoint(double time, Setpoint& sp) override {
    const Transform leaderPose = leader_.getEndEffectorTransform();
    const JointVector current = follower_.getJointPosition();
    // The grasp's error now, both arms measured in the same cycle.
    const Transform relative = rigidInverse(leaderPose) * follower_.getEndEffectorTransform();
    const double position = (getPosition(relative) - getPosition(grasp_)).norm();
    const Matrix<3, 3> r = getRotation(grasp_).transpose() * getRotation(relative);
    const double angle = std::acos(std::clamp((r.trace() - 1) / 2, -1.0, 1.0));
    worstPosition = std::max(worstPosition.load(), position);
    worstAngle = std::max(worstAngle.load(), angle);

    JointVector q = current;
    if (model_.inverseKinematicsClosest(leaderPose * grasp_, current, q) != IkStatus::Solved)
      return false;  // out of reach: the follower holds
    sp.position = q;
    sp.velocity = JointVector::Zero(q.size());
    if (lastTime_ >= 0 && time > lastTime_) sp.velocity = (q - last_) / (time - lastTime_);
    sp.acceleration = JointVector::Zero(q.size());
    last_ = q;
    lastTime_ = time;
    return true;
  }

  std::atomic<double> worstPosition{0}, worstAngle{0};  // [m], [rad]

 private:
  Puma560& leader_;
  Puma560& follower_;
  Transform grasp_;
  const Puma560Model& model_;
  JointVector last_;
  double lastTime_ = -1;
};

}  // namespace

int main(int argc, char* argv[]) {
  RoboticPlatform::init(argc, argv);

  Puma560 leader("leader");
  Puma560 follower("follower");
  follower.setTransform(translation(0, 1.0, 0) * zRotation(M_PI));  // facing the leader

  // The bar, 0.3 m along y between the two end-effectors, drawn on the leader's end-effector.
  WorkPiece bar("bar");
  Vector<3> size;
  size = 0.03, 0.3, 0.03;
  bar.setSize(size);
  bar.setConnection(leader, "endEffector");
  bar.setTransform(translation(0, -0.15, 0));  // its centre, half-way to the follower

  // Both arms to the grasp: the end-effectors pointing down, 0.3 m apart.
  const Transform down = xRotation(M_PI);
  DefaultTrajectoryGenerator<6> tragen, approach;
  leader.setTrajectoryGenerator(tragen);
  follower.setTrajectoryGenerator(approach);
  tragen.moveToThroughJointSpace(translation(0.5, 0.3, 0.3) * down);
  JointVector start = follower.getJointPosition();
  const auto& model = dynamic_cast<const Puma560Model&>(follower.getModel());
  const Transform followerGoal = translation(0.5, 0.6, 0.3) * down * zRotation(M_PI);  // world (the model knows its base)
  if (model.inverseKinematicsClosest(followerGoal, follower.getJointPosition(), start) != IkStatus::Solved) {
    std::cerr << "two_arms_one_object: the grasp is out of the follower's reach" << std::endl;
    return 1;
  }
  approach.moveRadians(start);
  tragen.stop(0.5);
  approach.stop(0.5);

  // The grasp: the follower's end-effector relative to the leader's, from here on kept rigid.
  const Transform grasp = rigidInverse(leader.getEndEffectorTransform()) * follower.getEndEffectorTransform();
  RigidGrasp rigid(leader, follower, grasp);
  follower.setTrajectoryGenerator(rigid);

  // The leader carries the bar across, down with a turn and back; the follower keeps its end.
  tragen.moveTo(translation(0.6, 0.2, 0.3) * down);
  tragen.moveTo(translation(0.55, 0.3, 0.22) * zRotation(0.2) * down);
  tragen.moveTo(translation(0.5, 0.3, 0.3) * down);
  tragen.stop(0.5);

  if (ObjectManager::isShutdownRequested()) {
    std::cerr << "two_arms_one_object: stopped by a system shutdown: " << ObjectManager::getShutdownReason() << std::endl;
    return RoboticPlatform::kExitAfterShutdown;
  }
  std::cout << "two_arms_one_object: done, worst relative-pose error " << rigid.worstPosition.load() * 1000 << " mm, "
            << rigid.worstAngle.load() * 180 / M_PI << " deg" << std::endl;
  follower.setTrajectoryGenerator(approach);  // before `rigid` goes
  return 0;
}
