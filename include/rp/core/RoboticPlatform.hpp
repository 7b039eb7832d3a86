#pragma once
/// @file
/// Platform start-up and the command-line switches of the paper's Table 3.

#include <functional>
#include <string>
#include <vector>

#include "rp/core/Configuration.hpp"

namespace rp {

class Clock;

/// Global settings of a Robotic Platform program, set by init() from the command line or by
/// the C++ equivalents below.
///
/// Switches (all before `--`; anything after `--` and every `--long` option other than
/// `--help` is left for the program):
/// | switch | meaning | C++ |
/// |---|---|---|
/// | `-sim` / `-nosim` | simulation mode on/off for all objects | setSimulationModeOn() / setSimulationModeOff() |
/// | `-gui` / `-nogui` | start the Scene Viewer or not | setGuiOn() / setGuiOff() |
/// | `-gui-address <ip>` | address the Scene Viewer listens on (default 127.0.0.1) | setGuiAddress() |
/// | `-gui-port <n>` | its TCP port (default 7070 or the next free one; 0: any free port) | setGuiPort() |
/// | `-gui-token <text>` | token pages must present (generated for a non-loopback address) | setGuiToken() |
/// | `-config <file>` | the global configuration file (default `rp.cfg`) | setConfigurationFileName() |
/// | `-qmotor` | open the QMotor window (live plots and tuning) in the default browser with `xdg-open` when a display is present, and print its URL (`rp: QMotor at URL`); without a display only the URL; with the Scene Viewer off (`-nogui`) there is no window and a warning says so | setQMotorOn() |
/// | `-log <file>` | log every log variable of every control program to one CSV file | setLogFileName() |
/// | `-simclock` | run control programs on a simulated clock, as fast as possible | useSimulatedClock() |
/// | `--help` | print the switches and exit 0 | - |
class RoboticPlatform {
 public:
  /// Initialises the platform: parses the switches (removing them from argv), reads and checks
  /// rp.cfg, loads its plugins, installs SIGINT/SIGTERM handlers that shut the system down and
  /// complete the log, and starts the log writer and the GUI if asked for. On a bad switch or a
  /// bad configuration it prints the message (`FILE:LINE: ...`) and exits with status 2 before
  /// any thread starts.
  /// @param[in,out] argc  argument count; reduced by the platform switches
  /// @param[in,out] argv  arguments; platform switches removed, the program's own kept in order
  /// @param[in] programUsage  extra lines printed by `--help` (the program's own options)
  /// Real-time safe: no.
  static void init(int& argc, char** argv, const std::string& programUsage = "");

  /// Parses platform switches without exiting (init() uses it).
  /// @param[in] args  the arguments after the program name
  /// @return the program's own arguments
  /// @throws std::invalid_argument for an unknown switch or a missing value
  static std::vector<std::string> parseCommandLine(const std::vector<std::string>& args);
  /// The `--help` text.
  static std::string usage();
  /// Whether init() has run.
  static bool isInitialized();

  /// Forces simulation mode on for every object (`-sim`).
  static void setSimulationModeOn();
  /// Makes hardware the default for every object (`-nosim`).
  static void setSimulationModeOff();
  /// Whether objects without their own setting simulate (default true: no hardware configured).
  static bool isSimulationModeOn();
  /// Whether `-sim` forces simulation on for every object.
  static bool isSimulationModeForced();
  /// Starts the Scene Viewer in init() (`-gui`, the default).
  static void setGuiOn();
  /// Does not start the Scene Viewer (`-nogui`).
  static void setGuiOff();
  /// Whether the Scene Viewer is to be started.
  static bool isGuiOn();
  /// Sets the address the Scene Viewer listens on (`-gui-address`); any address other than a
  /// loopback one makes the viewer require a token.
  /// @param[in] address  IPv4 or IPv6 literal (default `127.0.0.1`)
  static void setGuiAddress(const std::string& address);
  /// The address the Scene Viewer listens on.
  static std::string getGuiAddress();
  /// Sets the Scene Viewer's TCP port (`-gui-port`).
  /// @param[in] port  0..65535 (0: any free port), or -1 for the default (7070 or the next free one)
  /// @throws std::invalid_argument if out of range
  static void setGuiPort(int port);
  /// The Scene Viewer's TCP port as set (-1: the default).
  static int getGuiPort();
  /// Sets the token pages must present (`-gui-token`); empty: none on loopback, generated otherwise.
  /// @param[in] token  the token: at most 256 of `A-Z a-z 0-9 - . _ ~` (else std::invalid_argument)
  static void setGuiToken(const std::string& token);
  /// The token set with setGuiToken() (empty if none was given).
  static std::string getGuiToken();
  /// `-qmotor`: init() opens the QMotor window (live plots and tuning) in the default browser
  /// with `xdg-open` when a display is present (`DISPLAY` or `WAYLAND_DISPLAY`), and prints its
  /// URL either way; with the Scene Viewer off (`-nogui`) there is no window and a warning says so.
  static void setQMotorOn();
  /// Whether the tuning window is to be opened.
  static bool isQMotorOn();
  /// Sets the global configuration file name (`-config`).
  /// @param[in] fileName  path of the file
  static void setConfigurationFileName(const std::string& fileName);
  /// The global configuration file name (default `rp.cfg`).
  static std::string getConfigurationFileName();
  /// Sets the CSV log file for all control programs (`-log`); empty for no log.
  /// @param[in] fileName  path of the CSV file
  static void setLogFileName(const std::string& fileName);
  /// The CSV log file name (empty: no log).
  static std::string getLogFileName();
  /// Runs control programs started from now on on the platform's simulated clock (`-simclock`).
  static void useSimulatedClock();
  /// Runs control programs started from now on on the real clock (the default).
  static void useRealClock();
  /// The clock new control programs use.
  static Clock& getDefaultClock();

  /// Reads the configuration file named by getConfigurationFileName() (a missing default
  /// `rp.cfg` gives an empty configuration) and makes it the global one.
  /// @throws ConfigError with FILE:LINE
  static void loadConfiguration();
  /// Makes `configuration` the global one (tests and programs that build it themselves).
  /// @param[in] configuration  parsed configuration
  static void setConfiguration(const Configuration& configuration);
  /// The global configuration (empty until loaded). The reference stays valid until the next
  /// setConfiguration() or loadConfiguration(); objects keep their own section alive.
  static const Configuration& getConfiguration();

  /// Registers the function that starts the Scene Viewer (called by init() when the GUI is on).
  /// @param[in] starter  function starting the viewer
  static void setGuiStarter(std::function<void()> starter);

  /// Ends the platform: waits for a system shutdown in progress to complete (or, if none was
  /// requested, holds every arm still running until it is at rest and switches its power off),
  /// destroys the objects the ObjectManager created, stops every control program and completes
  /// the log file. Called automatically at exit after init(), which then sets the exit status:
  /// 128 + the signal number after SIGINT or SIGTERM, kExitAfterShutdown after any other
  /// system shutdown, else the program's own.
  static void finish();

  /// Exit status of a program that init() started and that ends after a system shutdown other
  /// than by a signal (a limit violation, a fault, an emergency stop).
  static constexpr int kExitAfterShutdown = 3;
};

}  // namespace rp
