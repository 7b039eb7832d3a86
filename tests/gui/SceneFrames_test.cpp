// The Scene Viewer's state frames: the poses drawn for a manipulator and the state values sent
// with them (joint positions, velocities, torques) are of one servo cycle. The page draws the
// poses and shows the values of the same frame; read apart, a moving arm's picture and its joint
// values would disagree by a cycle or more (seen in CI: the browser.urdf test's link 3 was 2 um
// from where the frame's own joint values put it, on an arm still settling).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "SceneState.hpp"
#include "StateFrame.hpp"
#include "rp/RoboticPlatform.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/ManipulatorData.hpp"

namespace {

// A Puma whose getJointPosition() answers a later cycle's position than its published state
// (0.05 rad further on every joint), as when its servo loop runs a cycle between two reads. As a
// class derived from an arm must (docs/core.md), it starts the servo loop when it is complete and
// stops it first: the loop calls the object's virtual functions (ThreadSanitizer saw the loop's
// first cycle race with this constructor when Puma560's own constructor started it).
class PumaAhead : public rp::Puma560 {
 public:
  explicit PumaAhead(const std::string& name) : rp::Puma560(name, DerivedClass{}) { startControlLoop(); }
  ~PumaAhead() override { stopControlLoop(); }
  rp::JointVector getJointPosition() const override {
    rp::JointVector q = rp::Puma560::getJointPosition();
    for (int i = 0; i < q.size(); ++i) q(i) += 0.05;
    return q;
  }
};

// Checks every frame of `arm` in one state frame against the kinematics of the joint positions in
// the same state frame's values; returns the number of frames compared.
int expectPosesOfTheFramesValues(rp::internal::SceneState& scene, const rp::Manipulator& arm, const std::string& name) {
  const auto [desc, index] = rp::test::describedObject(scene, name);
  const std::vector<std::string> frames = desc["frames"].get<std::vector<std::string>>();
  const rp::ManipulatorModel& model = arm.getModel();
  const int n = model.getNumberOfJoints();
  for (const rp::test::FrameObject& o : rp::test::decodeStateFrame(scene.buildFrame())) {
    if (o.index != index) continue;
    EXPECT_EQ(o.values.size(), static_cast<std::size_t>(3 * n + 3));
    EXPECT_EQ(o.poses.size(), frames.size());
    if (o.values.size() < static_cast<std::size_t>(n) || o.poses.size() != frames.size()) return 0;
    rp::JointVector q(n);
    for (int i = 0; i < n; ++i) q(i) = o.values[static_cast<std::size_t>(i)];
    rp::ManipulatorData data(model);
    rp::forwardKinematics(model, data, q);
    int compared = 0;
    for (std::size_t f = 0; f < frames.size(); ++f) {
      rp::Transform want;
      if (frames[f] == "endEffector") {
        want = data.endEffector;
      } else if (frames[f].rfind("link", 0) == 0) {
        want = data.linkTransforms[static_cast<std::size_t>(std::stoi(frames[f].substr(4)) - 1)];
      } else {
        continue;
      }
      EXPECT_LT((o.poses[f] - want).cwiseAbs().maxCoeff(), 1e-12)
          << frames[f] << " drawn at\n" << o.poses[f] << "\nthe frame's joint values put it at\n" << want;
      ++compared;
    }
    return compared;
  }
  ADD_FAILURE() << name << " is not in the state frame";
  return 0;
}

TEST(SceneFrames, AnArmsPosesAreThoseOfTheJointValuesSentWithThem) {
  rp::RoboticPlatform::setSimulationModeOn();
  PumaAhead puma("ahead");
  ASSERT_TRUE(puma.waitForCycles(2));
  rp::internal::SceneState scene;
  scene.refresh();
  EXPECT_EQ(expectPosesOfTheFramesValues(scene, puma, "ahead"), 7) << "link1..link6 and endEffector";
}

TEST(SceneFrames, AMovingArmsPosesAndValuesAreOfOneCycle) {
  // A Puma moving at speed while frames are built as fast as possible: every frame's poses are
  // those of its own joint values (the servo loop runs between any two reads of the arm).
  rp::RoboticPlatform::setSimulationModeOn();
  rp::Puma560 puma("mover");
  rp::DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);
  rp::JointVector goal = puma.getJointPosition();
  for (int i = 0; i < 3; ++i) goal(i) += goal(i) > 0 ? -0.5 : 0.5;  // towards the middle of the range
  tragen.moveRadians(goal);
  rp::internal::SceneState scene;
  scene.refresh();
  int frames = 0;
  const rp::JointVector start = puma.getJointPosition();
  while (!tragen.isDone() && frames < 20000 && !HasFailure()) {
    ASSERT_EQ(expectPosesOfTheFramesValues(scene, puma, "mover"), 7);
    ++frames;
  }
  const double travelled = (puma.getJointPosition() - start).cwiseAbs().maxCoeff();
  EXPECT_GT(travelled, 0.1) << "the arm moved while the frames were built (" << frames << " frames)";
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

}  // namespace
