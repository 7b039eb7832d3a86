// A UrdfManipulator made in code (no rp.cfg) is drawn in the Scene Viewer with its URDF's own
// <visual> elements: the scene a page receives marks the arm and lists every visual as a shape
// (6 in tests/browser/data/visual_arm.urdf: two boxes, two cylinders, a sphere and an STL mesh).
#include <utility>  // before Boost 1.74's asio

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>
#include <unistd.h>

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

// Reads text messages from `ws` until one satisfies `take` (at most 400 messages).
json readUntil(websocket::stream<tcp::socket>& ws, const std::function<bool(const json&)>& take) {
  beast::flat_buffer buffer;
  for (int i = 0; i < 400; ++i) {
    ws.read(buffer);
    const bool text = !ws.got_binary();
    const std::string data = beast::buffers_to_string(buffer.data());
    buffer.consume(buffer.size());
    if (!text) continue;
    const json m = json::parse(data, nullptr, false);
    if (m.is_object() && take(m)) return m;
  }
  return nullptr;
}

// The mesh arm of the browser test moved out of its package and found through rp.cfg's
// packagePath: each shape names its link, the missing mesh says why and brings its link's
// collision box; a page's report of a mesh it cannot parse is printed on stderr once per file,
// and only for files the scene names.
TEST(UrdfScene, MeshesThroughThePackagePathAndTheirProblems) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("rp-urdf-scene-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string packages = std::string(RP_TEST_DATA_DIR) + "/packages";
  std::filesystem::copy_file(packages + "/rp_mesh_arm/urdf/mesh_arm.urdf", dir / "mesh_arm.urdf",
                             std::filesystem::copy_options::overwrite_existing);
  rp::RoboticPlatform::setConfiguration(rp::Configuration::parse(
      "[mesh_arm]\nclass UrdfManipulator\nurdf mesh_arm.urdf\ntip hand_link\npackagePath " + packages + "\n",
      (dir / "rp.cfg").string()));
  rp::RoboticPlatform::setSimulationModeOn();
  json arm;
  std::string printed, again, stranger, err;
  {
    rp::UrdfManipulator robot("mesh_arm");
    EXPECT_EQ(robot.getPackagePath(), std::vector<std::string>{std::filesystem::path(packages).lexically_normal().string()});
    rp::SceneViewer& viewer = rp::SceneViewer::instance();
    rp::SceneViewerOptions options;
    options.port = 0;
    testing::internal::CaptureStderr();
    viewer.start(options);
    const int port = viewer.getPort();
    asio::io_context ioc;
    websocket::stream<tcp::socket> ws(ioc);
    ws.next_layer().connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
    ws.handshake("127.0.0.1:" + std::to_string(port), "/ws");
    const json scene = readUntil(ws, [](const json& m) { return m.value("type", "") == "scene"; });
    for (const auto& o : scene["objects"])
      if (o.value("name", "") == "mesh_arm") arm = o;
    auto ask = [&](const json& request) {
      ws.write(asio::buffer(request.dump()));
      const json r = readUntil(ws, [&](const json& m) { return m.contains("id") && m["id"] == request["id"]; });
      return r.is_object() ? r.value("reply", "<" + r.dump() + ">") : std::string("<no reply>");
    };
    printed = ask({{"type", "meshFailed"}, {"id", 1}, {"object", "mesh_arm"}, {"shape", 2}, {"message", "bad\nXML"}});
    again = ask({{"type", "meshFailed"}, {"id", 2}, {"object", "mesh_arm"}, {"shape", 2}, {"message", "bad XML"}});
    stranger = ask({{"type", "meshFailed"}, {"id", 3}, {"object", "nobody"}, {"shape", 0}, {"message", "x"}});
    ws.close(websocket::close_code::normal);
    viewer.stop();
    err = testing::internal::GetCapturedStderr();
  }
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(arm.is_object()) << "the arm is not in the scene";
  ASSERT_EQ(arm["shapes"].size(), 7u) << arm.dump();
  const json& upper = arm["shapes"][1];
  EXPECT_EQ(upper.value("link", ""), "upper_link");
  EXPECT_EQ(upper.value("uri", ""), "package://rp_mesh_arm/meshes/upper_arm.dae");
  EXPECT_EQ(upper.value("mesh", ""),
            std::filesystem::path(packages + "/rp_mesh_arm/meshes/upper_arm.dae").lexically_normal().string());
  EXPECT_FALSE(upper.contains("meshError"));
  const json& sensor = arm["shapes"][5];
  EXPECT_EQ(sensor.value("link", ""), "sensor_link");
  EXPECT_NE(sensor.value("meshError", "").find("no such file"), std::string::npos) << sensor.dump();
  ASSERT_EQ(sensor["fallback"].size(), 1u);
  EXPECT_EQ(sensor["fallback"][0].value("kind", ""), "box");
  // The tag's collision mesh and the hand's texture are served after the visuals.
  EXPECT_EQ(arm["shapes"][4]["texture"].value("meshShape", -1), 7);
  EXPECT_EQ(arm["shapes"][6]["fallback"][0].value("meshShape", -1), 8);
  // The missing mesh was printed when the arm was described; the page's report once per file.
  EXPECT_EQ(printed, "printed");
  EXPECT_EQ(again, "");
  EXPECT_EQ(stranger, "");
  EXPECT_NE(err.find("mesh package://rp_mesh_arm/meshes/missing_sensor.dae of link 'sensor_link' of 'mesh_arm'"),
            std::string::npos) << err;
  EXPECT_NE(err.find("broken.dae of 'mesh_arm' cannot be drawn: bad XML"), std::string::npos) << err;
  rp::RoboticPlatform::setConfiguration(rp::Configuration());
}

}  // namespace
