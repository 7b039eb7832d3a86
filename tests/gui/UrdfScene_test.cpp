// A UrdfManipulator made in code (no rp.cfg) is drawn in the Scene Viewer with its URDF's own
// <visual> elements: the scene a page receives marks the arm and lists every visual as a shape
// (6 in tests/browser/data/visual_arm.urdf: two boxes, two cylinders, a sphere and an STL mesh).
#include <utility>  // before Boost 1.74's asio

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

#include "rp/RoboticPlatform.hpp"

namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using nlohmann::json;

TEST(UrdfScene, ArmMadeInCodeIsDrawnWithItsVisuals) {
  rp::RoboticPlatform::setConfiguration(rp::Configuration());
  rp::RoboticPlatform::setSimulationModeOn();
  const std::string file = std::string(RP_TEST_DATA_DIR) + "/visual_arm.urdf";
  rp::UrdfManipulator arm("visual_arm", file);
  EXPECT_EQ(arm.getUrdfFile(), file);
  EXPECT_EQ(arm.getTip(), "");

  rp::SceneViewer& viewer = rp::SceneViewer::instance();
  rp::SceneViewerOptions options;
  options.port = 0;
  viewer.start(options);
  const int port = viewer.getPort();
  asio::io_context ioc;
  websocket::stream<tcp::socket> ws(ioc);
  ws.next_layer().connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  ws.handshake("127.0.0.1:" + std::to_string(port), "/ws");

  // The whole scene is sent to every page that connects.
  json described;
  beast::flat_buffer buffer;
  for (int i = 0; i < 200 && described.is_null(); ++i) {
    ws.read(buffer);
    if (!ws.got_binary()) {
      const json m = json::parse(beast::buffers_to_string(buffer.data()), nullptr, false);
      if (m.is_object() && m.value("type", "") == "scene")
        for (const auto& o : m["objects"])
          if (o.value("name", "") == "visual_arm") described = o;
    }
    buffer.consume(buffer.size());
  }
  ws.close(websocket::close_code::normal);
  viewer.stop();
  ASSERT_FALSE(described.is_null()) << "the arm is not in the scene";
  EXPECT_EQ(described.value("className", ""), "UrdfManipulator");
  EXPECT_TRUE(described.value("urdfVisuals", false)) << described.dump();
  ASSERT_TRUE(described["shapes"].is_array());
  EXPECT_EQ(described["shapes"].size(), 6u);
  int meshes = 0;
  for (const auto& s : described["shapes"]) meshes += s.value("kind", "") == "mesh";
  EXPECT_EQ(meshes, 1);
}

}  // namespace
