// Physical objects of classes that do not publish themselves (a user's PhysicalObject subclass
// without publishObject(), or a plain PhysicalObject) are drawn anyway: the Scene Viewer's scene
// lists them with PhysicalObject's own look, where rp.cfg or setTransform() puts them and on
// their mount, read only from their PhysicalObject part, from the end of PhysicalObject's
// constructor to the start of its destructor. Labelled "threads": ThreadSanitizer checks that a
// reader never touches the rest of an object being constructed or destroyed.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <thread>

#include "SceneState.hpp"
#include "StateFrame.hpp"
#include "rp/RoboticPlatform.hpp"

namespace {

using nlohmann::json;

// A user's class that never calls publishObject(), with state of its own written after the
// PhysicalObject part is complete.
class Fixture : public rp::PhysicalObject {
 public:
  explicit Fixture(const std::string& name) : rp::PhysicalObject(name) { for (auto& v : values_) v = 1.0; }
  ~Fixture() override { for (auto& v : values_) v = -1.0; }

 private:
  double values_[64];
};

}  // namespace
RP_REGISTER_CLASS(Fixture);
namespace {

// The base-frame pose of every object in a state frame, by scene index.
std::map<std::uint32_t, rp::Transform> framePoses(const std::string& frame) {
  std::map<std::uint32_t, rp::Transform> poses;
  for (const rp::test::FrameObject& o : rp::test::decodeStateFrame(frame))
    if (!o.poses.empty()) poses[o.index] = o.poses[0];
  return poses;
}

TEST(UnpublishedObjects, ArePlacedAsRpCfgSaysAndFollowTheirMount) {
  rp::RoboticPlatform::setSimulationModeOn();
  rp::RoboticPlatform::setConfiguration(rp::Configuration::parse("[table]\nclass Fixture\nposition 500 -100 200\norientation 0 0 90\n", "rp.cfg"));
  Fixture table("table");  // configured by rp.cfg, never published by its class
  rp::Puma560 puma("puma");
  Fixture tool("tool");
  tool.setConnection(puma, "endEffector");
  tool.setTransform(rp::translation(0, 0, 0.05));
  ASSERT_FALSE(table.isObjectPublished());
  ASSERT_FALSE(tool.isObjectPublished());

  rp::internal::SceneState scene;
  scene.refresh();
  const json t = rp::test::describedObject(scene, "table").first;
  ASSERT_TRUE(t.is_object()) << scene.sceneMessage();
  EXPECT_EQ(t["kind"], "physical");
  EXPECT_EQ(t["published"], false);
  EXPECT_EQ(t["frames"], json::array({"base"}));
  ASSERT_EQ(t["shapes"].size(), 1u);
  EXPECT_EQ(t["shapes"][0]["kind"], "box");  // PhysicalObject's own look: a 0.1 m cube
  EXPECT_EQ(t["shapes"][0]["size"], json::array({0.1, 0.1, 0.1}));
  const json m = rp::test::describedObject(scene, "tool").first;
  ASSERT_TRUE(m.is_object());
  EXPECT_EQ(m["connection"], (json{{"object", "puma"}, {"frame", "endEffector"}}));

  const std::map<std::uint32_t, rp::Transform> poses = framePoses(scene.buildFrame());
  const auto tp = poses.find(rp::test::describedObject(scene, "table").second);
  ASSERT_NE(tp, poses.end()) << "the table has a pose in the state frames";
  const rp::Transform expectedTable = rp::translation(0.5, -0.1, 0.2) * rp::rpyToTransform(0, 0, M_PI / 2);
  EXPECT_LT((tp->second - expectedTable).cwiseAbs().maxCoeff(), 1e-12) << tp->second;
  const auto mp = poses.find(rp::test::describedObject(scene, "tool").second);
  ASSERT_NE(mp, poses.end());
  const rp::Transform expectedTool = puma.getEndEffectorTransform() * rp::translation(0, 0, 0.05);
  EXPECT_LT((mp->second - expectedTool).cwiseAbs().maxCoeff(), 1e-6) << mp->second << "\n" << expectedTool;

  // Published later, it is described by its class as any published object.
  table.publishObject();
  scene.refresh();
  EXPECT_EQ(rp::test::describedObject(scene, "table").first["className"], "Fixture");
  EXPECT_NE(rp::test::describedObject(scene, "table").first["published"], false);
  tool.clearConnection();
}

TEST(UnpublishedObjects, AReaderNeverTouchesAnObjectBeingConstructedOrDestroyed) {
  rp::RoboticPlatform::setConfiguration(rp::Configuration());
  std::atomic<bool> stop{false};
  std::atomic<int> drawn{0};
  std::thread reader([&] {
    rp::internal::SceneState scene;
    while (!stop.load()) {
      scene.refresh();
      (void)scene.buildFrame();
      const json parsed = json::parse(scene.sceneMessage());
      for (const json& o : parsed["objects"])
        if (o["name"].get<std::string>().rfind("fixture_", 0) == 0 && o["kind"] == "physical") drawn.fetch_add(1);
    }
  });
  // Objects come and go while the reader draws them (until it has seen 20, at most 20,000).
  for (int i = 0; i < 20000 && drawn.load() < 20; ++i) {
    auto f = std::make_unique<Fixture>("fixture_" + std::to_string(i));
    f->setTransform(rp::translation(0.001 * (i % 100), 0, 0));
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  stop.store(true);
  reader.join();
  EXPECT_GT(drawn.load(), 0) << "the reader drew some of the objects";
}

}  // namespace
