// RoboticPlatform: command line (Table 3), configuration loading, signals, start-up and exit.
#include "rp/core/RoboticPlatform.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <stdexcept>

#include "../gui/UrlToken.hpp"
#include "Registry.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/rt/Clock.hpp"
#include "rp/rt/ControlProgram.hpp"
#include "rp/rt/LogWriter.hpp"

namespace rp {

namespace {

struct PlatformState {
  std::mutex mutex;
  std::string configFile = "rp.cfg";
  bool configFileGiven = false;
  std::string logFile;
  std::function<void()> guiStarter;
  std::string guiAddress = "127.0.0.1";
  std::string guiToken;
  int guiPort = -1;  // -1: the viewer's default port (with fallback to the next free one)
  std::atomic<int> simulation{-1};  // -1 default (on), 0 -nosim, 1 -sim (forced)
  std::atomic<bool> gui{true};
  std::atomic<bool> qmotor{false};
  std::atomic<bool> simulatedClock{false};
  std::atomic<bool> initialized{false};
};

PlatformState& state() {
  static PlatformState* s = new PlatformState;  // never destroyed (used by exit handlers)
  return *s;
}

SimulatedClock& platformSimulatedClock() {
  static SimulatedClock* c = new SimulatedClock(1e-4);
  return *c;
}

// SIGINT and SIGTERM: the first starts a system shutdown (the watcher thread ends the process
// with 128 + the signal once it is complete). Another one while the shutdown brings the arms to
// rest does not cut it short (`timeout` signals the program and then its process group; a user
// presses Ctrl-C again): it used to end the process at once, with no hold and no complete log.
// Once the shutdown is complete (a program that does not end after it), another signal ends the
// process. SIGKILL always ends it at once; a hardware server's watchdog then switches the outputs off.
void onSignal(int sig) {
  auto& reg = internal::registry();
  int none = 0;
  if (!reg.signalNumber.compare_exchange_strong(none, sig)) {
    if (reg.shutdownComplete.load()) _exit(128 + reg.signalNumber.load());
    static const char note[] = "rp: the system shutdown is still bringing the arms to rest (SIGKILL ends the program at once)\n";
    const ssize_t ignored = write(STDERR_FILENO, note, sizeof note - 1);
    (void)ignored;
    return;
  }
  ObjectManager::requestSystemShutdown(sig == SIGINT ? "SIGINT received" : "SIGTERM received");
}

// The last exit handler init() registers runs first at exit: it completes a shutdown in
// progress (or holds and powers off the arms still running), closes the log, and sets the exit
// status: 128 + the signal after SIGINT or SIGTERM; 1 when the -log file could not be written
// completely (its writer said why on stderr and kept the complete rows); kExitAfterShutdown
// after any other system shutdown (a fault, an emergency stop); else the program's own.
void atExit() {
  RoboticPlatform::finish();
  auto& reg = internal::registry();
  std::fflush(nullptr);
  if (const int sig = reg.signalNumber.load()) _exit(128 + sig);
  if (LogWriter::hasPlatformWriterFailed()) _exit(1);
  if (ObjectManager::isShutdownRequested()) {
    std::fprintf(stderr, "rp: the program ends after a system shutdown (%s): exit status %d\n",
                 ObjectManager::getShutdownReason().c_str(), RoboticPlatform::kExitAfterShutdown);
    std::fflush(nullptr);
    _exit(RoboticPlatform::kExitAfterShutdown);
  }
}

}  // namespace

std::string RoboticPlatform::usage() {
  return "Robotic Platform switches:\n"
         "  -sim               simulation mode on for every object\n"
         "  -nosim             use the hardware (objects may still set simulationMode on)\n"
         "  -gui | -nogui      start the Scene Viewer or not (default: start it)\n"
         "  -gui-address <ip>  address the Scene Viewer listens on (default 127.0.0.1)\n"
         "  -gui-port <n>      its TCP port (default 7070 or the next free one; 0: any free port)\n"
         "  -gui-token <text>  token pages must present (generated when the address is not loopback)\n"
         "  -config <file>     global configuration file (default: rp.cfg)\n"
         "  -qmotor            open the QMotor window (live plots and tuning) in the default\n"
         "                     browser (xdg-open) when a display is present, and print its URL;\n"
         "                     without a display only the URL; with the Scene Viewer off\n"
         "                     (-nogui) there is no window and a warning says so\n"
         "  -log <file>        log every log variable of every control program to one CSV file\n"
         "  -simclock          run control programs on a simulated clock, as fast as possible\n"
         "  --help             print this text and exit\n"
         "Arguments after -- and --long options are left for the program.\n";
}

std::vector<std::string> RoboticPlatform::parseCommandLine(const std::vector<std::string>& args) {
  std::vector<std::string> rest;
  auto& s = state();
  // A switch with its opposite is a slip, not "the last one wins" (-sim -nosim drove the
  // hardware): refused before any switch takes effect.
  const auto end = std::find(args.begin(), args.end(), "--");
  for (const auto& [on, off] : {std::pair<const char*, const char*>{"-sim", "-nosim"}, {"-gui", "-nogui"}}) {
    const auto a = std::find(args.begin(), end, on), b = std::find(args.begin(), end, off);
    if (a != end && b != end)
      throw std::invalid_argument("switches '" + std::string(a < b ? on : off) + "' and '" + (a < b ? off : on) +
                                  "' contradict each other");
  }
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--") {
      rest.insert(rest.end(), args.begin() + static_cast<long>(i), args.end());
      break;
    }
    auto value = [&](const char* what) -> std::string {
      if (i + 1 >= args.size() || args[i + 1].empty())
        throw std::invalid_argument("switch '" + a + "' needs a value (" + what + ")");
      return args[++i];
    };
    if (a == "-sim") setSimulationModeOn();
    else if (a == "-nosim") setSimulationModeOff();
    else if (a == "-gui") setGuiOn();
    else if (a == "-nogui") setGuiOff();
    else if (a == "-qmotor") setQMotorOn();
    else if (a == "-simclock") useSimulatedClock();
    else if (a == "-config") setConfigurationFileName(value("a file name"));
    else if (a == "-log") setLogFileName(value("a CSV file name"));
    else if (a == "-gui-address") setGuiAddress(value("an IP address"));
    else if (a == "-gui-token") {
      try {
        setGuiToken(value("a token"));
      } catch (const std::invalid_argument& e) {  // (the token itself, a secret, is not repeated)
        throw std::invalid_argument(std::string("switch '-gui-token' needs ") + e.what());
      }
    }
    else if (a == "-gui-port") {
      const std::string v = value("a port number 0..65535");
      std::size_t used = 0;
      int port = -1;
      try {
        // Digits only: std::stoi also takes " 80" and "+80".
        if (v.find_first_not_of("0123456789") == std::string::npos && v.size() <= 5) port = std::stoi(v, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != v.size() || port < 0 || port > 65535)
        throw std::invalid_argument("switch '-gui-port' needs a port number 0..65535, not '" + v + "'");
      setGuiPort(port);
    }
    else if (a == "--help" || a == "-help" || a == "-h") throw std::invalid_argument("--help");
    else if (a.size() >= 2 && a[0] == '-' && a[1] != '-' && !(a[1] >= '0' && a[1] <= '9') && a[1] != '.')
      throw std::invalid_argument("unknown platform switch '" + a +
                                  "' (known: -sim, -nosim, -gui, -nogui, -gui-address, -gui-port, -gui-token, -config, -qmotor, -log, "
                                  "-simclock, --help)");
    else
      rest.push_back(a);
  }
  (void)s;
  return rest;
}

void RoboticPlatform::init(int& argc, char** argv, const std::string& programUsage) {
  auto& s = state();
  const std::string program = argc > 0 && argv && argv[0] ? std::filesystem::path(argv[0]).filename().string() : "rp";
  std::vector<std::string> args;
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
  std::vector<std::string> rest;
  try {
    rest = parseCommandLine(args);
  } catch (const std::invalid_argument& e) {
    if (std::string(e.what()) == "--help") {
      std::cout << "usage: " << program << " [switches] [program arguments]\n" << usage();
      if (!programUsage.empty()) std::cout << programUsage << (programUsage.back() == '\n' ? "" : "\n");
      std::exit(0);
    }
    std::cerr << program << ": " << e.what() << "\n";
    std::exit(2);
  }
  // Remove the platform switches; keep the program's arguments in order (argv[argc] stays null).
  int out = 1;
  for (int i = 1; i < argc; ++i) {
    if (out - 1 < static_cast<int>(rest.size()) && rest[static_cast<std::size_t>(out - 1)] == argv[i]) argv[out++] = argv[i];
  }
  argc = out;
  if (argv) argv[argc] = nullptr;

  try {
    loadConfiguration();
  } catch (const ConfigError& e) {
    std::cerr << e.what() << "\n";
    std::exit(2);
  }
  // Simulation is the default when no hardware is configured.
  if (s.simulation.load() < 0) {
    bool hardware = false;
    for (const auto& section : getConfiguration().sections())
      if (const ConfigSetting* sim = section.find("simulationMode"); sim && sim->values == std::vector<std::string>{"off"})
        hardware = true;
    if (!hardware) std::cerr << "rp: no hardware configured: every object runs in simulation mode (-nosim to change)\n";
  }
  s.initialized = true;
  // An exception nobody catches (a robot that cannot be created, a target that cannot be
  // reached) ends the program with its message and status 1 instead of an abort; exit() still
  // completes the log file.
  static std::string terminateProgram;
  terminateProgram = program;
  std::set_terminate([] {
    std::string what = "unknown exception";
    if (std::exception_ptr e = std::current_exception()) {
      try {
        std::rethrow_exception(e);
      } catch (const std::exception& ex) {
        what = ex.what();
      } catch (...) {
      }
    }
    std::cerr << terminateProgram << ": error: " << what << std::endl;
    std::exit(1);
  });
  internal::ensureShutdownWatcher();
  signal(SIGINT, onSignal);
  signal(SIGTERM, onSignal);
  // A closed stdout (`program | head -1`) must not kill the control program: writes to it fail
  // with EPIPE instead.
  signal(SIGPIPE, SIG_IGN);
  std::atexit(atExit);
  if (!getLogFileName().empty()) {
    try {
      LogWriter::openPlatformWriter(getLogFileName());
      // A log that can no longer be written ends the run: the arms are held and powered off
      // (a system shutdown), the complete rows are kept, and the exit status is 1.
      LogWriter::getPlatformWriter()->setFailureHandler(
          [](const std::string&) { ObjectManager::requestSystemShutdown("the -log file cannot be written"); });
    } catch (const std::exception& e) {
      std::cerr << program << ": -log: " << e.what() << "\n";
      std::exit(2);
    }
  }
  std::function<void()> starter;
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    starter = s.guiStarter;
  }
  if (isGuiOn() && starter) starter();
  else if (isQMotorOn())
    std::cerr << "rp: -qmotor: no QMotor window, the Scene Viewer is off (-nogui)" << std::endl;
}

bool RoboticPlatform::isInitialized() { return state().initialized.load(); }

void RoboticPlatform::setSimulationModeOn() { state().simulation = 1; }
void RoboticPlatform::setSimulationModeOff() { state().simulation = 0; }
bool RoboticPlatform::isSimulationModeOn() { return state().simulation.load() != 0; }
bool RoboticPlatform::isSimulationModeForced() { return state().simulation.load() == 1; }
void RoboticPlatform::setGuiOn() { state().gui = true; }
void RoboticPlatform::setGuiOff() { state().gui = false; }
bool RoboticPlatform::isGuiOn() { return state().gui.load(); }
void RoboticPlatform::setGuiAddress(const std::string& address) {
  std::lock_guard<std::mutex> lock(state().mutex);
  state().guiAddress = address;
}

std::string RoboticPlatform::getGuiAddress() {
  std::lock_guard<std::mutex> lock(state().mutex);
  return state().guiAddress;
}

void RoboticPlatform::setGuiPort(int port) {
  if (port < -1 || port > 65535) throw std::invalid_argument("RoboticPlatform::setGuiPort: port must be -1..65535");
  std::lock_guard<std::mutex> lock(state().mutex);
  state().guiPort = port;
}

int RoboticPlatform::getGuiPort() {
  std::lock_guard<std::mutex> lock(state().mutex);
  return state().guiPort;
}

void RoboticPlatform::setGuiToken(const std::string& token) {
  if (!internal::isUrlToken(token))
    throw std::invalid_argument("at most 256 letters, digits and - . _ ~ (a token goes into the URL as it is)");
  std::lock_guard<std::mutex> lock(state().mutex);
  state().guiToken = token;
}

std::string RoboticPlatform::getGuiToken() {
  std::lock_guard<std::mutex> lock(state().mutex);
  return state().guiToken;
}

void RoboticPlatform::setQMotorOn() { state().qmotor = true; }
bool RoboticPlatform::isQMotorOn() { return state().qmotor.load(); }

void RoboticPlatform::setConfigurationFileName(const std::string& fileName) {
  std::lock_guard<std::mutex> lock(state().mutex);
  state().configFile = fileName;
  state().configFileGiven = true;
}

std::string RoboticPlatform::getConfigurationFileName() {
  std::lock_guard<std::mutex> lock(state().mutex);
  return state().configFile;
}

void RoboticPlatform::setLogFileName(const std::string& fileName) {
  std::lock_guard<std::mutex> lock(state().mutex);
  state().logFile = fileName;
}

std::string RoboticPlatform::getLogFileName() {
  std::lock_guard<std::mutex> lock(state().mutex);
  return state().logFile;
}

void RoboticPlatform::useSimulatedClock() { state().simulatedClock = true; }
void RoboticPlatform::useRealClock() { state().simulatedClock = false; }

Clock& RoboticPlatform::getDefaultClock() {
  if (state().simulatedClock.load()) return platformSimulatedClock();
  return RealClock::instance();
}

void RoboticPlatform::loadConfiguration() {
  std::string file;
  bool given;
  {
    std::lock_guard<std::mutex> lock(state().mutex);
    file = state().configFile;
    given = state().configFileGiven;
  }
  std::error_code ec;
  if (!given && !std::filesystem::exists(file, ec)) {
    setConfiguration(Configuration());
    return;
  }
  setConfiguration(Configuration::read(file));
}

void RoboticPlatform::setConfiguration(const Configuration& configuration) {
  auto& reg = internal::registry();
  auto copy = std::make_shared<const Configuration>(configuration);
  std::lock_guard<std::mutex> lock(reg.configMutex);
  reg.configuration = std::move(copy);
}

const Configuration& RoboticPlatform::getConfiguration() {
  // The registry keeps every configuration that objects still use alive through their own
  // shared pointers; the current one lives until it is replaced.
  return *internal::currentConfiguration();
}

void RoboticPlatform::setGuiStarter(std::function<void()> starter) {
  std::lock_guard<std::mutex> lock(state().mutex);
  state().guiStarter = std::move(starter);
}

void RoboticPlatform::finish() {
  auto& reg = internal::registry();
  if (ObjectManager::isShutdownRequested()) {
    // A shutdown in progress (a signal, a fault) is carried out by the manager's thread: the
    // program ends only once it is complete (the arms at rest, powered off, the log closed).
    ObjectManager::waitForShutdown(reg.timeoutSeconds.load() + 5.0);
  } else {
    // The arms still running (objects the program did not destroy) are held until at rest and
    // powered off, as in a shutdown.
    const auto pending = ObjectManager().shutdownAllObjects("the program ends");
    for (const auto& name : pending) std::fprintf(stderr, "rp: at exit: %s did not complete its shutdown\n", name.c_str());
  }
  ObjectManager().deleteAllObjects();
  ControlProgram::stopAll();
  LogWriter::closePlatformWriter();
}

}  // namespace rp
