// The Scene Viewer server: HTTP + WebSocket (Boost.Beast) on its own thread, a worker thread for
// commands that touch objects, state frames at display rate. See docs/gui.md for the protocol.
#include "rp/gui/SceneViewer.hpp"

#include <utility>  // before Boost 1.74's asio, which uses std::exchange without including it

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <list>
#include <mutex>
#include <random>
#include <set>
#include <thread>

#include "../core/ShortNumber.hpp"
#include "OpenInBrowser.hpp"
#include "QMotorRequests.hpp"
#include "SceneState.hpp"
#include "UrlToken.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/core/PhysicalObject.hpp"
#include "rp/core/RoboticPlatform.hpp"
#include "rp/rt/ControlProgram.hpp"
#include "rp/rt/LogWriter.hpp"

namespace rp {

namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using nlohmann::json;

constexpr std::size_t kMaxMessageBytes = 64 * 1024;  // largest WebSocket message accepted
constexpr std::size_t kMaxTextQueue = 256;           // replies and scenes waiting for a slow page
constexpr std::size_t kMaxWorkQueue = 128;           // commands waiting for the worker thread
constexpr std::size_t kMaxStringField = 256;         // longest name, command or message type
constexpr std::size_t kMaxLogColumns = 32;           // log columns one page may plot
constexpr std::size_t kMaxLogBatch = 2000;           // samples per column in one batch
constexpr int kPortFallbacks = 20;
constexpr auto kMaxAcceptPause = std::chrono::seconds(1);  // longest pause after an accept error

std::string& startPageStorage() {
  static std::string* page = new std::string("index.html");
  return *page;
}
std::mutex& startPageMutex() {
  static std::mutex* m = new std::mutex;
  return *m;
}

std::string generateToken() {
  std::random_device rd;
  std::string t;
  const char* hex = "0123456789abcdef";
  for (int i = 0; i < 32; ++i) t += hex[rd() % 16];
  return t;
}

bool constantTimeEqual(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d |= static_cast<unsigned char>(a[i] ^ b[i]);
  return d == 0;
}

// Value of `key` in the query string of `target` (no percent-decoding: tokens are hex).
std::string queryValue(std::string_view target, std::string_view key) {
  auto q = target.find('?');
  if (q == std::string_view::npos) return {};
  std::string_view query = target.substr(q + 1);
  while (!query.empty()) {
    auto amp = query.find('&');
    std::string_view pair = query.substr(0, amp);
    auto eq = pair.find('=');
    if (pair.substr(0, eq) == key) return std::string(eq == std::string_view::npos ? "" : pair.substr(eq + 1));
    if (amp == std::string_view::npos) break;
    query = query.substr(amp + 1);
  }
  return {};
}

std::string mimeType(const std::string& path) {
  auto ext = std::filesystem::path(path).extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json") return "application/json";
  if (ext == ".png") return "image/png";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".ico") return "image/x-icon";
  if (ext == ".wasm") return "application/wasm";
  return "application/octet-stream";
}

constexpr std::uintmax_t kMaxFrontEndFileBytes = 16u << 20;  // largest front-end file served
constexpr std::uintmax_t kMaxMeshFileBytes = 64u << 20;      // largest mesh file served
constexpr std::size_t kMaxFrontEndPath = 256;                // longest front-end URL path

// Whether `path` (a request target without its query) has the shape of a front-end file's URL:
// '/' and then segments of letters, digits, '.', '_' and '-', none empty and none starting with
// '.'. This refuses "//etc/passwd" (an empty segment: the rest would be an absolute path), "..",
// hidden files, percent-encoding (no front-end file needs it, so nothing is decoded) and
// backslashes before the file system is asked anything.
bool isFrontEndPath(std::string_view path) {
  if (path.size() < 2 || path.size() > kMaxFrontEndPath || path[0] != '/') return false;
  for (std::size_t start = 1; start <= path.size();) {
    std::size_t end = path.find('/', start);
    if (end == std::string_view::npos) end = path.size();
    const std::string_view segment = path.substr(start, end - start);
    if (segment.empty() || segment[0] == '.') return false;
    for (char c : segment) {
      const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                      c == '_' || c == '-';
      if (!ok) return false;
    }
    start = end + 1;
  }
  return true;
}

// The file of the front end that the URL path names: the path resolved (symbolic links followed)
// must still lie inside the resolved web root and be a regular file of at most
// kMaxFrontEndFileBytes. Empty if there is none.
std::filesystem::path frontEndFile(const std::string& webRoot, std::string_view path) {
  namespace fs = std::filesystem;
  if (webRoot.empty() || !isFrontEndPath(path)) return {};
  std::error_code ec;
  const fs::path root = fs::canonical(webRoot, ec);
  if (ec) return {};
  const fs::path file = fs::canonical(root / fs::path(std::string(path.substr(1))), ec);
  if (ec) return {};
  auto r = root.begin(), f = file.begin();
  for (; r != root.end(); ++r, ++f)
    if (f == file.end() || *r != *f) return {};  // outside the web root (a link out of it)
  if (f == file.end()) return {};                // the root itself
  if (!fs::is_regular_file(file, ec) || fs::file_size(file, ec) > kMaxFrontEndFileBytes || ec) return {};
  return file;
}

// The contents of `file`, at most `limit` bytes; false if it cannot be read whole within the limit.
bool readFileCapped(const std::filesystem::path& file, std::uintmax_t limit, std::string& out) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;
  out.clear();
  char chunk[64 * 1024];
  while (in) {
    in.read(chunk, sizeof chunk);
    out.append(chunk, static_cast<std::size_t>(in.gcount()));
    if (out.size() > limit) return false;  // grew since its size was checked
  }
  return in.eof();
}

// The host part of a Host header value: "name", "name:port", "[v6]" or "[v6]:port" -> name or
// "[v6]", lower case; empty if it is malformed.
std::string hostName(std::string_view host) {
  std::string h;
  if (!host.empty() && host[0] == '[') {
    const auto close = host.find(']');
    if (close == std::string_view::npos) return {};
    h = std::string(host.substr(0, close + 1));
    host = host.substr(close + 1);
  } else {
    const auto colon = host.find(':');
    h = std::string(host.substr(0, colon));
    host = colon == std::string_view::npos ? std::string_view() : host.substr(colon);
  }
  if (!host.empty() && (host[0] != ':' || host.size() < 2 || host.size() > 6 ||
                        host.substr(1).find_first_not_of("0123456789") != std::string_view::npos))
    return {};  // only ":port" may follow
  std::transform(h.begin(), h.end(), h.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return h;
}

const char* kNotBuiltPage =
    "<!doctype html><html><head><meta charset=\"utf-8\"><title>Robotic Platform</title></head><body>"
    "<h1>Robotic Platform Scene Viewer</h1><p>The front end is not built. Build the CMake target "
    "<code>rp_web</code> (it runs <code>npm ci</code> and <code>npm run build</code> in <code>web/</code>) "
    "or point the environment variable <code>RP_WEB_ROOT</code> at a built front end.</p></body></html>";

}  // namespace

// ---------------------------------------------------------------------------------------------
struct SceneViewer::Impl {
  class WsSession;
  class HttpSession;
  class ConnectionSlot;

  mutable std::mutex mutex;  // guards the fields below that other threads read
  bool running = false;
  SceneViewerOptions options;
  std::string token;
  std::set<std::string> hostNames;  // Host header names accepted (see hostAllowed())
  bool anyIpHost = false;           // listening on every address: any IP literal is accepted too
  int port = 0;
  std::string url;

  std::unique_ptr<asio::io_context> ioc;
  std::unique_ptr<tcp::acceptor> acceptor;
  std::unique_ptr<asio::steady_timer> timer;
  std::unique_ptr<asio::steady_timer> acceptTimer;  // the pause after an accept error
  std::chrono::milliseconds acceptPause{0};
  std::thread thread;

  // Connections (server thread): how many are open, and the HTTP connections waiting for a
  // request, oldest first (closed first when a connection is needed).
  std::size_t openConnections = 0;
  std::list<std::weak_ptr<HttpSession>> idleHttp;

  // Server-thread state.
  std::set<std::shared_ptr<WsSession>> sessions;
  internal::SceneState scene;
  std::chrono::steady_clock::time_point lastRefresh{};
  std::chrono::steady_clock::duration period{};
  std::chrono::steady_clock::duration writeTimeout{};
  std::chrono::steady_clock::time_point lastLogPush{};
  std::string shutdownMessage;  // the system shutdown every page is told about (empty: none yet)

  // Worker thread for commands that touch objects (they may block, e.g. a serial device).
  std::thread worker;
  std::mutex workMutex;
  std::condition_variable workCv;
  std::deque<std::function<void()>> work;
  bool workerStop = false;

  // Statistics.
  std::atomic<std::uint64_t> connections{0}, framesBuilt{0}, framesSent{0}, framesDropped{0}, messagesReceived{0},
      messagesRefused{0}, handshakesRefused{0};
  std::atomic<std::size_t> pageCount{0}, openCount{0};
  std::atomic<std::uint64_t> connectionsClosedForRoom{0}, connectionsRefused{0}, acceptFailures{0}, slowPagesDropped{0};

  void accept();
  bool closeIdleConnection();
  void announceShutdown();
  bool hostAllowed(std::string_view host) const;
  void tick();
  bool refreshScene(bool force);
  void onMessage(const std::shared_ptr<WsSession>& session, std::string text, bool binary);
  bool onLogMessage(const std::shared_ptr<WsSession>& session, const std::string& type, const json& msg, const json& id,
                    const std::function<void(const std::string&)>& refuse);
  void pushLogSamples();
  bool enqueueWork(std::function<void()> job);
  void workerLoop();
};

// One of the kSceneViewerMaxConnections connections, counted while held (server thread).
class SceneViewer::Impl::ConnectionSlot {
 public:
  explicit ConnectionSlot(Impl& impl) : impl_(&impl) { impl_->openCount.store(++impl_->openConnections); }
  ConnectionSlot(ConnectionSlot&& other) noexcept : impl_(std::exchange(other.impl_, nullptr)) {}
  ConnectionSlot(const ConnectionSlot&) = delete;
  ConnectionSlot& operator=(const ConnectionSlot&) = delete;
  ConnectionSlot& operator=(ConnectionSlot&&) = delete;
  ~ConnectionSlot() { release(); }
  void release() {
    if (impl_) impl_->openCount.store(--impl_->openConnections);
    impl_ = nullptr;
  }

 private:
  Impl* impl_;
};

// A page's WebSocket: a bounded queue of text messages and a one-slot queue of the latest state frame.
class SceneViewer::Impl::WsSession : public std::enable_shared_from_this<SceneViewer::Impl::WsSession> {
 public:
  WsSession(Impl& impl, tcp::socket&& socket, ConnectionSlot&& slot)
      : impl_(impl), slot_(std::move(slot)), ws_(std::move(socket)) {}

  void run(http::request<http::string_body> req) {
    ws_.read_message_max(kMaxMessageBytes);
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return self->close();
      self->impl_.sessions.insert(self);
      self->impl_.pageCount.store(self->impl_.sessions.size());
      self->impl_.connections.fetch_add(1);
      json hello = {{"type", "hello"},
                    {"protocol", kSceneViewerProtocolVersion},
                    {"qmotor", RoboticPlatform::isQMotorOn()},
                    {"rate", self->impl_.options.rate}};
      self->sendText(hello.dump());
      if (!self->impl_.shutdownMessage.empty()) self->sendText(self->impl_.shutdownMessage);
      if (!self->impl_.refreshScene(true)) self->sendText(self->impl_.scene.sceneMessage());
      self->read();
    });
  }

  void sendText(std::string text) {
    if (closed_) return;
    if (text_.size() >= kMaxTextQueue) {  // the page does not keep up: drop it, not the server
      close();
      return;
    }
    text_.push_back(std::make_shared<const std::string>(std::move(text)));
    write();
  }

  void sendState(const std::shared_ptr<const std::string>& frame) {
    if (closed_ || closing_) return;
    if (state_) impl_.framesDropped.fetch_add(1);
    state_ = frame;
    write();
  }

  // Text messages waiting to be written (log samples are not sent while many wait).
  std::size_t queuedText() const { return text_.size(); }

  // The log columns this page plots (QMotor), and the time of the last sample sent.
  std::vector<std::string> logColumns;
  std::vector<double> logAfter;  // per column

  void close() {
    if (closed_) return;
    closed_ = true;
    impl_.sessions.erase(shared_from_this());
    impl_.pageCount.store(impl_.sessions.size());
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ec);
    beast::get_lowest_layer(ws_).socket().close(ec);
    slot_.release();
  }

  // Closes once the messages queued now are written (the server is stopping; its last word, such
  // as the system shutdown, should reach the page). stop() closes what is left shortly after.
  void closeWhenWritten() {
    if (closed_) return;
    closing_ = true;
    state_.reset();
    if (!writing_ && text_.empty()) close();
  }

  // Whether a write has waited longer than `timeout` for the page to read (a page that stopped
  // reading: its socket's buffers are full).
  bool writeStalled(std::chrono::steady_clock::time_point now, std::chrono::steady_clock::duration timeout) const {
    return writing_ && now - writeStarted_ > timeout;
  }

 private:
  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        if (ec == websocket::error::message_too_big) self->impl_.messagesRefused.fetch_add(1);
        return self->close();
      }
      std::string text = beast::buffers_to_string(self->buffer_.data());
      self->buffer_.consume(self->buffer_.size());
      self->impl_.onMessage(self, std::move(text), !self->ws_.got_text());
      self->read();
    });
  }

  void write() {
    if (writing_ || closed_) return;
    std::shared_ptr<const std::string> next;
    bool binary = false;
    if (!text_.empty()) {
      next = text_.front();
      text_.pop_front();
    } else if (state_) {
      next = std::move(state_);
      state_.reset();
      binary = true;
    } else {
      return;
    }
    writing_ = true;
    writeStarted_ = std::chrono::steady_clock::now();
    ws_.binary(binary);
    ws_.async_write(asio::buffer(*next), [self = shared_from_this(), next, binary](beast::error_code ec, std::size_t) {
      self->writing_ = false;
      if (ec) return self->close();
      if (binary) self->impl_.framesSent.fetch_add(1);
      if (self->closing_ && self->text_.empty()) return self->close();
      self->write();
    });
  }

  Impl& impl_;
  ConnectionSlot slot_;
  websocket::stream<beast::tcp_stream> ws_;
  beast::flat_buffer buffer_;
  std::deque<std::shared_ptr<const std::string>> text_;
  std::shared_ptr<const std::string> state_;
  bool writing_ = false;
  bool closing_ = false;
  std::chrono::steady_clock::time_point writeStarted_{};
  bool closed_ = false;
};

// An HTTP connection: static files of the web root, or the upgrade to a page's WebSocket.
class SceneViewer::Impl::HttpSession : public std::enable_shared_from_this<SceneViewer::Impl::HttpSession> {
 public:
  HttpSession(Impl& impl, tcp::socket&& socket) : impl_(impl), slot_(impl), stream_(std::move(socket)) {}
  ~HttpSession() { leaveIdle(); }
  HttpSession(const HttpSession&) = delete;
  HttpSession& operator=(const HttpSession&) = delete;

  void run() { read(); }

  // Closes the connection to make room for another (it waits for a request: nothing is lost but
  // a keep-alive connection the browser opens again).
  void closeForRoom() {
    leaveIdle();
    beast::error_code ec;
    stream_.socket().shutdown(tcp::socket::shutdown_both, ec);
    stream_.socket().close(ec);
    slot_.release();
  }

 private:
  void enterIdle() {
    leaveIdle();
    idle_ = impl_.idleHttp.insert(impl_.idleHttp.end(), weak_from_this());
    isIdle_ = true;
  }
  void leaveIdle() {
    if (isIdle_) impl_.idleHttp.erase(idle_);
    isIdle_ = false;
  }

  void read() {
    enterIdle();
    parser_.emplace();
    parser_->header_limit(8 * 1024);
    parser_->body_limit(8 * 1024);
    stream_.expires_after(std::chrono::seconds(30));
    http::async_read(stream_, buffer_, *parser_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->leaveIdle();
      if (ec) {
        beast::error_code ignored;
        self->stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
        return;
      }
      self->handle(self->parser_->release());
    });
  }

  void handle(http::request<http::string_body> req) {
    const std::string target(req.target());
    // DNS rebinding: a page of another site whose name was made to resolve to this address sends
    // that name as Host. Only the names this server is known by are accepted.
    // Exactly one Host header: with two, only the first would be checked, and what a proxy on the
    // way takes as the host is anyone's guess.
    const auto host = req[http::field::host];
    const bool oneHost = req.count(http::field::host) <= 1;
    if (!oneHost || !impl_.hostAllowed(std::string_view(host.data(), host.size()))) {
      if (websocket::is_upgrade(req)) impl_.handshakesRefused.fetch_add(1);
      return respond(http::status::forbidden, "text/plain",
                     oneHost ? "Scene Viewer: this server is not known by the host name in the Host header\n"
                             : "Scene Viewer: a request may have one Host header only\n",
                     req);
    }
    if (websocket::is_upgrade(req)) {
      std::string why;
      if (target.substr(0, target.find('?')) != "/ws") why = "no WebSocket at this path";
      else if (!impl_.token.empty() && !constantTimeEqual(queryValue(target, "token"), impl_.token))
        why = "wrong or missing token";
      else if (auto origin = req.find(http::field::origin); origin != req.end()) {
        const std::string host(req[http::field::host]);
        const std::string o(origin->value());
        if (o != "http://" + host && o != "https://" + host) why = "Origin " + o + " is not this server";
      }
      if (!why.empty()) {
        impl_.handshakesRefused.fetch_add(1);
        return respond(http::status::forbidden, "text/plain", "Scene Viewer: " + why + "\n", req);
      }
      stream_.expires_never();
      std::make_shared<WsSession>(impl_, stream_.release_socket(), std::move(slot_))->run(std::move(req));
      return;
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head)
      return respond(http::status::method_not_allowed, "text/plain", "only GET\n", req);
    std::string path = target.substr(0, target.find('?'));
    if (path == "/") path = "/index.html";
    if (path == "/api/info") {
      json info = {{"protocol", kSceneViewerProtocolVersion}, {"tokenRequired", !impl_.token.empty()}};
      return respond(http::status::ok, "application/json", info.dump(), req);
    }
    if (path == "/mesh") return serveMesh(target, req);
    // Only the files of the built front end: nothing else of the file system is reachable.
    const std::filesystem::path file = frontEndFile(impl_.options.webRoot, path);
    std::string body;
    if (file.empty() || !readFileCapped(file, kMaxFrontEndFileBytes, body)) {
      if (path == "/index.html") return respond(http::status::ok, "text/html; charset=utf-8", kNotBuiltPage, req);
      return respond(http::status::not_found, "text/plain", "not found\n", req);
    }
    respond(http::status::ok, mimeType(path), std::move(body), req);
  }

  // GET /mesh?object=NAME&shape=I[&token=T]: the mesh file that shape I of a live object's 3D model
  // names, and nothing else (no path from the request reaches the file system).
  void serveMesh(const std::string& target, const http::request<http::string_body>& req) {
    if (!impl_.token.empty() && !constantTimeEqual(queryValue(target, "token"), impl_.token))
      return respond(http::status::forbidden, "text/plain", "wrong or missing token\n", req);
    const std::string object = queryValue(target, "object"), shape = queryValue(target, "shape");
    std::size_t index = 0;
    if (shape.empty() || shape.size() > 6 || shape.find_first_not_of("0123456789") != std::string::npos)
      return respond(http::status::bad_request, "text/plain", "shape must be a number\n", req);
    index = static_cast<std::size_t>(std::stoul(shape));
    const std::string file = impl_.scene.meshFile(object, index);
    std::error_code ec;
    std::string body;
    if (file.empty() || !std::filesystem::is_regular_file(file, ec) ||
        std::filesystem::file_size(file, ec) > kMaxMeshFileBytes || ec || !readFileCapped(file, kMaxMeshFileBytes, body))
      return respond(http::status::not_found, "text/plain", "no mesh file for that shape\n", req);
    // A URDF texture is an image (the page loads it as one); meshes are bytes.
    std::string ext = std::filesystem::path(file).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const char* type = ext == ".png" ? "image/png" : ext == ".jpg" || ext == ".jpeg" ? "image/jpeg" : "application/octet-stream";
    respond(http::status::ok, type, std::move(body), req);
  }

  void respond(http::status status, const std::string& type, std::string body,
               const http::request<http::string_body>& req) {
    auto res = std::make_shared<http::response<http::string_body>>(status, req.version());
    res->set(http::field::server, "Robotic Platform Scene Viewer");
    res->set(http::field::content_type, type);
    res->set(http::field::cache_control, "no-cache");
    res->set("X-Content-Type-Options", "nosniff");
    // No other site may frame the pages (clickjacking) or learn the token from a Referer.
    res->set("X-Frame-Options", "DENY");
    res->set("Content-Security-Policy", "frame-ancestors 'none'");
    res->set("Referrer-Policy", "no-referrer");
    res->keep_alive(req.keep_alive());
    if (req.method() != http::verb::head) {
      res->body() = std::move(body);
      res->prepare_payload();
    } else {
      res->content_length(body.size());  // what a GET would send, without the body
    }
    http::async_write(stream_, *res, [self = shared_from_this(), res](beast::error_code ec, std::size_t) {
      if (ec || !res->keep_alive()) {
        beast::error_code ignored;
        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
        return;
      }
      self->read();
    });
  }

  Impl& impl_;
  ConnectionSlot slot_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::list<std::weak_ptr<HttpSession>>::iterator idle_;
  bool isIdle_ = false;
};

// Accepts connections, at most kSceneViewerMaxConnections at a time: a new one takes the place
// of the HTTP connection that has waited longest for a request, or is closed at once if every
// connection is busy or a page. An accept error (out of file descriptors: the connection stays
// in the listen queue) also closes such a connection to free a descriptor and tries again;
// with none to close it pauses (10 ms, doubling up to 1 s) instead of trying again at once,
// which would spin: the listening socket stays readable while the connection waits.
void SceneViewer::Impl::accept() {
  acceptor->async_accept([this](beast::error_code ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted) return;
    if (ec) {
      acceptFailures.fetch_add(1);
      if (closeIdleConnection()) return accept();
      acceptPause = std::min<std::chrono::milliseconds>(
          std::max(acceptPause * 2, std::chrono::milliseconds(10)),
          std::chrono::duration_cast<std::chrono::milliseconds>(kMaxAcceptPause));
      acceptTimer->expires_after(acceptPause);
      acceptTimer->async_wait([this](beast::error_code e) {
        if (!e) accept();
      });
      return;
    }
    acceptPause = std::chrono::milliseconds(0);
    if (openConnections >= kSceneViewerMaxConnections && !closeIdleConnection()) {
      connectionsRefused.fetch_add(1);
      beast::error_code ignored;
      socket.close(ignored);
    } else {
      std::make_shared<HttpSession>(*this, std::move(socket))->run();
    }
    accept();
  });
}

// Closes the HTTP connection that has waited longest for a request; false if there is none.
bool SceneViewer::Impl::closeIdleConnection() {
  while (!idleHttp.empty()) {
    std::shared_ptr<HttpSession> oldest = idleHttp.front().lock();
    if (!oldest) {
      idleHttp.pop_front();
      continue;
    }
    oldest->closeForRoom();  // leaves the list
    connectionsClosedForRoom.fetch_add(1);
    return true;
  }
  return false;
}

// Whether a request's Host header names this server: localhost, a loopback address, the address
// it listens on; when it listens on every address also the machine's name and any IP literal (a
// rebinding attack needs a DNS name). With or without a port (a forwarded port may differ).
bool SceneViewer::Impl::hostAllowed(std::string_view host) const {
  const std::string name = hostName(host);
  if (name.empty()) return false;
  if (hostNames.count(name)) return true;
  std::string literal = name;
  if (literal.size() > 2 && literal.front() == '[' && literal.back() == ']') literal = literal.substr(1, literal.size() - 2);
  else if (literal.find(':') != std::string::npos) return false;  // a v6 literal must be in brackets
  beast::error_code ec;
  const auto a = asio::ip::make_address(literal, ec);
  if (ec) return false;
  return a.is_loopback() || anyIpHost;
}

bool SceneViewer::Impl::refreshScene(bool force) {
  auto now = std::chrono::steady_clock::now();
  if (!force && now - lastRefresh < std::chrono::milliseconds(250)) return false;
  lastRefresh = now;
  // Objects seen the first time are only recorded; a second look describes them.
  bool changed = scene.refresh();
  if (force) changed = scene.refresh() || changed;
  if (changed)
    for (const auto& s : std::vector<std::shared_ptr<WsSession>>(sessions.begin(), sessions.end()))
      s->sendText(scene.sceneMessage());
  return changed;
}

void SceneViewer::Impl::tick() {
  timer->expires_at(timer->expiry() + period);
  timer->async_wait([this](beast::error_code ec) {
    if (ec) return;
    tick();
  });
  announceShutdown();
  if (sessions.empty()) return;  // nothing to do without pages: no cost to the program
  // A page that stopped reading (its socket's buffers full for writeTimeout) is dropped.
  const auto now = std::chrono::steady_clock::now();
  for (const auto& s : std::vector<std::shared_ptr<WsSession>>(sessions.begin(), sessions.end()))
    if (s->writeStalled(now, writeTimeout)) {
      slowPagesDropped.fetch_add(1);
      s->close();
    }
  refreshScene(false);
  pushLogSamples();
  auto frame = std::make_shared<const std::string>(scene.buildFrame());
  framesBuilt.fetch_add(1);
  for (const auto& s : std::vector<std::shared_ptr<WsSession>>(sessions.begin(), sessions.end())) s->sendState(frame);
}

// Once a system shutdown has been requested, tells every page (and every page that connects
// later) why, which objects reported an error (as last described), and when: {"type": "shutdown", "reason",
// "objects": [{"name", "code", "message"}], "time" (UTC, ISO 8601)}.
void SceneViewer::Impl::announceShutdown() {
  if (!shutdownMessage.empty() || !ObjectManager::isShutdownRequested()) return;
  const std::string reason = ObjectManager::getShutdownReason();
  if (reason.empty()) return;  // being written by the requesting thread: next tick
  // The objects' errors as last described: asking the objects now would wait for the registry,
  // which the shutdown holds while it shuts them down, and the pages would hear of it only then.
  json objects = json::array();
  const json described = json::parse(scene.sceneMessage(), nullptr, false);
  if (described.is_object() && described.contains("objects"))
    for (const json& o : described["objects"]) {
      const json error = o.value("error", json::object());
      if (error.value("code", 0) != 0)
        objects.push_back({{"name", o.value("name", "")}, {"code", error.value("code", 0)},
                           {"message", error.value("message", "")}});
    }
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm utc{};
  gmtime_r(&t, &utc);
  char time[96];
  std::snprintf(time, sizeof time, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", utc.tm_year + 1900, utc.tm_mon + 1,
                utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec, static_cast<int>(ms));
  shutdownMessage = json{{"type", "shutdown"}, {"reason", reason}, {"objects", objects}, {"time", time}}.dump();
  for (const auto& s : std::vector<std::shared_ptr<WsSession>>(sessions.begin(), sessions.end()))
    s->sendText(shutdownMessage);
}

bool SceneViewer::Impl::enqueueWork(std::function<void()> job) {
  std::lock_guard<std::mutex> lock(workMutex);
  if (work.size() >= kMaxWorkQueue) return false;
  work.push_back(std::move(job));
  workCv.notify_one();
  return true;
}

void SceneViewer::Impl::workerLoop() {
  for (;;) {
    std::function<void()> job;
    {
      std::unique_lock<std::mutex> lock(workMutex);
      workCv.wait(lock, [&] { return workerStop || !work.empty(); });
      if (work.empty()) return;
      job = std::move(work.front());
      work.pop_front();
    }
    job();
  }
}

// A reference to the published object `name` (held while a command uses it, so the object cannot
// be destroyed meanwhile); throws with a message for the page if there is none.
static ObjectReference publishedObject(const std::string& name) {
  ObjectManager om;
  ObjectReference o = om.findPublishedObject(name);
  if (o) return o;
  if (om.findObject(name)) throw std::invalid_argument("object '" + name + "' is not published (being constructed or destroyed, or its class does not publish it)");
  throw std::invalid_argument("no object '" + name + "'");
}

void SceneViewer::Impl::onMessage(const std::shared_ptr<WsSession>& session, std::string text, bool binary) {
  messagesReceived.fetch_add(1);
  json id = nullptr;
  auto refuse = [&](const std::string& why) {
    messagesRefused.fetch_add(1);
    session->sendText(json{{"type", "error"}, {"id", id}, {"message", why}}.dump());
  };
  if (binary) return refuse("binary messages are not accepted (send JSON text)");
  json msg = json::parse(text, nullptr, false);
  if (msg.is_discarded()) return refuse("not valid JSON");
  if (!msg.is_object()) return refuse("a message must be a JSON object");
  if (msg.contains("id")) {
    if (!msg["id"].is_number_integer()) return refuse("'id' must be an integer");
    id = msg["id"];
  }
  auto str = [&](const char* key, std::string& out) -> bool {
    auto it = msg.find(key);
    if (it == msg.end() || !it->is_string()) {
      refuse(std::string("'") + key + "' must be a string");
      return false;
    }
    out = it->get<std::string>();
    if (out.empty() || out.size() > kMaxStringField) {
      refuse(std::string("'") + key + "' must have 1 to 256 characters");
      return false;
    }
    return true;
  };
  std::string type;
  if (!str("type", type)) return;

  if (type == "hello") {
    auto it = msg.find("protocol");
    if (it == msg.end() || !it->is_number_integer()) return refuse("'protocol' must be an integer");
    if (it->get<long long>() != kSceneViewerProtocolVersion)
      return refuse("protocol " + it->dump() + " is not supported (server speaks " +
                    std::to_string(kSceneViewerProtocolVersion) + ")");
    return session->sendText(json{{"type", "result"}, {"id", id}, {"ok", true}}.dump());
  }
  if (type == "ping") return session->sendText(json{{"type", "pong"}, {"id", id}}.dump());
  if (type == "scene") return session->sendText(scene.sceneMessage());

  if (type == "emergencyStop") {
    // Every page's emergency stop: the system shutdown, at once from the server thread (it never
    // blocks, and does not wait behind queued commands).
    ObjectManager::requestSystemShutdown("emergency stop from the Scene Viewer");
    session->sendText(json{{"type", "result"}, {"id", id}, {"ok", true}}.dump());
    return announceShutdown();
  }
  if (onLogMessage(session, type, msg, id, refuse)) return;

  std::string object;
  if (!str("object", object)) return;
  if (type == "meshFailed") {
    // A page could not draw a mesh the scene names: printed on stderr once per file.
    auto shape = msg.find("shape");
    if (shape == msg.end() || !shape->is_number_integer() || shape->get<long long>() < 0 ||
        shape->get<long long>() > 1000000)
      return refuse("'shape' must be a non-negative integer");
    std::string why;
    if (!str("message", why)) return;
    const bool printed = scene.reportMeshFailure(object, static_cast<std::size_t>(shape->get<long long>()), why);
    return session->sendText(json{{"type", "result"}, {"id", id}, {"ok", true}, {"reply", printed ? "printed" : ""}}.dump());
  }
  std::function<std::string()> action;  // runs in the worker; returns the reply text; throws on failure
  if (type == "command") {
    std::string command;
    if (!str("command", command)) return;
    action = [object, command] {
      ObjectReference o = publishedObject(object);
      return o->executeCommand(command);  // what it did, shown in the page
    };
  } else if (type == "display") {
    std::string mode;
    if (!str("mode", mode)) return;
    if (mode != "off" && mode != "solid" && mode != "wireframe") return refuse("'mode' must be off, solid or wireframe");
    action = [object, mode] {
      ObjectReference ref = publishedObject(object);
      auto* o = ref.as<PhysicalObject>();
      if (!o) throw std::invalid_argument("'" + object + "' is not a physical object");
      o->setDisplayMode(mode == "off" ? DisplayMode::Off : mode == "solid" ? DisplayMode::Solid : DisplayMode::Wireframe);
      return std::string();
    };
  } else if (type == "setParameter") {
    std::string name;
    if (!str("name", name)) return;
    std::vector<double> values;
    long long index = -1;
    const bool hasValue = msg.contains("value"), hasValues = msg.contains("values"), hasIndex = msg.contains("index");
    // One form per message: 'value' (every element, or the one at 'index') or 'values' (each
    // element: exactly as many as the parameter has, checked in the worker). A one-element
    // 'values' used to go to the whole-parameter form and set every joint's gain to it.
    if (hasValue && hasValues) return refuse("setParameter takes 'value' or 'values', not both");
    if (hasIndex && !hasValue) return refuse("'index' goes with 'value' (one element), not with 'values'");
    if (hasValue) {
      const json& v = msg["value"];
      if (!v.is_number()) return refuse("'value' must be a number");
      values.push_back(v.get<double>());
      if (hasIndex) {
        const json& i = msg["index"];
        if (!i.is_number_integer() || i.get<long long>() < 0 || i.get<long long>() > 1000000)
          return refuse("'index' must be a non-negative integer");
        index = i.get<long long>();
      }
    } else if (auto vs = msg.find("values"); vs != msg.end() && vs->is_array() && !vs->empty() && vs->size() <= 1024) {
      for (const auto& x : *vs) {
        if (!x.is_number()) return refuse("'values' must be numbers");
        values.push_back(x.get<double>());
      }
    } else {
      return refuse("setParameter needs 'value' (a number) or 'values' (1 to 1024 numbers)");
    }
    for (double v : values)
      if (!std::isfinite(v)) return refuse("parameter values must be finite");
    action = [object, name, values, index, all = hasValues] {
      ObjectReference o = publishedObject(object);
      ControlProgram* p = o->getControlProgram();
      if (!p) throw std::invalid_argument("object '" + object + "' has no tunable parameters");
      if (all) p->setParameter(name, values);  // throws unless one value per element
      else if (index >= 0) p->setParameter(name, static_cast<std::size_t>(index), values[0]);
      else p->setParameter(name, values[0]);
      json now = p->getParameter(name);
      return now.dump();
    };
  } else if (type == "qmotor") {
    // QMotor: start/stop/restart the object's control program, save/load its control-program
    // files, QMotor's log. Every field is checked here; the object is touched in the worker.
    internal::QMotorRequest request;
    try {
      request = internal::parseQMotorRequest(msg);
    } catch (const std::exception& e) {
      return refuse(e.what());
    }
    action = [object, request = std::move(request)] {
      ObjectReference o = publishedObject(object);
      return internal::runQMotorRequest(*o, request);
    };
  } else if (type == "message") {
    std::string messageType;
    if (!str("messageType", messageType)) return;
    std::string payload;
    if (auto p = msg.find("payload"); p != msg.end()) {
      if (!p->is_string()) return refuse("'payload' must be a string");
      payload = p->get<std::string>();
    }
    action = [object, messageType, payload] {
      ObjectReference o = publishedObject(object);
      std::string reply;
      if (!o->handleMessage(messageType, payload, reply))
        throw std::invalid_argument("object '" + object + "' does not understand the message '" + messageType + "'");
      return reply;
    };
  } else {
    return refuse("unknown message type '" + type +
                  "' (known: hello, ping, scene, command, display, setParameter, qmotor, message, meshFailed, emergencyStop, "
                  "logInfo, logging, logSubscribe)");
  }

  std::weak_ptr<WsSession> weak = session;
  asio::io_context* io = ioc.get();
  bool queued = enqueueWork([this, weak, io, id, action = std::move(action)] {
    json reply;
    try {
      std::string r = action();
      reply = {{"type", "result"}, {"id", id}, {"ok", true}, {"reply", r}};
    } catch (const std::exception& e) {
      messagesRefused.fetch_add(1);
      reply = {{"type", "error"}, {"id", id}, {"message", e.what()}};
    }
    asio::post(*io, [this, weak, text = reply.dump()]() mutable {
      if (auto s = weak.lock()) s->sendText(std::move(text));
      refreshScene(true);  // display mode, parameters or errors may have changed: tell every page
    });
  });
  if (!queued) refuse("the server is busy (too many commands waiting)");
}

// QMotor's log messages: logInfo (the log file, whether it is logging, its columns), logging {on}
// (start or stop logging to the file) and logSubscribe {columns} (the columns this page plots).
// Returns false for any other type.
bool SceneViewer::Impl::onLogMessage(const std::shared_ptr<WsSession>& session, const std::string& type,
                                     const json& msg, const json& id,
                                     const std::function<void(const std::string&)>& refuse) {
  if (type != "logInfo" && type != "logging" && type != "logSubscribe") return false;
  LogWriter* writer = LogWriter::getPlatformWriter();
  if (!writer || writer->isClosed()) {
    refuse("the program writes no log file (start it with -log FILE)");
    return true;
  }
  auto info = [&] {
    return json{{"file", writer->fileName()}, {"logging", writer->isLogging()}, {"columns", writer->getColumns()}};
  };
  if (type == "logInfo") {
    session->sendText(json{{"type", "result"}, {"id", id}, {"ok", true}, {"reply", info().dump()}}.dump());
  } else if (type == "logging") {
    auto on = msg.find("on");
    if (on == msg.end() || !on->is_boolean()) {
      refuse("'on' must be true or false");
      return true;
    }
    if (on->get<bool>()) writer->startLogging();
    else writer->stopLogging();
    session->sendText(json{{"type", "result"}, {"id", id}, {"ok", true}, {"reply", info().dump()}}.dump());
    // Every page shows whether the program is logging.
    const std::string note = json{{"type", "logState"}, {"logging", writer->isLogging()}}.dump();
    for (const auto& s : std::vector<std::shared_ptr<WsSession>>(sessions.begin(), sessions.end()))
      if (s != session) s->sendText(note);
  } else {  // logSubscribe
    auto columns = msg.find("columns");
    if (columns == msg.end() || !columns->is_array() || columns->size() > kMaxLogColumns) {
      refuse("'columns' must be an array of at most " + std::to_string(kMaxLogColumns) + " column names");
      return true;
    }
    const std::vector<std::string> known = writer->getColumns();
    std::vector<std::string> chosen;
    for (const json& c : *columns) {
      if (!c.is_string() || c.get<std::string>().empty() || c.get<std::string>().size() > kMaxStringField) {
        refuse("'columns' must hold names of 1 to 256 characters");
        return true;
      }
      const std::string name = c.get<std::string>();
      if (std::find(known.begin(), known.end(), name) == known.end()) {
        refuse("'" + name + "' is not a column of the log " + writer->fileName());
        return true;
      }
      if (std::find(chosen.begin(), chosen.end(), name) == chosen.end()) chosen.push_back(name);
    }
    // Columns already plotted go on from their last sample; new ones get the recent samples.
    std::vector<double> after(chosen.size(), -std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < chosen.size(); ++i)
      for (std::size_t j = 0; j < session->logColumns.size(); ++j)
        if (session->logColumns[j] == chosen[i]) after[i] = session->logAfter[j];
    session->logAfter = std::move(after);
    session->logColumns = std::move(chosen);
    session->sendText(json{{"type", "result"}, {"id", id}, {"ok", true}, {"reply", info().dump()}}.dump());
  }
  return true;
}

// Sends each page that plots log columns the samples taken since its last batch (20 batches a
// second; a page with many messages still queued gets its samples in a later, larger batch).
void SceneViewer::Impl::pushLogSamples() {
  const auto now = std::chrono::steady_clock::now();
  if (now - lastLogPush < std::chrono::milliseconds(50)) return;
  lastLogPush = now;
  LogWriter* writer = LogWriter::getPlatformWriter();
  if (!writer || writer->isClosed()) return;
  for (const auto& s : std::vector<std::shared_ptr<WsSession>>(sessions.begin(), sessions.end())) {
    if (s->logColumns.empty() || s->queuedText() > 8) continue;
    json out = json::array();
    bool any = false;
    for (std::size_t i = 0; i < s->logColumns.size(); ++i) {
      std::vector<LogSeries> series;
      try {
        series = writer->getRecentSamples({s->logColumns[i]}, s->logAfter[i], kMaxLogBatch);
      } catch (const std::exception&) {
        continue;  // the writer was closed meanwhile
      }
      const LogSeries& l = series.front();
      if (!l.time.empty()) {
        s->logAfter[i] = l.time.back();
        any = true;
      }
      out.push_back({{"column", l.column}, {"t", l.time}, {"v", l.value}});
    }
    if (!any) continue;
    s->sendText(json{{"type", "logSamples"}, {"series", out}}.dump());
  }
}

// ---------------------------------------------------------------------------------------------
SceneViewer::SceneViewer() : impl_(std::make_unique<Impl>()) {}

SceneViewer::~SceneViewer() { stop(); }

SceneViewer& SceneViewer::instance() {
  static SceneViewer* viewer = new SceneViewer;  // never destroyed: stop() runs at exit
  return *viewer;
}

bool SceneViewer::isLoopbackAddress(const std::string& address) {
  beast::error_code ec;
  auto a = asio::ip::make_address(address, ec);
  return !ec && a.is_loopback();
}

void SceneViewer::start(const SceneViewerOptions& options) {
  Impl& m = *impl_;
  {
    std::lock_guard<std::mutex> lock(m.mutex);
    if (m.running) throw std::logic_error("SceneViewer::start: already running");
  }
  if (!(options.rate >= 1 && options.rate <= 240))
    throw std::invalid_argument("SceneViewer: rate must be 1..240 Hz, not " + internal::shortNumber(options.rate));
  if (!(options.writeTimeout >= 0.1 && options.writeTimeout <= 3600))
    throw std::invalid_argument("SceneViewer: writeTimeout must be 0.1..3600 s, not " +
                                internal::shortNumber(options.writeTimeout));
  if (options.port < 0 || options.port > 65535)
    throw std::invalid_argument("SceneViewer: port must be 0..65535, not " + std::to_string(options.port));
  beast::error_code ec;
  auto address = asio::ip::make_address(options.address, ec);
  if (ec) throw std::invalid_argument("SceneViewer: '" + options.address + "' is not an IP address");

  if (!internal::isUrlToken(options.token))
    throw std::invalid_argument("SceneViewer: the token must be at most 256 letters, digits and - . _ ~ (pages present "
                                "it in the URL as it is)");

  m.options = options;
  if (m.options.webRoot.empty()) m.options.webRoot = defaultWebRoot();
  m.token = options.token;
  if (m.token.empty() && !address.is_loopback()) m.token = generateToken();
  m.hostNames = {"localhost", "localhost."};
  m.hostNames.insert(address.is_v6() ? "[" + address.to_string() + "]" : address.to_string());
  m.anyIpHost = address.is_unspecified();
  if (m.anyIpHost) {
    std::string name = asio::ip::host_name();
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    m.hostNames.insert(name);
  }
  m.ioc = std::make_unique<asio::io_context>(1);
  m.acceptor = std::make_unique<tcp::acceptor>(*m.ioc);

  auto tryListen = [&](int port) -> bool {
    beast::error_code e;
    tcp::endpoint ep(address, static_cast<unsigned short>(port));
    m.acceptor->open(ep.protocol(), e);
    if (e) return false;
    m.acceptor->set_option(asio::socket_base::reuse_address(true), e);
    m.acceptor->bind(ep, e);
    if (!e) m.acceptor->listen(asio::socket_base::max_listen_connections, e);
    if (e) {
      beast::error_code ignored;
      m.acceptor->close(ignored);
      ec = e;
      return false;
    }
    return true;
  };
  bool ok = tryListen(options.port);
  if (!ok && options.port == kSceneViewerDefaultPort) {
    for (int i = 1; i <= kPortFallbacks && !ok && options.port + i <= 65535; ++i) ok = tryListen(options.port + i);
    if (!ok) ok = tryListen(0);
  }
  if (!ok) {
    m.acceptor.reset();
    m.ioc.reset();
    throw std::runtime_error("SceneViewer: cannot listen on " + options.address + ":" + std::to_string(options.port) +
                             ": " + ec.message());
  }
  const int port = m.acceptor->local_endpoint().port();
  std::string host = options.address;
  if (address.is_unspecified()) host = asio::ip::host_name();
  else if (address.is_v6()) host = "[" + host + "]";
  std::string page = m.options.startPage.empty() ? "index.html" : m.options.startPage;
  std::string url = "http://" + host + ":" + std::to_string(port) + "/" + page;
  if (!m.token.empty()) url += (page.find('?') == std::string::npos ? "?" : "&") + std::string("token=") + m.token;

  m.period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(1.0 / options.rate));
  m.writeTimeout = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(options.writeTimeout));
  m.timer = std::make_unique<asio::steady_timer>(*m.ioc);
  m.acceptTimer = std::make_unique<asio::steady_timer>(*m.ioc);
  m.acceptPause = std::chrono::milliseconds(0);
  m.shutdownMessage.clear();
  m.timer->expires_after(m.period);
  m.timer->async_wait([&m](beast::error_code e) {
    if (!e) m.tick();
  });
  m.accept();
  m.connections = 0;
  m.framesBuilt = m.framesSent = m.framesDropped = m.messagesReceived = m.messagesRefused = m.handshakesRefused = 0;
  m.connectionsClosedForRoom = m.connectionsRefused = m.acceptFailures = m.slowPagesDropped = 0;
  m.workerStop = false;
  m.worker = std::thread([&m] { m.workerLoop(); });
  m.thread = std::thread([&m] { m.ioc->run(); });
  if (!address.is_loopback())
    std::cerr << "rp: warning: the Scene Viewer listens on " << options.address << ":" << port
              << ", beyond this machine: anyone who can reach it and knows the token can move the robots"
              << " (see the Security section of docs/gui.md)" << std::endl;
  std::lock_guard<std::mutex> lock(m.mutex);
  m.port = port;
  m.url = url;
  m.running = true;
}

void SceneViewer::stop() {
  Impl& m = *impl_;
  {
    std::lock_guard<std::mutex> lock(m.mutex);
    if (!m.running) return;
    m.running = false;
  }
  {
    std::lock_guard<std::mutex> lock(m.workMutex);
    m.workerStop = true;
    m.work.clear();
    m.workCv.notify_all();
  }
  if (m.worker.joinable()) m.worker.join();
  asio::post(*m.ioc, [&m] {
    beast::error_code ec;
    m.acceptor->close(ec);
    m.timer->cancel();
    m.acceptTimer->cancel();
    m.announceShutdown();  // a program ending in a shutdown tells its pages why before it goes
    for (const auto& s : std::vector<std::shared_ptr<Impl::WsSession>>(m.sessions.begin(), m.sessions.end()))
      s->closeWhenWritten();
  });
  // Give open connections a moment to close, then stop whatever is left.
  std::thread stopper([&m] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    m.ioc->stop();
  });
  if (m.thread.joinable()) m.thread.join();
  stopper.join();
  m.sessions.clear();
  m.timer.reset();
  m.acceptTimer.reset();
  m.acceptor.reset();
  m.ioc.reset();  // destroys the sessions still held by pending operations
  m.idleHttp.clear();
  m.pageCount = 0;
  std::lock_guard<std::mutex> lock(m.mutex);
  m.port = 0;
  m.url.clear();
}

bool SceneViewer::isRunning() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->running;
}

std::string SceneViewer::getUrl() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->url;
}

int SceneViewer::getPort() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->port;
}

std::string SceneViewer::getToken() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->running ? impl_->token : std::string();
}

std::string SceneViewer::getWebRoot() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->running ? impl_->options.webRoot : defaultWebRoot();
}

SceneViewerStatistics SceneViewer::getStatistics() const {
  const Impl& m = *impl_;
  SceneViewerStatistics s;
  s.pages = m.pageCount.load();
  s.connections = m.connections.load();
  s.framesBuilt = m.framesBuilt.load();
  s.framesSent = m.framesSent.load();
  s.framesDropped = m.framesDropped.load();
  s.messagesReceived = m.messagesReceived.load();
  s.messagesRefused = m.messagesRefused.load();
  s.handshakesRefused = m.handshakesRefused.load();
  s.openConnections = m.openCount.load();
  s.connectionsClosedForRoom = m.connectionsClosedForRoom.load();
  s.connectionsRefused = m.connectionsRefused.load();
  s.acceptFailures = m.acceptFailures.load();
  s.slowPagesDropped = m.slowPagesDropped.load();
  return s;
}

void SceneViewer::setStartPage(const std::string& page) {
  std::lock_guard<std::mutex> lock(startPageMutex());
  startPageStorage() = page;
}

void SceneViewer::startFromPlatform() {
  SceneViewerOptions o;
  o.address = RoboticPlatform::getGuiAddress();
  const int port = RoboticPlatform::getGuiPort();
  o.port = port < 0 ? kSceneViewerDefaultPort : port;
  o.token = RoboticPlatform::getGuiToken();
  {
    std::lock_guard<std::mutex> lock(startPageMutex());
    o.startPage = startPageStorage();
  }
  try {
    instance().start(o);
  } catch (const std::exception& e) {
    std::cerr << "rp: " << e.what() << "\n";
    if (port > 0 || dynamic_cast<const std::invalid_argument*>(&e)) std::exit(2);  // the user asked for exactly this
    std::cerr << "rp: running without the Scene Viewer\n";
    return;
  }
  static std::once_flag atExit;
  std::call_once(atExit, [] { std::atexit([] { instance().stop(); }); });
  std::cerr << "rp: Scene Viewer at " << instance().getUrl() << std::endl;
  if (RoboticPlatform::isQMotorOn()) {  // -qmotor: the plots and tuning window
    const std::string url = instance().getUrl();
    const std::string token = instance().getToken();
    const std::size_t root = url.find('/', url.find("//") + 2);  // end of http://host:port
    const std::string qmotor = url.substr(0, root) + "/qmotor.html" + (token.empty() ? "" : "?token=" + token);
    std::cerr << "rp: QMotor at " << qmotor << std::endl;
    internal::openInBrowser(qmotor, "-qmotor");  // the default browser when there is a display
  }
}

namespace {
// The library registers the viewer as the platform's GUI when it is loaded.
[[maybe_unused]] const bool kGuiRegistered = [] {
  RoboticPlatform::setGuiStarter([] { SceneViewer::startFromPlatform(); });
  return true;
}();
}  // namespace

}  // namespace rp
