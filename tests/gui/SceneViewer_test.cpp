// The Scene Viewer server without a browser: listening, port fallback, token rules, HTTP paths,
// the WebSocket handshake rules and the platform switches. (tests/browser drives it with Chromium.)
#include "rp/gui/SceneViewer.hpp"

#include <utility>  // before Boost 1.74's asio

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "rp/core/ObjectManager.hpp"
#include "rp/core/PhysicalObject.hpp"

#include "rp/core/RoboticPlatform.hpp"

extern char** environ;

namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;

struct Reply {
  int status = 0;
  std::string body;
  http::fields headers;
};

// A GET of `target` (sent as is) with the Host header `host` (default 127.0.0.1:PORT; "-" sends none).
Reply get(int port, const std::string& target, const std::string& origin = "", bool upgrade = false,
          const std::string& host = "") {
  asio::io_context ioc;
  tcp::socket socket(ioc);
  socket.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  http::request<http::empty_body> req(http::verb::get, target, 11);
  if (host != "-") req.set(http::field::host, host.empty() ? "127.0.0.1:" + std::to_string(port) : host);
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
  r.headers = parser.get().base();
  if (r.status != 101) {
    http::read(socket, buffer, parser);
    r.body = parser.get().body();
  }
  return r;
}

// Sends `request` as it is and returns everything the server sends until it closes.
std::string rawRequest(int port, const std::string& request) {
  asio::io_context ioc;
  tcp::socket socket(ioc);
  socket.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  asio::write(socket, asio::buffer(request));
  std::string out;
  beast::error_code ec;
  char chunk[4096];
  for (;;) {
    const std::size_t got = socket.read_some(asio::buffer(chunk), ec);
    out.append(chunk, got);
    if (ec) break;
  }
  return out;
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
  EXPECT_EQ(get(port, "/../../etc/passwd").status, 404);
  EXPECT_EQ(get(port, "/%2e%2e/etc/passwd").status, 404);
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

// A web root of its own: index.html, assets/app.js, a link out of the root, a hidden file and a
// file over the size cap.
struct WebRoot {
  std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("rp_gui_webroot_" + std::to_string(::getpid()));
  WebRoot() {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir / "assets");
    std::ofstream(dir / "index.html") << "<html>the front end</html>";
    std::ofstream(dir / "assets" / "app.js") << "console.log('app');";
    std::ofstream(dir / ".secret") << "hidden";
    std::filesystem::create_symlink("/etc/passwd", dir / "leak.txt");
    std::filesystem::create_directory_symlink("/etc", dir / "etc-link");
    std::ofstream(dir / "big.js").close();
    std::filesystem::resize_file(dir / "big.js", (16u << 20) + 1);  // sparse: one byte over the cap
  }
  ~WebRoot() { std::filesystem::remove_all(dir); }
};

TEST(SceneViewer, ServesOnlyTheFrontEndFiles) {
  WebRoot root;
  rp::SceneViewer& v = rp::SceneViewer::instance();
  rp::SceneViewerOptions o;
  o.port = 0;
  o.webRoot = root.dir.string();
  v.start(o);
  const int port = v.getPort();
  Reply index = get(port, "/");
  EXPECT_EQ(index.status, 200);
  EXPECT_EQ(index.body, "<html>the front end</html>");
  EXPECT_EQ(get(port, "/assets/app.js").body, "console.log('app');");
  EXPECT_EQ(get(port, "/assets/app.js?v=1").status, 200);
  // Every way out of the web root, plain, doubled, encoded and absolute: not found, and not one
  // byte of the file.
  for (const char* target :
       {"//etc/passwd", "///etc/passwd", "////etc/passwd", "//proc/self/cmdline", "//proc/self/environ",
        "//proc/self/fd/2", "/assets//etc/passwd", "/assets///etc/passwd", "/../../etc/passwd", "/./../etc/passwd",
        "/assets/../../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd", "/%2E%2E/%2E%2E/etc/passwd",
        "/..%2f..%2f..%2fetc/passwd", "/..%2F..%2Fetc%2Fpasswd", "/%2f%2fetc/passwd", "/%2Fetc%2Fpasswd",
        "/%252e%252e/etc/passwd", "/..\\..\\etc\\passwd", "/\\etc\\passwd", "/etc/passwd", "/proc/self/cmdline",
        "http://127.0.0.1/etc/passwd", "http://127.0.0.1//etc/passwd", "file:///etc/passwd", "etc/passwd",
        "/leak.txt", "/etc-link/passwd", "/.secret", "/assets/", "/assets", "/big.js", "/index.html%00.js",
        "/index.html/.", "/.", "/./index.html"}) {
    SCOPED_TRACE(target);
    Reply r = get(port, target);
    EXPECT_EQ(r.status, 404);
    EXPECT_EQ(r.body.find("root:"), std::string::npos);
    EXPECT_EQ(r.body.find("gui_scene_viewer_test"), std::string::npos);
    EXPECT_EQ(r.body.find("hidden"), std::string::npos);
  }
  v.stop();
}

TEST(SceneViewer, HostHeaderAndFraming) {
  rp::SceneViewer& v = rp::SceneViewer::instance();
  rp::SceneViewerOptions o;
  o.port = 0;
  v.start(o);
  const int port = v.getPort();
  const std::string p = std::to_string(port);
  for (const std::string& host : std::vector<std::string>{"127.0.0.1", "127.0.0.1:" + p, "localhost", "LocalHost:" + p, "localhost.:1234",
                                 "[::1]", "[::1]:" + p, "127.0.0.2:80"}) {
    SCOPED_TRACE(host);
    EXPECT_EQ(get(port, "/api/info", "", false, host).status, 200);
    EXPECT_EQ(get(port, "/ws", "", true, host).status, 101);
  }
  // A DNS name made to point at 127.0.0.1 (rebinding), another address, malformed or no Host.
  int refused = 0;
  for (const std::string& host : std::vector<std::string>{"evil.example", "evil.example:" + p, "localhost.evil.example", "127.0.0.1.evil.example",
                                 "192.168.1.20", "[::1", "::1", "127.0.0.1:80x", "127.0.0.1:", "-"}) {
    SCOPED_TRACE(host);
    Reply r = get(port, "/index.html", "", false, host);
    EXPECT_EQ(r.status, 403);
    EXPECT_EQ(r.body.find("<html"), std::string::npos);
    EXPECT_EQ(get(port, "/ws", "", true, host).status, 403);
    ++refused;
  }
  EXPECT_EQ(v.getStatistics().handshakesRefused, static_cast<std::uint64_t>(refused));
  // Two Host headers, in either order: refused (only the first used to be checked).
  for (const std::string& hosts : std::vector<std::string>{"Host: 127.0.0.1:" + p + "\r\nHost: evil.example\r\n",
                                                           "Host: evil.example\r\nHost: 127.0.0.1:" + p + "\r\n",
                                                           "Host: 127.0.0.1:" + p + "\r\nHost: 127.0.0.1:" + p + "\r\n"}) {
    SCOPED_TRACE(hosts);
    const std::string head = rawRequest(port, "GET /index.html HTTP/1.1\r\n" + hosts + "Connection: close\r\n\r\n");
    EXPECT_EQ(head.substr(0, 12), "HTTP/1.1 403") << head;
    EXPECT_EQ(head.find("<html"), std::string::npos);
  }
  // HEAD: the length a GET would send, and no body.
  {
    const std::string head = rawRequest(port, "HEAD /api/info HTTP/1.1\r\nHost: 127.0.0.1:" + p + "\r\nConnection: close\r\n\r\n");
    const std::string body = get(port, "/api/info").body;
    EXPECT_EQ(head.substr(0, 12), "HTTP/1.1 200") << head;
    EXPECT_NE(head.find("Content-Length: " + std::to_string(body.size()) + "\r\n"), std::string::npos) << head;
    EXPECT_EQ(head.substr(head.find("\r\n\r\n") + 4), "") << "a HEAD reply with a body";
  }
  // No other site may put the pages in a frame.
  Reply index = get(port, "/");
  EXPECT_EQ(index.headers["X-Frame-Options"], "DENY");
  EXPECT_EQ(index.headers["Content-Security-Policy"], "frame-ancestors 'none'");
  EXPECT_EQ(index.headers["Referrer-Policy"], "no-referrer");
  EXPECT_EQ(get(port, "/no-such-file").headers["X-Frame-Options"], "DENY");
  v.stop();

  // Listening on a given address accepts it; on every address any IP literal and the machine's name.
  o.address = "0.0.0.0";
  v.start(o);
  const int any = v.getPort();
  const std::string token = "/ws?token=" + v.getToken();
  EXPECT_EQ(get(any, token, "", true, "192.168.1.20:" + std::to_string(any)).status, 101);
  EXPECT_EQ(get(any, token, "", true, boost::asio::ip::host_name()).status, 101);
  EXPECT_EQ(get(any, token, "", true, "evil.example").status, 403);
  v.stop();
}

TEST(SceneViewer, TokenRules) {
  rp::SceneViewer& v = rp::SceneViewer::instance();
  rp::SceneViewerOptions o;
  o.port = 0;
  o.token = "secret";
  testing::internal::CaptureStderr();
  v.start(o);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");  // loopback: no warning
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
  testing::internal::CaptureStderr();
  v.start(o);
  const std::string warning = testing::internal::GetCapturedStderr();
  EXPECT_NE(warning.find("rp: warning: the Scene Viewer listens on 0.0.0.0:" + std::to_string(v.getPort())),
            std::string::npos) << warning;
  EXPECT_EQ(v.getToken().size(), 32u);
  EXPECT_NE(v.getUrl().find("?token=" + v.getToken()), std::string::npos);
  EXPECT_EQ(get(v.getPort(), "/ws", "", true).status, 403);
  v.stop();
  // A token the page could not present in the URL as it is (the server does not percent-decode)
  // is refused at the start, not taken to lock every page out.
  o.address = "127.0.0.1";
  for (const std::string& bad : std::vector<std::string>{"a&b c", "a b", "x#y", "t%26", "caf\xc3\xa9", std::string(257, 'a')}) {
    o.token = bad;
    EXPECT_THROW(v.start(o), std::invalid_argument) << bad;
    EXPECT_FALSE(v.isRunning()) << bad;
  }
  o.token = "Az09-._~";
  v.start(o);
  EXPECT_EQ(get(v.getPort(), "/ws?token=Az09-._~", "", true).status, 101);
  v.stop();
}

// Stops the viewer at the end of a test, also one that failed an ASSERT.
struct StopViewerAtEnd {
  ~StopViewerAtEnd() { rp::SceneViewer::instance().stop(); }
};

// An open TCP connection to the viewer that sends nothing.
std::unique_ptr<tcp::socket> idleConnection(asio::io_context& ioc, int port) {
  auto s = std::make_unique<tcp::socket>(ioc);
  s->connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  return s;
}

// Polls `done` every 20 ms for up to a minute (a loaded machine is slow, never wrong).
template <class F>
bool waitFor(F done) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

TEST(SceneViewer, ConnectionCap) {
  StopViewerAtEnd stopAtEnd;
  rp::SceneViewer& v = rp::SceneViewer::instance();
  rp::SceneViewerOptions o;
  o.port = 0;
  v.start(o);
  const int port = v.getPort();
  asio::io_context ioc;
  // A page first: pages are never closed to make room.
  boost::beast::websocket::stream<tcp::socket> page(ioc);
  page.next_layer().connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  page.handshake("127.0.0.1:" + std::to_string(port), "/ws");
  // 200 connections that never send a request (300 of them once took the server down).
  std::vector<std::unique_ptr<tcp::socket>> idle;
  for (int i = 0; i < 200; ++i) idle.push_back(idleConnection(ioc, port));
  std::size_t most = 0;
  ASSERT_TRUE(waitFor([&] {
    const rp::SceneViewerStatistics s = v.getStatistics();
    most = std::max(most, s.openConnections);
    return s.connectionsClosedForRoom + s.connectionsRefused >= 200 + 1 - rp::kSceneViewerMaxConnections;
  })) << v.getStatistics().connectionsClosedForRoom;
  EXPECT_LE(most, rp::kSceneViewerMaxConnections);
  EXPECT_LE(v.getStatistics().openConnections, rp::kSceneViewerMaxConnections);
  EXPECT_EQ(v.getStatistics().connectionsRefused, 0u);  // each took an idle one's place
  // Pages are still served, and the page is still connected.
  EXPECT_EQ(get(port, "/api/info").status, 200);
  EXPECT_EQ(v.getStatistics().pages, 1u);
  page.write(asio::buffer(std::string(R"({"type":"ping","id":7})")));
  for (;;) {
    beast::flat_buffer buffer;
    page.read(buffer);
    if (beast::buffers_to_string(buffer.data()).find("\"pong\"") != std::string::npos) break;
  }
  v.stop();
}

// A page that stops reading is dropped once a write to it has waited writeTimeout.
TEST(SceneViewer, PageThatStopsReadingIsDropped) {
  StopViewerAtEnd stopAtEnd;
  // 300 objects: state frames of about 44 kB, 240 a second, fill the socket buffers quickly.
  std::vector<std::unique_ptr<rp::PhysicalObject>> objects;
  for (int i = 0; i < 300; ++i) {
    objects.push_back(std::make_unique<rp::PhysicalObject>("slowPageObject" + std::to_string(i)));
    objects.back()->publishObject();
  }
  rp::SceneViewer& v = rp::SceneViewer::instance();
  rp::SceneViewerOptions o;
  o.port = 0;
  o.rate = 240;
  o.writeTimeout = 1;
  v.start(o);
  const int port = v.getPort();
  asio::io_context ioc;
  boost::beast::websocket::stream<tcp::socket> page(ioc);
  page.next_layer().open(tcp::v4());
  page.next_layer().set_option(asio::socket_base::receive_buffer_size(4096));
  page.next_layer().connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  page.handshake("127.0.0.1:" + std::to_string(port), "/ws");
  ASSERT_TRUE(waitFor([&] { return v.getStatistics().pages == 1; }));
  // ...and never reads.
  ASSERT_TRUE(waitFor([&] { return v.getStatistics().slowPagesDropped == 1; }));
  EXPECT_EQ(v.getStatistics().pages, 0u);
  v.stop();
  objects.clear();
  rp::SceneViewerOptions bad;
  bad.writeTimeout = 0;
  EXPECT_THROW(v.start(bad), std::invalid_argument);
}

// The viewer in a child process (gui_fd_limit_server) with its file descriptors used up.
class FdLimitServer {
 public:
  FdLimitServer() {
    int in[2], out[2];
    if (::pipe2(in, O_CLOEXEC) != 0 || ::pipe2(out, O_CLOEXEC) != 0) throw std::runtime_error("pipe");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, in[0], 0);
    posix_spawn_file_actions_adddup2(&actions, out[1], 1);
    const std::string server = RP_FD_LIMIT_SERVER;
    const char* argv[] = {server.c_str(), "128", nullptr};
    const int rc = posix_spawn(&pid_, server.c_str(), &actions, nullptr, const_cast<char**>(argv), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(in[0]);
    ::close(out[1]);
    if (rc != 0) throw std::runtime_error("cannot start " + server);
    to_ = ::fdopen(in[1], "w");
    from_ = ::fdopen(out[0], "r");
  }
  ~FdLimitServer() {
    std::fclose(to_);  // end of its input: it stops
    std::fclose(from_);
    int status = 0;
    ::waitpid(pid_, &status, 0);
  }
  FdLimitServer(const FdLimitServer&) = delete;
  FdLimitServer& operator=(const FdLimitServer&) = delete;
  // Sends a command and returns the line it answers.
  std::string ask(const std::string& command) {
    if (!command.empty()) {
      std::fputs((command + "\n").c_str(), to_);
      std::fflush(to_);
    }
    char line[256];
    if (!std::fgets(line, sizeof line, from_)) return {};
    return line;
  }
  std::uint64_t acceptFailures() {
    std::istringstream s(ask("stats"));
    std::string word;
    std::uint64_t pages = 0, open = 0, closed = 0, refused = 0, failures = 0;
    s >> word >> pages >> open >> closed >> refused >> failures;
    return failures;
  }

 private:
  pid_t pid_ = 0;
  FILE* to_ = nullptr;
  FILE* from_ = nullptr;
};

TEST(SceneViewer, OutOfFileDescriptors) {
#if defined(__SANITIZE_ADDRESS__)
  // The sanitizer build has UBSan too, whose vptr check tests memory through a pipe: in a
  // process with no descriptor left it reports every virtual call as an invalid vptr.
  GTEST_SKIP() << "UBSan needs a free file descriptor; this test runs in the release and TSan builds";
#endif
  FdLimitServer server;
  int port = 0;
  ASSERT_EQ(std::sscanf(server.ask("").c_str(), "port %d", &port), 1);
  ASSERT_EQ(server.ask("fill").rfind("filled ", 0), 0u);
  // Connections wait in the listen queue: every accept fails (no descriptor left).
  asio::io_context ioc;
  std::vector<std::unique_ptr<tcp::socket>> waiting;
  for (int i = 0; i < 5; ++i) waiting.push_back(idleConnection(ioc, port));
  tcp::socket& client = *waiting.back();
  const std::string request = "GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
  asio::write(client, asio::buffer(request));
  ASSERT_TRUE(waitFor([&] { return server.acceptFailures() >= 4; }));
  // It pauses between attempts (10 ms, doubling up to 1 s) instead of spinning on the readable
  // listening socket: within the next 1.5 s at most 1500 / 80 attempts (a spinning server made
  // hundreds of thousands).
  const std::uint64_t before = server.acceptFailures();
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  EXPECT_LE(server.acceptFailures() - before, 20u);
  // With descriptors again, the waiting request is answered.
  ASSERT_EQ(server.ask("release"), "released\n");
  ::timeval timeout{60, 0};
  ::setsockopt(client.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  beast::flat_buffer buffer;
  http::response<http::string_body> res;
  http::read(client, buffer, res);
  EXPECT_EQ(res.result_int(), 200u);
  EXPECT_EQ(res.body(), "{\"protocol\":1,\"tokenRequired\":false}");
}

// A page of the viewer (Boost.Beast WebSocket client) that reads JSON text messages.
class Page {
 public:
  explicit Page(int port) : ws_(ioc_) {
    ws_.next_layer().connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
    ws_.handshake("127.0.0.1:" + std::to_string(port), "/ws");
    ::timeval timeout{60, 0};  // a message that never comes fails the test instead of hanging it
    ::setsockopt(ws_.next_layer().native_handle(), SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  }
  void send(const std::string& text) { ws_.write(asio::buffer(text)); }
  // The next text message of type `type` (state frames and other messages are skipped).
  nlohmann::json next(const std::string& type) {
    for (;;) {
      beast::flat_buffer buffer;
      ws_.read(buffer);
      if (!ws_.got_text()) continue;
      nlohmann::json m = nlohmann::json::parse(beast::buffers_to_string(buffer.data()));
      if (m.value("type", "") == type) return m;
    }
  }

 private:
  asio::io_context ioc_;
  boost::beast::websocket::stream<tcp::socket> ws_;
};

// An object that reports an error, as an arm does before it asks for a safety shutdown.
class FaultyObject : public rp::PhysicalObject {
 public:
  FaultyObject() : rp::PhysicalObject("faultyArm") {
    setError(7, "joint 2 beyond its limit");
    publishObject();
  }
  ~FaultyObject() override { withdrawObject(); }
};

TEST(SceneViewer, ShutdownIsShownOnEveryPage) {
  StopViewerAtEnd stopAtEnd;
  FaultyObject faulty;
  rp::SceneViewer& v = rp::SceneViewer::instance();
  rp::SceneViewerOptions o;
  o.port = 0;
  v.start(o);
  Page page(v.getPort());
  page.next("hello");
  rp::ObjectManager::requestSystemShutdown("faultyArm: joint 2 beyond its limit");
  const nlohmann::json m = page.next("shutdown");
  EXPECT_EQ(m["reason"], "faultyArm: joint 2 beyond its limit");
  ASSERT_EQ(m["objects"].size(), 1u) << m.dump();
  EXPECT_EQ(m["objects"][0]["name"], "faultyArm");
  EXPECT_EQ(m["objects"][0]["code"], 7);
  EXPECT_EQ(m["objects"][0]["message"], "joint 2 beyond its limit");
  const std::string time = m["time"];
  EXPECT_EQ(time.size(), 24u) << time;  // 2026-11-24T23:59:59.123Z
  EXPECT_EQ(time.back(), 'Z');
  // A page that connects later is told too, right after hello.
  Page later(v.getPort());
  later.next("hello");
  EXPECT_EQ(later.next("shutdown")["reason"], "faultyArm: joint 2 beyond its limit");
  EXPECT_TRUE(rp::ObjectManager::waitForShutdown(60));
  v.stop();
  rp::ObjectManager::resetShutdown();
}

TEST(SceneViewer, EmergencyStopFromAPage) {
  StopViewerAtEnd stopAtEnd;
  rp::SceneViewer& v = rp::SceneViewer::instance();
  rp::SceneViewerOptions o;
  o.port = 0;
  v.start(o);
  Page page(v.getPort()), other(v.getPort());
  page.next("hello");
  other.next("hello");
  ASSERT_FALSE(rp::ObjectManager::isShutdownRequested());
  page.send(R"({"type":"emergencyStop","id":3})");
  EXPECT_EQ(page.next("result")["id"], 3);
  EXPECT_TRUE(rp::ObjectManager::isShutdownRequested());
  EXPECT_EQ(rp::ObjectManager::getShutdownReason(), "emergency stop from the Scene Viewer");
  EXPECT_EQ(other.next("shutdown")["reason"], "emergency stop from the Scene Viewer");
  EXPECT_TRUE(rp::ObjectManager::waitForShutdown(60));
  v.stop();
  rp::ObjectManager::resetShutdown();
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
  for (const char* bad : {"a&b c", "t?x", "a/b"}) {
    try {
      rp::RoboticPlatform::parseCommandLine({"-gui-token", bad});
      FAIL() << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("-gui-token"), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find(bad), std::string::npos) << "the refused token (a secret) is repeated";
    }
  }
  EXPECT_THROW(rp::RoboticPlatform::setGuiToken("a b"), std::invalid_argument);
  EXPECT_EQ(rp::RoboticPlatform::getGuiToken(), "abc") << "a refused token replaced the last";
  EXPECT_THROW(rp::RoboticPlatform::setGuiPort(70000), std::invalid_argument);
  rp::RoboticPlatform::setGuiAddress("127.0.0.1");
  rp::RoboticPlatform::setGuiPort(-1);
  rp::RoboticPlatform::setGuiToken("");
}

}  // namespace
