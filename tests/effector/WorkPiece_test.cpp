// WorkPiece: settings, a simulated gripper holds it only when its fingers are around it, the
// held piece's mass is the arm's payload, and a released piece falls with g onto its table.
#include "rp/effector/WorkPiece.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <thread>
#include <vector>

#include "EffectorTestSupport.hpp"
#include "Vec3.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

using test::vec3;

SimulatedClock& simClock() {
  RoboticPlatform::useSimulatedClock();
  return dynamic_cast<SimulatedClock&>(RoboticPlatform::getDefaultClock());
}

// Records the fall's state every cycle.
class Sampler : public ControlProgram {
 public:
  explicit Sampler(const WorkPiece& piece) : ControlProgram("sampler"), piece_(piece) {
    setLogWriter(nullptr);
    seen.reserve(2000);
  }
  ~Sampler() override { stop(); }
  void control() override {
    const WorkPiece::FallState s = piece_.getFallState();
    if (s.steps > 0 && seen.size() < 2000) seen.push_back(s);  // from the fall's first step on
  }
  std::vector<WorkPiece::FallState> seen;  // the test reads it once the loop has stopped

 private:
  const WorkPiece& piece_;
};

class WorkPieceTest : public test::EffectorTest {
 protected:
  void SetUp() override {
    RoboticPlatform::setSimulationModeOn();
    ObjectManager::resetShutdown();
    simClock().resume();
  }
};

TEST_F(WorkPieceTest, TakesItsSettingsFromRpCfgAndIsDrawnAsABox) {
  configure("[piece]\nclass WorkPiece\nposition 100 200 30\nmass 1.5\nsize 60 40 20\ntableHeight 20\n");
  auto* piece = om_.createDerivedObject<WorkPiece>("piece");
  ASSERT_NE(piece, nullptr);
  EXPECT_DOUBLE_EQ(piece->getMass(), 1.5);
  EXPECT_NEAR((piece->getSize() - vec3(0.06, 0.04, 0.02)).norm(), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(piece->getTableHeight(), 0.02);
  EXPECT_NEAR((getPosition(piece->getTransform()) - vec3(0.1, 0.2, 0.03)).norm(), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(piece->restingHeight(piece->getTransform()), 0.03);  // 20 mm table + 10 mm
  const Model3D model = piece->get3DModel();
  ASSERT_EQ(model.shapes.size(), 1u);
  EXPECT_EQ(model.shapes[0].kind, ShapeKind::Box);
  EXPECT_NEAR((model.shapes[0].size - vec3(0.06, 0.04, 0.02)).norm(), 0.0, 1e-15);
  configure("[piece2]\nclass WorkPiece\nmass 0\n");
  EXPECT_THROW(om_.createDerivedObject<WorkPiece>("piece2"), ConfigError);
}

// Gripper at 0.5 m pointing down (its z axis), the tool point 0.1 m below it: (0, 0, 0.4).
TEST_F(WorkPieceTest, AGripperHoldsOnlyAPieceBetweenItsFingers) {
  DefaultGripper gripper("gripper");
  gripper.setTransform(translation(0, 0, 0.5) * xRotation(M_PI));
  ASSERT_NEAR((getPosition(gripper.getToolTransform()) - vec3(0, 0, 0.4)).norm(), 0.0, 1e-12);
  WorkPiece piece("piece");  // 40 mm cube, the opening is 80 mm, the tolerance 10 mm

  piece.setTransform(translation(0.015, 0, 0.4));  // 15 mm beside the tool point
  ASSERT_TRUE(gripper.close());
  EXPECT_TRUE(gripper.getGraspedObjects().empty()) << "not between the fingers";
  EXPECT_EQ(piece.getConnection(), nullptr);
  ASSERT_TRUE(gripper.open());

  piece.setTransform(translation(0, 0, 0.4));
  piece.setSize(vec3(0.09, 0.04, 0.04));  // 90 mm across the fingers: wider than the opening
  ASSERT_TRUE(gripper.close());
  EXPECT_TRUE(gripper.getGraspedObjects().empty()) << "wider than the opening";
  ASSERT_TRUE(gripper.open());
  piece.setTransform(translation(0, 0, 0.4) * zRotation(M_PI / 2));  // turned: 40 mm across
  ASSERT_TRUE(gripper.close());
  EXPECT_EQ(gripper.getGraspedObjects().size(), 1u) << "turned, it fits";
  gripper.relax();  // lets it go
  piece.waitUntilLanded();

  piece.setSize(vec3(0.04, 0.04, 0.04));
  piece.setTransform(translation(0.003, -0.004, 0.405));  // 7 mm from the tool point
  ASSERT_TRUE(gripper.close());
  ASSERT_EQ(gripper.getGraspedObjects().size(), 1u);
  EXPECT_EQ(piece.getConnection(), &gripper);
  // The gripper moves: the piece moves with it, where it was held.
  const Transform moved = translation(0.3, 0.1, 0.6) * zRotation(0.5) * xRotation(M_PI);
  gripper.setTransform(moved);
  const Transform inGripper = rigidInverse(translation(0, 0, 0.5) * xRotation(M_PI)) * translation(0.003, -0.004, 0.405);
  EXPECT_NEAR((getPosition(piece.getWorldTransform()) - getPosition(Transform(moved * inGripper))).norm(), 0.0, 1e-12);
}

TEST_F(WorkPieceTest, AReleasedPieceFallsWithGOntoItsTable) {
  DefaultGripper gripper("gripper");
  gripper.setTransform(translation(0.2, 0.1, 0.6) * xRotation(M_PI));  // tool point at z = 0.5
  WorkPiece piece("piece");
  piece.setTableHeight(0.05);
  piece.setTransform(translation(0.2, 0.1, 0.5));
  ASSERT_TRUE(gripper.close());
  ASSERT_EQ(gripper.getGraspedObjects().size(), 1u);
  // A loop of the test's own on the same simulated clock, in lock-step with the fall's, records
  // what it sees of the fall every cycle.
  Sampler sampler(piece);
  sampler.start();
  // Running on the clock before the fall starts (a loop joins the clock in its thread, later).
  while (sampler.getCycleCount() < 2) std::this_thread::yield();
  ASSERT_TRUE(gripper.open());
  ASSERT_TRUE(piece.waitUntilLanded(60));
  sampler.stop();
  // Each step's height is z0 - g t^2 / 2 at its time since the fall began.
  int samples = 0;
  std::uint64_t lastStep = 0;
  double lastHeight = 0.5;
  for (const WorkPiece::FallState& s : sampler.seen) {
    if (s.steps <= lastStep || s.landed) continue;
    ++samples;
    EXPECT_NEAR(s.height, 0.5 - 0.5 * 9.81 * s.time * s.time, 1e-12) << "at t = " << s.time;
    EXPECT_LT(s.height, lastHeight + (s.steps == 1 ? 1e-12 : 0.0));
    lastHeight = s.height;
    lastStep = s.steps;
  }
  EXPECT_GE(samples, 100) << "too few of its 297 steps seen";  // 228 seen: the two loops share ticks, in either order
  // On the table: the centre half its 40 mm height above it, 0.43 m down after t = sqrt(2 h / g).
  const WorkPiece::FallState end = piece.getFallState();
  EXPECT_TRUE(end.landed);
  EXPECT_DOUBLE_EQ(end.from, 0.5);
  const double fallTime = std::sqrt(2 * (0.5 - 0.07) / 9.81);
  EXPECT_GE(end.time, fallTime);
  EXPECT_LT(end.time, fallTime + 1e-3 + 1e-9) << "landed in the first 1 ms cycle after the fall time";
  EXPECT_NEAR((getPosition(piece.getTransform()) - vec3(0.2, 0.1, 0.07)).norm(), 0.0, 1e-12);
  EXPECT_EQ(piece.getConnection(), nullptr);
}

TEST_F(WorkPieceTest, AHeldPieceIsThePayloadOfTheArmTheGripperIsMountedOn) {
  Puma560 puma("puma");
  DefaultGripper gripper("gripper");
  gripper.setConnection(puma, "endEffector");
  WorkPiece piece("piece");
  piece.setMass(0.8);
  // 4 mm off the tool point (0.1 m along the end-effector's z), in the end-effector frame.
  const Vector<3> centre = vec3(0.004, 0, 0.1);
  const Transform endEffector = puma.getFrameTransform("endEffector");
  piece.setTransform(translation(transformPoint(endEffector, centre)));
  ASSERT_TRUE(gripper.close());
  ASSERT_EQ(gripper.getGraspedObjects().size(), 1u);
  EXPECT_DOUBLE_EQ(puma.getPayloadMass(), 0.8);
  EXPECT_NEAR((puma.getPayloadCentre() - centre).norm(), 0.0, 1e-6);
  ASSERT_TRUE(gripper.open());
  EXPECT_EQ(puma.getPayloadMass(), 0.0);
  piece.waitUntilLanded();
}

}  // namespace
}  // namespace rp
