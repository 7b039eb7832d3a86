// The Scene Viewer with a page connected while objects are created and destroyed: the server
// thread describes and reads them and the worker runs commands on them, and none of this may
// touch an object being constructed or destroyed (labelled "threads": ThreadSanitizer checks it).
#include <utility>  // before Boost 1.74's asio

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <set>
#include <string>
#include <thread>

#include "rp/core/ObjectManager.hpp"
#include "rp/core/PhysicalObject.hpp"
#include "rp/effector/DefaultGripper.hpp"
#include "rp/gui/SceneViewer.hpp"
#include "rp/manipulator/Puma560.hpp"

namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using nlohmann::json;

std::atomic<int> outsideLifetime{0};  // reads of a Probe outside its published window

// A physical object that publishes itself last in its constructor and withdraws first in its
// destructor, and counts any virtual call that arrives outside that window.
class Probe : public rp::PhysicalObject {
 public:
  explicit Probe(const std::string& name) : rp::PhysicalObject(name) {
    addCommand("Poke", [this] { check(); }, "a command for the test");
    alive_ = true;
    publishObject();
  }
  ~Probe() override {
    withdrawObject();
    alive_ = false;
  }
  rp::Model3D get3DModel() const override {
    check();
    return rp::PhysicalObject::get3DModel();
  }
  bool getStateSnapshot(rp::StateSnapshot& s) const override {
    check();
    s.size = 1;
    s.values[0] = 1;
    return true;
  }
  rp::ControlPanel getControlPanel() const override {
    check();
    return rp::PhysicalObject::getControlPanel();
  }

 private:
  void check() const {
    if (!alive_) ++outsideLifetime;
  }
  bool alive_ = false;  // plain bool: a read outside the window is also a race ThreadSanitizer reports
};

TEST(SceneViewerChurn, PageConnectedWhileObjectsComeAndGo) {
  rp::SceneViewer& viewer = rp::SceneViewer::instance();
  rp::SceneViewerOptions options;
  options.port = 0;
  options.rate = 120;
  viewer.start(options);
  const int port = viewer.getPort();

  asio::io_context ioc;
  websocket::stream<tcp::socket> ws(ioc);
  ws.next_layer().connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  ws.handshake("127.0.0.1:" + std::to_string(port), "/ws");

  // The page: one thread that sends commands to the objects of the current generation and reads
  // what the server sends (state frames arrive at 120 Hz, so a read never waits long).
  std::atomic<bool> stop{false};
  std::atomic<int> generation{0};
  std::atomic<int> frames{0}, scenes{0}, results{0}, errors{0};
  std::set<std::string> described;  // churned objects the scene described with their class
  std::thread page([&] {
    beast::flat_buffer buffer;
    beast::error_code ec;
    auto send = [&](const json& m) {
      ws.text(true);
      ws.write(asio::buffer(m.dump()), ec);
    };
    for (int i = 0; !stop && !ec; ++i) {
      const std::string k = std::to_string(generation.load());
      send({{"type", "command"}, {"object", "probe_" + k}, {"command", "Poke"}, {"id", i}});
      send({{"type", "display"}, {"object", "probe_" + k}, {"mode", i % 2 ? "wireframe" : "solid"}, {"id", i}});
      send({{"type", "command"}, {"object", "tool_" + k}, {"command", i % 2 ? "Open" : "Close"}, {"id", i}});
      send({{"type", "setParameter"}, {"object", "arm_" + k}, {"name", "kp"}, {"index", 0}, {"value", 1000.0}, {"id", i}});
      for (int r = 0; r < 4 && !ec; ++r) {
        ws.read(buffer, ec);
        if (ec) break;
        if (ws.got_binary()) {
          ++frames;
        } else {
          json m = json::parse(beast::buffers_to_string(buffer.data()), nullptr, false);
          const std::string type = m.is_object() ? m.value("type", "") : "";
          if (type == "scene") {
            ++scenes;
            for (const auto& o : m["objects"])
              if (o.value("className", "") != "") described.insert(o.value("name", ""));
          } else if (type == "result") {
            ++results;
          } else if (type == "error") {
            ++errors;
          }
        }
        buffer.consume(buffer.size());
      }
    }
    ws.close(websocket::close_code::normal, ec);
  });

  for (int k = 1; k <= 12; ++k) {
    generation = k;
    {
      rp::Puma560 arm("arm_" + std::to_string(k));
      rp::DefaultGripper tool("tool_" + std::to_string(k));
      tool.setConnection(arm, "endEffector");
      tool.publishObject();  // already published by its class: publishing again changes nothing
      Probe probe("probe_" + std::to_string(k));
      rp::PhysicalObject plain("plain_" + std::to_string(k));  // never published: listed by name only
      std::this_thread::sleep_for(std::chrono::milliseconds(k % 3 == 0 ? 400 : 30));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(k % 2 ? 0 : 20));
  }
  // Let the viewer see the last objects gone, then close.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  stop = true;
  page.join();
  viewer.stop();

  EXPECT_EQ(outsideLifetime.load(), 0);
  EXPECT_GT(frames.load(), 0);
  EXPECT_GT(scenes.load(), 1);
  EXPECT_GT(results.load() + errors.load(), 0);
  // The objects that lived 400 ms were described with their class by the scene; a never-published
  // object never is.
  EXPECT_TRUE(described.count("arm_3") && described.count("tool_3") && described.count("probe_3"))
      << "described: " << json(described).dump();
  for (const auto& name : described) EXPECT_NE(name.rfind("plain_", 0), 0u) << name;
}

}  // namespace
