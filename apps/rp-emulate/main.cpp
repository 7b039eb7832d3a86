// rp-emulate: runs one of the device emulators by hand, on 127.0.0.1 or a pseudo-terminal.
//
//   rp-emulate modbus [-port P] [-duration S]
//       Modbus TCP I/O server; prints "modbus 127.0.0.1:PORT", then every coil change ("coil 3 = 1").
//   rp-emulate barretthand [-movetime MS] [-object COUNTS] [-duration S]
//       BarrettHand on a pseudo-terminal; prints "barretthand /dev/pts/N", then every command received.
//   rp-emulate netft [-port P] [-rate HZ] [-wrench FX FY FZ TX TY TZ] [-countsPerForce C] [-countsPerTorque C]
//                    [-drop N] [-reorder N] [-garble N] [-truncate N] [-duration S]
//       Net F/T RDT server on UDP; prints "netft 127.0.0.1:PORT".
// -port 0 (the default) picks a free port. Runs until SIGINT/SIGTERM or -duration seconds.
// Exit status 2 for bad arguments, 1 if the emulator cannot start.
#include <chrono>
#include <csignal>
#include <iostream>
#include <stdexcept>
#include <string>
#include <thread>

#include "Arguments.hpp"
#include <vector>

#include "BarrettHandEmulator.hpp"
#include "ModbusEmulator.hpp"
#include "NetFtEmulator.hpp"

namespace {

using rp::emulator::toDouble;
using rp::emulator::toInt;
using rp::emulator::UsageError;

volatile std::sig_atomic_t gStop = 0;
void onSignal(int) { gStop = 1; }

constexpr const char* kUsage =
    "usage: rp-emulate modbus [-port P] [-duration S]\n"
    "       rp-emulate barretthand [-movetime MS] [-object COUNTS] [-duration S]\n"
    "       rp-emulate netft [-port P] [-rate HZ] [-wrench FX FY FZ TX TY TZ] [-countsPerForce C]\n"
    "                        [-countsPerTorque C] [-drop N] [-reorder N] [-garble N] [-truncate N] [-duration S]\n";

// Runs until a signal or the duration ends, calling poll() every 20 ms.
template <typename Poll>
void runUntilStopped(double duration, Poll poll) {
  const auto start = std::chrono::steady_clock::now();
  while (!gStop) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    poll();
    if (duration > 0 && std::chrono::steady_clock::now() - start > std::chrono::duration<double>(duration)) break;
  }
}

}  // namespace

int main(int argc, char** argv) {
  using namespace rp::emulator;
  if (argc < 2) {
    std::cerr << kUsage;
    return 2;
  }
  const std::string device = argv[1];
  if (device == "--help" || device == "-help" || device == "-h") {
    std::cout << kUsage;
    return 0;
  }
  double duration = 0;
  ModbusEmulator::Config modbus;
  BarrettHandEmulator::Config hand;
  NetFtEmulator::Config netft;
  NetFtEmulator::Faults faults;
  std::array<double, 6> wrench{};
  try {
    if (device != "modbus" && device != "barretthand" && device != "netft")
      throw UsageError("unknown device '" + device + "' (modbus, barretthand or netft)");
    for (int i = 2; i < argc; ++i) {
      const std::string opt = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw UsageError(opt + " needs a value");
        return argv[++i];
      };
      if (opt == "-duration") duration = toDouble(opt, value());
      else if (opt == "-port") modbus.port = netft.port = toInt(opt, value());
      else if (opt == "-movetime" && device == "barretthand") hand.moveTimeMs = toInt(opt, value());
      else if (opt == "-object" && device == "barretthand") hand.objectAt = toInt(opt, value());
      else if (opt == "-rate" && device == "netft") netft.rateHz = toDouble(opt, value());
      else if (opt == "-countsPerForce" && device == "netft") netft.countsPerForce = toDouble(opt, value());
      else if (opt == "-countsPerTorque" && device == "netft") netft.countsPerTorque = toDouble(opt, value());
      else if (opt == "-drop" && device == "netft") faults.dropEvery = toInt(opt, value());
      else if (opt == "-reorder" && device == "netft") faults.reorderEvery = toInt(opt, value());
      else if (opt == "-garble" && device == "netft") faults.garbleEvery = toInt(opt, value());
      else if (opt == "-truncate" && device == "netft") faults.truncateEvery = toInt(opt, value());
      else if (opt == "-wrench" && device == "netft") {
        for (double& w : wrench) w = toDouble(opt, value());
      } else {
        throw UsageError("unknown option '" + opt + "' for " + device);
      }
    }
    if (modbus.port < 0 || modbus.port > 65535) throw UsageError("-port must be 0 .. 65535");
    if (duration < 0) throw UsageError("-duration must not be negative (0: until a signal)");
    if (hand.moveTimeMs < 0) throw UsageError("-movetime must not be negative");
    for (const int every : {faults.dropEvery, faults.reorderEvery, faults.garbleEvery, faults.truncateEvery})
      if (every < 0) throw UsageError("-drop, -reorder, -garble and -truncate must not be negative (0: never)");
  } catch (const UsageError& e) {
    std::cerr << "rp-emulate: " << e.what() << "\n" << kUsage;
    return 2;
  }
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  try {
    if (device == "modbus") {
      ModbusEmulator server(modbus);
      server.start();
      std::cout << "modbus 127.0.0.1:" << server.port() << std::endl;
      std::vector<bool> coils(64, false);
      runUntilStopped(duration, [&] {
        for (int c = 0; c < 64; ++c)
          if (server.coil(c) != coils[static_cast<std::size_t>(c)]) {
            coils[static_cast<std::size_t>(c)] = server.coil(c);
            std::cout << "coil " << c << " = " << coils[static_cast<std::size_t>(c)] << std::endl;
          }
      });
    } else if (device == "barretthand") {
      BarrettHandEmulator emulator(hand);
      emulator.start();
      std::cout << "barretthand " << emulator.devicePath() << std::endl;
      std::size_t shown = 0;
      runUntilStopped(duration, [&] {
        const auto commands = emulator.commands();
        for (; shown < commands.size(); ++shown) std::cout << "command " << commands[shown] << std::endl;
      });
    } else {
      NetFtEmulator sensor(netft);
      sensor.setWrench(wrench);
      sensor.setFaults(faults);
      sensor.start();
      std::cout << "netft 127.0.0.1:" << sensor.port() << std::endl;
      runUntilStopped(duration, [] {});
    }
  } catch (const std::exception& e) {
    std::cerr << "rp-emulate: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
