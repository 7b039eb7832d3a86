// The generic drawing of an arm's links (src/manipulator/LinkShapes.cpp), checked against the
// arm's forward kinematics at random joint positions: every link is a connected path of
// cylinders from its joint's origin to the next joint's origin, and every joint's motor housing
// sits on that joint's axis; for standard DH (Puma 560, WAM 4 and 7), modified DH (the Puma
// re-expressed) and placements (a URDF arm).
#include "LinkShapes.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "ModifiedDh.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/Model.hpp"
#include "rp/model/UrdfModel.hpp"

namespace rp {
namespace {

struct Segment {
  Eigen::Vector3d a, b, axis;  // world end points; unit axis from a to b
  double radius, length;
};

// The world end points of cylinder `s`, drawn in a frame posed at `frame`.
Segment world(const Shape& s, const Transform& frame) {
  const Eigen::Matrix4d T = Eigen::Matrix4d(frame) * Eigen::Matrix4d(s.pose);
  const Eigen::Vector3d c = T.topRightCorner<3, 1>(), z = T.block<3, 1>(0, 2);
  return {c - 0.5 * s.size(1) * z, c + 0.5 * s.size(1) * z, z, s.size(0), s.size(1)};
}

// Checks `model`'s drawing at random joint positions: each link's cylinders (the link colour)
// chain from joint i's origin to joint i+1's; a housing (the motor colour) lies on each joint axis.
void checkDrawing(const ManipulatorModel& model) {
  SCOPED_TRACE(model.getName());
  Model3D m;
  for (int i = 1; i <= model.getNumberOfJoints(); ++i) m.frames.push_back("link" + std::to_string(i));
  internal::addLinkShapes(model, m);
  EXPECT_TRUE(m.linksDrawn);
  const int n = model.getNumberOfJoints();
  const bool standard = model.getConvention() == DHConvention::Standard;
  ManipulatorData data(model);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    JointVector q(n);
    for (int i = 0; i < n; ++i)
      q(i) = std::uniform_real_distribution<double>(model.getPositionMin()(i), model.getPositionMax()(i))(rng);
    forwardKinematics(model, data, q);
    // Joint j's (from 0) origin and axis in the world: on z of frame j-1 for standard DH (the
    // base for j = 0), of frame j otherwise.
    auto jointFrame = [&](int j) -> Eigen::Matrix4d {
      const int f = standard ? j - 1 : j;
      return f < 0 ? Eigen::Matrix4d(model.getBaseTransform()) : Eigen::Matrix4d(data.linkTransforms[static_cast<std::size_t>(f)]);
    };
    auto frameOf = [&](const Shape& s) -> Transform {
      if (s.frame == "base") return model.getBaseTransform();
      return data.linkTransforms[static_cast<std::size_t>(std::stoi(s.frame.substr(4)) - 1)];
    };
    std::vector<std::vector<Segment>> links(static_cast<std::size_t>(n));
    std::vector<Segment> housings;
    for (const Shape& s : m.shapes) {
      ASSERT_EQ(s.kind, ShapeKind::Cylinder);
      ASSERT_GT(s.size(0), 0);
      const Segment w = world(s, frameOf(s));
      if (s.color.r < 0.5) {
        housings.push_back(w);
      } else if (s.frame != "base") {
        links[static_cast<std::size_t>(std::stoi(s.frame.substr(4)) - 1)].push_back(w);
      }
    }
    // Link i (its body: from joint i to joint i+1; the last one to its flange, not checked).
    for (int i = 0; i + 1 < n; ++i) {
      const Eigen::Vector3d from = jointFrame(i).topRightCorner<3, 1>(), to = jointFrame(i + 1).topRightCorner<3, 1>();
      Eigen::Vector3d at = from;
      for (const Segment& s : links[static_cast<std::size_t>(i)]) {
        EXPECT_LT((s.a - at).norm(), 1e-9) << "link " << i + 1 << ": a gap in the drawing";
        at = s.b;
      }
      EXPECT_LT((at - to).norm(), 1e-9) << "link " << i + 1 << " does not reach joint " << i + 2;
    }
    // A housing on every joint's axis, centred on its origin.
    for (int j = 0; j < n; ++j) {
      const Eigen::Matrix4d F = jointFrame(j);
      const Eigen::Vector3d o = F.topRightCorner<3, 1>(), z = F.block<3, 1>(0, 2);
      bool found = false;
      for (const Segment& h : housings)
        found = found || ((0.5 * (h.a + h.b) - o).norm() < 1e-9 && h.axis.cross(z).norm() < 1e-9);
      EXPECT_TRUE(found) << "no housing on joint " << j + 1 << "'s axis";
    }
  }
}

TEST(LinkShapes, DhArmsAreDrawnAlongTheirKinematics) {
  checkDrawing(Puma560Model());
  checkDrawing(WAM4Model());
  checkDrawing(WAM7Model());
  checkDrawing(*test::toModifiedDh(Puma560Model()));
}

TEST(LinkShapes, UrdfArmsAreDrawnAlongTheirPlacements) {
  for (const char* file : {"ur_like.urdf", "noisy_axes_arm.urdf", "test_arm.urdf"})
    checkDrawing(*loadUrdf(std::string(RP_MODEL_DATA_DIR) + "/" + file));
}

TEST(LinkShapes, SizesFollowTheArmsReach) {
  // The Puma (about 1.7 m of offsets) is drawn thicker than the WAM 4 (about 0.9 m), and every
  // radius shrinks or stays along the chain.
  auto firstRadius = [](const ManipulatorModel& model) {
    Model3D m;
    internal::addLinkShapes(model, m);
    return m.shapes.front().size(0);
  };
  EXPECT_GT(firstRadius(Puma560Model()), firstRadius(WAM4Model()));
}

}  // namespace
}  // namespace rp
