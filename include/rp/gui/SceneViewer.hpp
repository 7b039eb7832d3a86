#pragma once
/// @file
/// The Scene Viewer server (paper sections 3.12 and 4.1): an HTTP and WebSocket server inside
/// the process that serves the browser front end (web/) and streams the work cell to it.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace rp {

/// Version of the message protocol between the server and the pages (sent in `hello` and in
/// every binary state frame). See docs/gui.md for the messages.
inline constexpr int kSceneViewerProtocolVersion = 1;

/// Default TCP port of the Scene Viewer; when it is taken the server tries the next ports.
inline constexpr int kSceneViewerDefaultPort = 7070;

/// Most connections (pages and HTTP requests) the Scene Viewer keeps open at once; another one
/// takes the place of the HTTP connection that has waited longest for a request, or is closed.
inline constexpr std::size_t kSceneViewerMaxConnections = 64;

/// Where and how the Scene Viewer listens.
struct SceneViewerOptions {
  std::string address = "127.0.0.1";  ///< IP address to listen on (IPv4 or IPv6 literal)
  /// TCP port; kSceneViewerDefaultPort tries up to 20 following ports when it is taken (then any
  /// free port); 0 asks the system for any free port; any other port must be free.
  int port = kSceneViewerDefaultPort;
  /// Token every WebSocket must present (`?token=`); empty: none on a loopback address, a
  /// generated one on any other address.
  std::string token;
  std::string webRoot;  ///< folder of the built front end; empty: defaultWebRoot()
  double rate = 60;     ///< state frames per second sent to each page [Hz], 1..240
  std::string startPage = "index.html";  ///< page (with query) the printed URL opens
  /// A page whose socket has not taken a message for this long (it stopped reading) is dropped [s],
  /// 0.1..3600.
  double writeTimeout = 10;
};

/// Counters of a running Scene Viewer (for tests and the measurement script).
struct SceneViewerStatistics {
  std::size_t pages = 0;             ///< WebSocket connections open now
  std::uint64_t connections = 0;     ///< WebSocket connections accepted since start()
  std::uint64_t framesBuilt = 0;     ///< state frames built
  std::uint64_t framesSent = 0;      ///< state frames written to pages
  std::uint64_t framesDropped = 0;   ///< state frames replaced by a newer one before a page took them
  std::uint64_t messagesReceived = 0;  ///< commands received
  std::uint64_t messagesRefused = 0;   ///< commands answered with an error
  std::uint64_t handshakesRefused = 0; ///< WebSocket upgrades refused (token, Origin, Host, path)
  std::size_t openConnections = 0;     ///< TCP connections open now (pages and HTTP)
  /// HTTP connections waiting for a request closed to make room for a new connection
  std::uint64_t connectionsClosedForRoom = 0;
  std::uint64_t connectionsRefused = 0;  ///< new connections closed at once: kSceneViewerMaxConnections busy
  std::uint64_t acceptFailures = 0;      ///< accept errors (such as out of file descriptors)
  std::uint64_t slowPagesDropped = 0;    ///< pages dropped because they stopped reading (writeTimeout)
};

/// The process's Scene Viewer server: one thread running an HTTP + WebSocket server (Boost.Beast)
/// that serves the front end's files, replays the scene (every object's name, class, 3D model,
/// connection, commands and control panel, addressed by paths `/objects/NAME`) to each page that
/// connects, sends binary state frames (every frame pose and state value) at `rate`, and executes
/// validated commands from the pages (object commands, display mode, tunable parameters, object
/// messages) in a worker thread. Each page has its own bounded queue keeping only the latest state
/// frame, so a slow page never slows the others or a servo loop; state is read from the snapshots
/// the servo threads publish without blocking.
///
/// RoboticPlatform::init() starts it unless `-nogui` (with `-gui-address`, `-gui-port`,
/// `-gui-token`) and prints the URL to open. Programs may also start and stop it themselves.
class SceneViewer {
 public:
  /// The process's viewer (not started). Real-time safe: no.
  static SceneViewer& instance();

  /// Starts listening and the server thread; prints nothing (see getUrl()) but a warning on
  /// stderr when the address is not a loopback address.
  /// @param[in] options  address, port, token, web root and rate
  /// @throws std::invalid_argument for a bad address, port or rate
  /// @throws std::runtime_error if it cannot listen (port taken and no fallback)
  /// @throws std::logic_error if already running
  /// Real-time safe: no.
  void start(const SceneViewerOptions& options = {});
  /// Stops the server thread and closes every page; does nothing when not running.
  /// Real-time safe: no.
  void stop();
  /// Whether the server runs.
  bool isRunning() const;
  /// The URL to open, with the token if one is required (empty when not running).
  std::string getUrl() const;
  /// The TCP port actually listened on (0 when not running).
  int getPort() const;
  /// The token pages must present (empty: none required).
  std::string getToken() const;
  /// The folder the front end is served from.
  std::string getWebRoot() const;
  /// Counters since start(). Real-time safe: no.
  SceneViewerStatistics getStatistics() const;

  /// The folder of the built front end: the environment variable `RP_WEB_ROOT` if set, else the
  /// installed `share/roboticplatform/web` beside the loaded library (`<libdir>/../share/...`,
  /// found at run time, so an installed prefix works wherever it is copied) if it holds an
  /// `index.html`, else the build tree's `webroot/` compiled in.
  static std::string defaultWebRoot();
  /// Whether `address` is a loopback address (127.0.0.0/8 or ::1).
  /// @param[in] address  IP address literal
  static bool isLoopbackAddress(const std::string& address);

  /// Starts the viewer with the options RoboticPlatform::init() collected from the command line
  /// (`-gui-address`, `-gui-port`, `-gui-token`) and prints `rp: Scene Viewer at URL` on stderr.
  /// init() calls it through RoboticPlatform::setGuiStarter(). If the viewer cannot start, it
  /// prints why; a port given explicitly that cannot be used ends the program with status 2.
  static void startFromPlatform();
  /// Sets the page the URL printed by startFromPlatform() opens (utility programs call it before
  /// RoboticPlatform::init(), e.g. `jointmove.html?object=puma`).
  /// @param[in] page  page and query, relative to the web root
  static void setStartPage(const std::string& page);

  ~SceneViewer();                                    ///< stops the server
  SceneViewer(const SceneViewer&) = delete;             ///< not copyable
  SceneViewer& operator=(const SceneViewer&) = delete;  ///< not copyable

 private:
  SceneViewer();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rp
