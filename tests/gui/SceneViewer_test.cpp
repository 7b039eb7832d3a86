// The Scene Viewer server without a browser: listening, port fallback, token rules, HTTP paths,
// the WebSocket handshake rules and the platform switches. (tests/browser drives it with Chromium.)
#include "rp/gui/SceneViewer.hpp"

#include <utility>  // before Boost 1.74's asio

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <gtest/gtest.h>

#include <string>

#include "rp/core/RoboticPlatform.hpp"

namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;

struct Reply {
  int status = 0;
  std::string body;
};

Reply get(int port, const std::string& target, const std::string& origin = "", bool upgrade = false) {
  asio::io_context ioc;
  tcp::socket socket(ioc);
  socket.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  http::request<http::empty_body> req(http::verb::get, target, 11);
  req.set(http::field::host, "127.0.0.1:" + std::to_string(port));
  if (!origin.empty()) req.set(http::field::origin, origin);
  if (upgrade) {
    req.set(http::field::connection, "Upgrade");
    req.set(http::field::upgrade, "websocket");
    req.set(http::field::sec_websocket_version, "13");
    req.set(http::field::sec_websocket_key, "dGhlIHNhbXBsZSBub25jZQ==");
  }
  http::write(socket, req);
  beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  parser.skip(upgrade);  // a 101 has no body
  http::read_header(socket, buffer, parser);
  Reply r;
  r.status = static_cast<int>(parser.get().result_int());
  if (r.status != 101) {
    http::read(socket, buffer, parser);
    r.body = parser.get().body();
  }
  return r;
}

TEST(SceneViewer, ServesFilesAndRefusesBadPaths) {
  rp::SceneViewer& v = rp::SceneViewer::instance();
  rp::SceneViewerOptions o;
  o.port = 0;
  v.start(o);
  ASSERT_TRUE(v.isRunning());
  const int port = v.getPort();
  EXPECT_GT(port, 0);
  EXPECT_EQ(v.getUrl(), "http://127.0.0.1:" + std::to_string(port) + "/index.html");
  EXPECT_EQ(v.getToken(), "");
  EXPECT_THROW(v.start(o), std::logic_error);
  Reply index = get(port, "/");
  EXPECT_EQ(index.status, 200);
  EXPECT_NE(index.body.find("Robotic Platform"), std::string::npos);
  EXPECT_EQ(get(port, "/../../etc/passwd").status, 400);
  EXPECT_EQ(get(port, "/%2e%2e/etc/passwd").status, 400);
  EXPECT_EQ(get(port, "/no-such-file.js").status, 404);
  EXPECT_EQ(get(port, "/api/info").body, "{\"protocol\":1,\"tokenRequired\":false}");
  // WebSocket handshake: right path and no Origin (not a browser) or our own Origin.
  EXPECT_EQ(get(port, "/ws", "", true).status, 101);
  EXPECT_EQ(get(port, "/ws", "http://127.0.0.1:" + std::to_string(port), true).status, 101);
  EXPECT_EQ(get(port, "/ws", "http://evil.example", true).status, 403);
  EXPECT_EQ(get(port, "/other", "", true).status, 403);
  EXPECT_EQ(v.getStatistics().handshakesRefused, 2u);
  v.stop();
  EXPECT_FALSE(v.isRunning());
  EXPECT_EQ(v.getUrl(), "");
  v.stop();  // twice is fine
}

TEST(SceneViewer, TokenRules) {
  rp::SceneViewer& v = rp::SceneViewer::instance();
  rp::SceneViewerOptions o;
  o.port = 0;
  o.token = "secret";
  v.start(o);
  const int port = v.getPort();
  EXPECT_EQ(v.getUrl(), "http://127.0.0.1:" + std::to_string(port) + "/index.html?token=secret");
  EXPECT_EQ(get(port, "/ws", "", true).status, 403);
  EXPECT_EQ(get(port, "/ws?token=wrong", "", true).status, 403);
  EXPECT_EQ(get(port, "/ws?token=secrets", "", true).status, 403);
  EXPECT_EQ(get(port, "/ws?token=secret", "", true).status, 101);
  v.stop();
  // Any address other than loopback: a token is generated.
  o.token.clear();
  o.address = "0.0.0.0";
  v.start(o);
  EXPECT_EQ(v.getToken().size(), 32u);
  EXPECT_NE(v.getUrl().find("?token=" + v.getToken()), std::string::npos);
  EXPECT_EQ(get(v.getPort(), "/ws", "", true).status, 403);
  v.stop();
}

TEST(SceneViewer, PortFallbackAndErrors) {
  // Occupy a port, then ask for it explicitly: an error naming it.
  asio::io_context ioc;
  tcp::acceptor taken(ioc, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  const int busy = taken.local_endpoint().port();
  rp::SceneViewer& v = rp::SceneViewer::instance();
  rp::SceneViewerOptions o;
  o.port = busy;
  try {
    v.start(o);
    FAIL() << "started on a busy port";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(":" + std::to_string(busy)), std::string::npos) << e.what();
  }
  EXPECT_FALSE(v.isRunning());
  // The default port falls back to another free one when taken.
  tcp::acceptor defaultTaken(ioc);
  boost::system::error_code ec;
  defaultTaken.open(tcp::v4());
  defaultTaken.bind(tcp::endpoint(asio::ip::make_address("127.0.0.1"), rp::kSceneViewerDefaultPort), ec);
  if (!ec) defaultTaken.listen();
  o.port = rp::kSceneViewerDefaultPort;
  v.start(o);
  if (!ec) {  // (else another program holds it)
    EXPECT_NE(v.getPort(), rp::kSceneViewerDefaultPort);
  }
  EXPECT_GT(v.getPort(), 0);
  v.stop();
  o.port = 0;
  o.rate = 0;
  EXPECT_THROW(v.start(o), std::invalid_argument);
  o.rate = 60;
  o.address = "localhost:80";
  EXPECT_THROW(v.start(o), std::invalid_argument);
  EXPECT_TRUE(rp::SceneViewer::isLoopbackAddress("127.0.0.1"));
  EXPECT_TRUE(rp::SceneViewer::isLoopbackAddress("127.1.2.3"));
  EXPECT_TRUE(rp::SceneViewer::isLoopbackAddress("::1"));
  EXPECT_FALSE(rp::SceneViewer::isLoopbackAddress("0.0.0.0"));
  EXPECT_FALSE(rp::SceneViewer::isLoopbackAddress("192.168.1.2"));
  EXPECT_FALSE(rp::SceneViewer::isLoopbackAddress("not an address"));
}

TEST(SceneViewer, PlatformSwitches) {
  auto rest = rp::RoboticPlatform::parseCommandLine({"-gui-address", "0.0.0.0", "-gui-port", "8123", "-gui-token", "abc", "x"});
  EXPECT_EQ(rest, std::vector<std::string>{"x"});
  EXPECT_EQ(rp::RoboticPlatform::getGuiAddress(), "0.0.0.0");
  EXPECT_EQ(rp::RoboticPlatform::getGuiPort(), 8123);
  EXPECT_EQ(rp::RoboticPlatform::getGuiToken(), "abc");
  for (const char* bad : {"-1", "65536", "80x", "", "port"}) {
    try {
      rp::RoboticPlatform::parseCommandLine({"-gui-port", bad});
      FAIL() << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("-gui-port"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(rp::RoboticPlatform::parseCommandLine({"-gui-address"}), std::invalid_argument);
  EXPECT_THROW(rp::RoboticPlatform::setGuiPort(70000), std::invalid_argument);
  rp::RoboticPlatform::setGuiAddress("127.0.0.1");
  rp::RoboticPlatform::setGuiPort(-1);
  rp::RoboticPlatform::setGuiToken("");
}

}  // namespace
