#include "BoardSettings.hpp"

#include "rp/io/HwServerIoBoard.hpp"
#include "rp/io/IoException.hpp"
#include "rp/io/ModbusIoBoard.hpp"
#include "rp/io/SimulatedIoBoard.hpp"

namespace rp::internal {

void declareTwoLineBoardSettings(SettingSchema& schema, const char* lineA, const char* lineB) {
  schema.addChoice("board", {"simulated", "modbus", "hwserver"}, "the I/O board that drives the lines");
  schema.addInteger(lineA, "digital output line (modbus: coil address)");
  schema.addInteger(lineB, "digital output line (modbus: coil address)");
  schema.addWord("address", "Modbus TCP server address");
  schema.addInteger("port", "Modbus TCP port", 1, 65535);
  schema.addInteger("unitId", "Modbus unit id", 0, 247);
  schema.addInteger("timeout", "Modbus response timeout [ms]", 1, 60000);
  schema.addWord("server", "hardware server name (rp-hwserver -name NAME)");
  schema.setDefault("board", "(none: the lines are not driven, commands report an error)");
  schema.setDefault(lineA, "(required with board)");
  schema.setDefault(lineB, "(required with board)");
  schema.setDefault("address", "127.0.0.1");
  schema.setDefault("port", "502");
  schema.setDefault("unitId", "1");
  schema.setDefault("timeout", "200");
  schema.setDefault("server", "(required with board hwserver)");
}

namespace {
int integer(const ConfigSection& section, const char* name, int fallback) {
  const ConfigSetting* s = section.find(name);
  if (s == nullptr) return fallback;
  const double v = section.getNumbers(name).at(0);
  if (v < 0 || v > 65535) throw section.errorAt(*s, std::string("setting '") + name + "' must be 0 .. 65535");
  return static_cast<int>(v);
}
int requiredLine(const ConfigSection& section, const char* name) {
  if (!section.has(name))
    throw ConfigError(section.fileName(), section.line(),
                      "[" + section.name() + "] has a 'board' but no '" + name + "' setting");
  return integer(section, name, 0);
}
}  // namespace

TwoLineBoard createTwoLineBoard(const ConfigSection& section, const char* lineA, const char* lineB) {
  TwoLineBoard out;
  if (!section.has("board")) {
    for (const char* s : {lineA, lineB, "address", "port", "unitId", "timeout", "server"})
      if (const ConfigSetting* setting = section.find(s))
        throw section.errorAt(*setting, std::string("setting '") + s + "' needs a 'board' setting");
    return out;
  }
  const ConfigSetting& boardSetting = *section.find("board");
  const std::string kind = section.getWord("board");
  const int a = requiredLine(section, lineA);
  const int b = requiredLine(section, lineB);
  if (a == b) throw section.errorAt(boardSetting, std::string("'") + lineA + "' and '" + lineB + "' are the same line");
  if (kind != "hwserver" && section.has("server"))
    throw section.errorAt(*section.find("server"), "setting 'server' needs 'board hwserver'");
  if (kind == "modbus") {
    ModbusIoBoard::Config config;
    if (section.has("address")) config.address = section.getWord("address");
    config.port = integer(section, "port", 502);
    config.unitId = integer(section, "unitId", 1);
    config.responseTimeoutMs = integer(section, "timeout", 200);
    config.digitalOutputCoils = {a, b};
    try {
      out.board = std::make_unique<ModbusIoBoard>(config);
    } catch (const IoException& e) {
      throw section.errorAt(boardSetting, e.what());
    }
    out.lineA = 0;
    out.lineB = 1;
    return out;
  }
  for (const char* s : {"address", "port", "unitId", "timeout"})
    if (const ConfigSetting* setting = section.find(s))
      throw section.errorAt(*setting, std::string("setting '") + s + "' needs 'board modbus'");
  out.lineA = a;
  out.lineB = b;
  if (kind == "simulated") {
    out.board = std::make_unique<SimulatedIoBoard>();
  } else {
    if (!section.has("server"))
      throw ConfigError(section.fileName(), section.line(),
                        "[" + section.name() + "] has 'board hwserver' but no 'server' setting");
    try {
      // A background heartbeat: the lines stay while this process runs, and go off when it ends.
      out.board = std::make_unique<HwServerIoBoard>(section.getWord("server"), 500,
                                                    HwServerIoBoard::Heartbeat::kBackgroundThread);
    } catch (const IoException& e) {
      out.deviceError = e.what();  // the server is not running: a device error, reported by the object
      return out;
    }
  }
  if (a >= out.board->numDigitalOutputs() || b >= out.board->numDigitalOutputs())
    throw section.errorAt(boardSetting, "the board has only " + std::to_string(out.board->numDigitalOutputs()) +
                                            " digital outputs");
  return out;
}

bool driveTwoLines(IoBoard& board, int lineA, bool valueA, int lineB, bool valueB, std::string& error) {
  // Switch off before switching on, so both lines are never on together.
  const bool offFirstA = !valueA;
  const int first = offFirstA ? lineA : lineB, second = offFirstA ? lineB : lineA;
  const bool firstValue = offFirstA ? valueA : valueB, secondValue = offFirstA ? valueB : valueA;
  // Done only when the device has both (through a hardware server: after the server wrote them
  // and the board accepted them; other boards answer each write at once).
  if (board.writeDigitalOutput(first, firstValue) != IoStatus::kOk ||
      board.writeDigitalOutput(second, secondValue) != IoStatus::kOk ||
      board.confirmWrites(kConfirmTimeoutMs) != IoStatus::kOk) {
    error = board.lastError();
    return false;
  }
  return true;
}

}  // namespace rp::internal
