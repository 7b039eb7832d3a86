// Reads what the Scene Viewer's SceneState sends, in the tests: an object's description in the
// scene message, and the binary state frames (the layout SceneState::buildFrame() writes): each
// object's scene index, world poses and state values.
#pragma once

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "SceneState.hpp"
#include "rp/math/Transform.hpp"

namespace rp::test {

/// The scene message's description of the object named `name` and its index among the scene's
/// objects (the index state frames give); a test failure, null and 0 if there is none.
inline std::pair<nlohmann::json, std::uint32_t> describedObject(const internal::SceneState& s, const std::string& name) {
  const nlohmann::json scene = nlohmann::json::parse(s.sceneMessage());
  for (std::size_t i = 0; i < scene["objects"].size(); ++i)
    if (scene["objects"][i]["name"] == name) return {scene["objects"][i], static_cast<std::uint32_t>(i)};
  ADD_FAILURE() << name << " is not in the scene: " << s.sceneMessage();
  return {nullptr, 0};
}

/// One object of a state frame.
struct FrameObject {
  std::uint32_t index = 0;           ///< index into the scene message's objects
  std::uint32_t error = 0;           ///< the object's error code
  std::vector<Transform> poses;      ///< world pose of each of the object's frames
  std::vector<double> values;        ///< state values (a manipulator's q, qd, tau, ...)
};

/// Decodes one state frame (little-endian; see SceneState::buildFrame()).
inline std::vector<FrameObject> decodeStateFrame(const std::string& frame) {
  std::size_t at = 0;
  auto u32 = [&] {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(static_cast<unsigned char>(frame.at(at + i))) << (8 * i);
    at += 4;
    return v;
  };
  auto f64 = [&] {
    std::uint64_t bits = 0;
    for (int i = 0; i < 8; ++i) bits |= static_cast<std::uint64_t>(static_cast<unsigned char>(frame.at(at + i))) << (8 * i);
    at += 8;
    double v;
    std::memcpy(&v, &bits, 8);
    return v;
  };
  EXPECT_EQ(u32(), internal::kStateFrameMagic);
  (void)u32();  // protocol
  (void)u32();  // scene version
  const std::uint32_t count = u32();
  (void)f64();  // time
  std::vector<FrameObject> objects(count);
  for (FrameObject& o : objects) {
    o.index = u32();
    const std::uint32_t poses = u32(), values = u32();
    o.error = u32();
    o.poses.resize(poses);
    for (Transform& t : o.poses)
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) t(r, c) = f64();
    o.values.resize(values);
    for (double& v : o.values) v = f64();
  }
  EXPECT_EQ(at, frame.size()) << "bytes after the last object";
  return objects;
}

}  // namespace rp::test
