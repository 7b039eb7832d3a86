#include "rp/effector/BarrettHand.hpp"

#include <sstream>

#include "Json.hpp"
#include "rp/core/TypeDatabase.hpp"
#include "rp/io/IoException.hpp"

namespace rp {

BarrettHand::BarrettHand(const std::string& name) : Gripper(ClassSection(name, "BarrettHand")) {
  if (const ConfigSection* section = configSection()) {
    if (!section->has("port"))
      throw ConfigError(section->fileName(), section->line(),
                        "[" + section->name() + "] has no 'port' setting (the hand's serial port, e.g. /dev/ttyS0)");
    config_.port = section->getWord("port");
    auto integer = [&](const char* setting, int& target, int lo, int hi) {
      if (const ConfigSetting* s = section->find(setting)) {
        const double v = section->getNumbers(setting).at(0);
        if (v < lo || v > hi)
          throw section->errorAt(*s, std::string("setting '") + setting + "' must be " + std::to_string(lo) + " .. " +
                                         std::to_string(hi));
        target = static_cast<int>(v);
      }
    };
    integer("baud", config_.baud, 1, 115200);
    integer("timeout", config_.timeoutMs, 1, 600000);
    integer("motionTimeout", config_.motionTimeoutMs, 1, 600000);
    try {
      driver_ = std::make_unique<BarrettHandSerial>(config_);
    } catch (const IoException& e) {
      const ConfigSetting* at = section->find("baud");
      throw at ? section->errorAt(*at, e.what()) : ConfigError(section->fileName(), section->line(), e.what());
    }
  } else {
    driver_ = std::make_unique<BarrettHandSerial>(config_);
  }
  addCommandWithResult("Initialize", [this] { return commandResult(initialize(), "initialised"); },
                       "initialise the hand (HI)");
  publishObject();  // complete: other threads (the Scene Viewer) may use it
}

BarrettHand::~BarrettHand() { withdrawObject(); }  // first: other threads keep off from here on

void BarrettHand::declareSettings(SettingSchema& schema) {
  Gripper::declareSettings(schema);
  schema.addWord("port", "serial port of the hand, e.g. /dev/ttyS0");
  schema.addInteger("baud", "baud rate: 9600, 19200, 38400, 57600 or 115200", 1, 115200);
  schema.addInteger("timeout", "how long to wait for the prompt [ms]", 1, 600000);
  schema.addInteger("motionTimeout", "the same for HI, GO and GC [ms]", 1, 600000);
  schema.setDefault("port", "(required)");
  schema.setDefault("baud", "9600");
  schema.setDefault("timeout", "1000");
  schema.setDefault("motionTimeout", "10000");
}

bool BarrettHand::check(IoStatus status) {
  if (status == IoStatus::kOk) return true;
  setError(1, (getName() + ": " + driver_->lastError()).c_str());
  if (status == IoStatus::kNotConnected || status == IoStatus::kTimeout || status == IoStatus::kProtocolError)
    initialized_ = false;  // reopen and initialise again next time
  return false;
}

// The port is open (opened now if needed); the hand is not initialised by this.
bool BarrettHand::opened() {
  if (config_.port.empty()) {
    setError(1, (getName() + ": no serial port configured (rp.cfg setting 'port')").c_str());
    return false;
  }
  return driver_->isOpen() || check(driver_->open());
}

// Ready for a motion command: open and initialised (HI once).
bool BarrettHand::ready() {
  if (initialized_ && driver_->isOpen()) return true;
  if (!opened()) return false;
  if (!check(driver_->initialize())) return false;
  initialized_ = true;
  return true;
}

bool BarrettHand::initialize() {
  if (isSimulationModeOn()) return true;
  initialized_ = false;
  if (!ready()) return false;
  clearError();
  return true;
}

bool BarrettHand::hardwareOpen() { return ready() && check(driver_->openGrasp()); }
bool BarrettHand::hardwareClose() { return ready() && check(driver_->closeGrasp()); }
bool BarrettHand::hardwareRelax() { return ready() && check(driver_->relax()); }

bool BarrettHand::readPositions(std::array<int, 4>& counts) {
  if (isSimulationModeOn()) return false;
  return opened() && check(driver_->readPositions(counts));  // a reading never moves the fingers (no HI)
}

bool BarrettHand::handleMessage(const std::string& type, const std::string& payload, std::string& reply) {
  if (type != "read" || isSimulationModeOn()) return Gripper::handleMessage(type, payload, reply);
  std::array<int, 4> p{};
  if (!readPositions(p)) {
    reply = "{\"state\": \"";
    reply.append(stateName(getState()));
    reply.append("\", \"error\": ");
    reply.append(internal::jsonString(getErrorStatus().message));
    reply.push_back('}');
    return true;
  }
  std::ostringstream out;
  out << "{\"state\": \"" << stateName(getState()) << "\", \"positions\": [" << p[0] << ", " << p[1] << ", " << p[2]
      << ", " << p[3] << "]}";
  reply = out.str();
  return true;
}

}  // namespace rp

RP_REGISTER_CLASS_AS(rp::BarrettHand, "BarrettHand");
