// rp-hwserver: a QMotor-style hardware server. Does one I/O board's I/O at a fixed rate and serves
// its lines to any number of client programs (HwServerIoBoard) through POSIX shared memory.
//
//   rp-hwserver -name NAME [-rate HZ] [-duration S] -board simulated [-loopback]
//               [-digitalInputs N] [-digitalOutputs N] [-analogInputs N] [-analogOutputs N] [-encoders N]
//   rp-hwserver -name NAME [-rate HZ] [-duration S] -board modbus [-address A] -port P [-unit ID]
//               [-timeout MS] [-coils LIST] [-discreteInputs LIST] [-inputRegisters LIST]
//               [-holdingRegisters LIST] [-encoderRegisters LIST] [-voltsPerCount V]
//   rp-hwserver -name NAME [-rate HZ] [-duration S] -board puma560 [-countsPerRadian C]
//       a Puma 560 wired to a board: encoders 0-5 in counts, analog outputs 0-5 in DAC volts
//       (torque = volts x amplifier gain, gain = torque limit / 10 V), digital output 0 enables
//       the amplifiers (brakes hold the arm while it is off); the arm's dynamics are simulated.
// LIST is comma-separated register or coil addresses, one per line (e.g. -coils 0,1,2,3).
// -watchdog MS (default 50): a client silent for longer than MS while one of its outputs is on
// (killed, stopped, hung) has its outputs switched off (digital off, 0 V), logged once on stderr;
// a detached or dead client's outputs go off too.
// Prints "rp-hwserver: serving NAME ..." once clients can attach; stops on SIGINT/SIGTERM or after
// -duration seconds, setting every output to zero. Exit status 2 for bad arguments, 1 for errors.
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "ArmIoBoard.hpp"
#include "Arguments.hpp"
#include "rp/io/HwServer.hpp"
#include "rp/io/IoException.hpp"
#include "rp/io/ModbusIoBoard.hpp"
#include "rp/io/SimulatedIoBoard.hpp"
#include "rp/model/Puma560Model.hpp"

namespace {

using rp::emulator::toDouble;
using rp::emulator::toInt;
using rp::emulator::toIntList;
using rp::emulator::UsageError;

volatile std::sig_atomic_t gStop = 0;
void onSignal(int) { gStop = 1; }

constexpr const char* kUsage =
    "usage: rp-hwserver -name NAME [-rate HZ] [-duration S] [-watchdog MS] -board simulated|modbus|puma560 [board options]\n"
    "  -watchdog MS: switch off the outputs of a client silent for MS milliseconds (default 50)\n"
    "  simulated: [-loopback] [-digitalInputs N] [-digitalOutputs N] [-analogInputs N] [-analogOutputs N] [-encoders N]\n"
    "  modbus:    [-address A] -port P [-unit ID] [-timeout MS] [-coils LIST] [-discreteInputs LIST]\n"
    "             [-inputRegisters LIST] [-holdingRegisters LIST] [-encoderRegisters LIST] [-voltsPerCount V]\n"
    "  puma560:   [-countsPerRadian C]   (encoders 0-5, DAC volts 0-5, digital output 0 = amplifier enable)\n";

}  // namespace

int main(int argc, char** argv) {
  std::string name, board;
  double rate = 1000.0, duration = 0.0, watchdog = rp::HwServer::kDefaultWatchdogMs;
  rp::SimulatedIoBoard::Config sim;
  rp::ModbusIoBoard::Config modbus;
  rp::emulator::ArmIoBoard::Config arm;
  modbus.port = 0;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string opt = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw UsageError(opt + " needs a value");
        return argv[++i];
      };
      if (opt == "-name") name = value();
      else if (opt == "-rate") rate = toDouble(opt, value());
      else if (opt == "-duration") duration = toDouble(opt, value());
      else if (opt == "-watchdog") watchdog = toDouble(opt, value());
      else if (opt == "-board") board = value();
      else if (opt == "-loopback") sim.loopback = true;
      else if (opt == "-digitalInputs") sim.digitalInputs = toInt(opt, value());
      else if (opt == "-digitalOutputs") sim.digitalOutputs = toInt(opt, value());
      else if (opt == "-analogInputs") sim.analogInputs = toInt(opt, value());
      else if (opt == "-analogOutputs") sim.analogOutputs = toInt(opt, value());
      else if (opt == "-encoders") sim.encoders = toInt(opt, value());
      else if (opt == "-address") modbus.address = value();
      else if (opt == "-port") modbus.port = toInt(opt, value());
      else if (opt == "-unit") modbus.unitId = toInt(opt, value());
      else if (opt == "-timeout") modbus.responseTimeoutMs = toInt(opt, value());
      else if (opt == "-coils") modbus.digitalOutputCoils = toIntList(opt, value());
      else if (opt == "-discreteInputs") modbus.digitalInputs = toIntList(opt, value());
      else if (opt == "-inputRegisters") modbus.analogInputRegisters = toIntList(opt, value());
      else if (opt == "-holdingRegisters") modbus.analogOutputRegisters = toIntList(opt, value());
      else if (opt == "-encoderRegisters") modbus.encoderRegisters = toIntList(opt, value());
      else if (opt == "-voltsPerCount") modbus.voltsPerCount = toDouble(opt, value());
      else if (opt == "-countsPerRadian") arm.countsPerRadian = toDouble(opt, value());
      else if (opt == "-h" || opt == "-help" || opt == "--help") {
        std::cout << kUsage;
        return 0;
      } else {
        throw UsageError("unknown option '" + opt + "'");
      }
    }
    if (name.empty()) throw UsageError("-name is required");
    if (board != "simulated" && board != "modbus" && board != "puma560")
      throw UsageError("-board must be simulated, modbus or puma560");
    if (!(arm.countsPerRadian > 0)) throw UsageError("-countsPerRadian must be positive");
    if (duration < 0) throw UsageError("-duration must not be negative");
    if (!(watchdog >= 1 && watchdog <= 60000)) throw UsageError("-watchdog must be 1 .. 60000 ms");
  } catch (const UsageError& e) {
    std::cerr << "rp-hwserver: " << e.what() << "\n" << kUsage;
    return 2;
  }

  try {
    std::unique_ptr<rp::IoBoard> io;
    rp::Puma560Model puma;
    if (board == "simulated") io = std::make_unique<rp::SimulatedIoBoard>(sim);
    else if (board == "modbus") io = std::make_unique<rp::ModbusIoBoard>(modbus);
    else io = std::make_unique<rp::emulator::ArmIoBoard>(puma, arm);
    rp::HwServer server(*io, name, rate, watchdog);
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    server.start();
    std::cout << "rp-hwserver: serving " << name << " (" << board << " board, " << io->numDigitalInputs()
              << " DI, " << io->numDigitalOutputs() << " DO, " << io->numAnalogInputs() << " AI, "
              << io->numAnalogOutputs() << " AO, " << io->numEncoders() << " encoders) at " << rate
              << " Hz, client watchdog " << watchdog << " ms" << std::endl;
    rp::IoStatus lastStatus = rp::IoStatus::kOk;
    std::uint64_t trips = 0;
    const auto start = std::chrono::steady_clock::now();
    while (!gStop) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      const rp::IoStatus s = server.boardStatus();
      if (s != lastStatus) {  // report board failures and recoveries once each
        if (s != rp::IoStatus::kOk) std::cerr << "rp-hwserver: board error: " << rp::toString(s) << std::endl;
        else std::cerr << "rp-hwserver: board working again" << std::endl;
        lastStatus = s;
      }
      if (const std::uint64_t t = server.watchdogTrips(); t != trips) {  // once per client cut off
        double silenceMs = 0;
        const int pid = server.lastWatchdogTrip(silenceMs);
        std::cerr << "rp-hwserver: client (pid " << pid << ") silent for " << std::llround(silenceMs)
                  << " ms: its outputs switched off (watchdog " << watchdog << " ms)" << std::endl;
        trips = t;
      }
      if (duration > 0 && std::chrono::steady_clock::now() - start > std::chrono::duration<double>(duration)) break;
    }
    server.stop();
    std::cout << "rp-hwserver: stopped after " << server.cycles() << " cycles, " << server.overruns() << " overruns"
              << std::endl;
  } catch (const rp::IoException& e) {
    std::cerr << "rp-hwserver: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
