// rp-device: creates one object from rp.cfg and runs one of its interactive commands, or prints
// its readings as JSON, then exits.
//
//   rp-device [-config FILE] [-sim|-nosim] NAME COMMAND|read
//
// Examples: rp-device gripper Close      rp-device -config cell.cfg ftsensor read
// As in every program, the object simulates unless -nosim is given or its rp.cfg section says
// simulationMode off (then it uses its hardware); stderr says when it simulates.
// Exit status: 0 done; 1 device error (the object's error status is printed); 2 configuration
// or usage error (bad switch, bad rp.cfg, unknown object, unknown command).
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "rp/core/ObjectManager.hpp"
#include "rp/core/PhysicalObject.hpp"
#include "rp/core/RoboticPlatform.hpp"

namespace {

constexpr const char* kUsage =
    "usage: rp-device [-config FILE] [-sim|-nosim] NAME COMMAND|read\n"
    "  runs the interactive command COMMAND of the rp.cfg object NAME (e.g. rp-device gripper Close),\n"
    "  or prints its readings as JSON (rp-device ftsensor read)\n"
    "  the object simulates unless -nosim is given or its section says simulationMode off\n"
    "  exit status: 0 done, 1 device error, 2 configuration or usage error\n";

std::string commandList(const rp::RoboticObject& object) {
  std::string out;
  for (const auto& c : object.getCommands()) out += (out.empty() ? "" : ", ") + c.name;
  return out.empty() ? "none" : out;
}

// The object's message, naming the object once (objects start their messages with their name).
std::string namedMessage(const rp::RoboticObject& object, const std::string& message) {
  const std::string prefix = object.getName() + ":";
  return message.compare(0, prefix.size(), prefix) == 0 ? message : object.getName() + ": " + message;
}

int deviceError(const rp::RoboticObject& object) {
  std::cerr << "rp-device: " << namedMessage(object, object.getErrorStatus().message) << std::endl;
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> positional;
  int simulate = -1;  // -1: as every program, simulated unless the section says simulationMode off
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-config") {
      if (i + 1 >= argc) {
        std::cerr << "rp-device: -config needs a file name\n" << kUsage;
        return 2;
      }
      rp::RoboticPlatform::setConfigurationFileName(argv[++i]);
    } else if (arg == "-sim") {
      simulate = 1;
    } else if (arg == "-nosim") {
      simulate = 0;
    } else if (arg == "-h" || arg == "-help" || arg == "--help") {
      std::cout << kUsage;
      return 0;
    } else if (!arg.empty() && arg[0] == '-') {
      std::cerr << "rp-device: unknown switch '" << arg << "'\n" << kUsage;
      return 2;
    } else {
      positional.push_back(arg);
    }
  }
  if (positional.size() != 2) {
    std::cerr << "rp-device: expected NAME and COMMAND\n" << kUsage;
    return 2;
  }
  const std::string& name = positional[0];
  const std::string& command = positional[1];
  if (simulate == 1) rp::RoboticPlatform::setSimulationModeOn();  // forces every object
  else if (simulate == 0) rp::RoboticPlatform::setSimulationModeOff();

  rp::ObjectManager om;
  int status = 0;
  try {
    rp::RoboticPlatform::loadConfiguration();
    rp::RoboticObject* object = om.createObject(name);
    if (auto* physical = dynamic_cast<rp::PhysicalObject*>(object); physical && physical->isSimulationModeOn())
      std::cerr << "rp-device: " << name << " is simulated (-nosim or 'simulationMode off' use its hardware)\n";
    if (object->getErrorCode() != 0) {
      status = deviceError(*object);
    } else if (command == "read") {
      std::string reply;
      if (!object->handleMessage("read", "", reply)) {
        std::cerr << "rp-device: " << name << " (" << object->getClassName() << ") has no readings\n";
        status = 2;
      } else if (object->getErrorCode() != 0) {
        std::cout << reply << std::endl;
        status = deviceError(*object);
      } else {
        std::cout << reply << std::endl;
      }
    } else {
      bool known = false;
      for (const auto& c : object->getCommands()) known = known || c.name == command;
      if (!known) {
        std::cerr << "rp-device: " << name << " (" << object->getClassName() << ") has no command '" << command
                  << "' (commands: " << commandList(*object) << "; or read)\n";
        status = 2;
      } else {
        std::string failure;
        try {
          object->executeCommand(command);
        } catch (const std::runtime_error& e) {
          failure = e.what();  // the device did not carry it out
        }
        if (object->getErrorCode() != 0) {
          status = deviceError(*object);
        } else if (!failure.empty()) {
          std::cerr << "rp-device: " << namedMessage(*object, failure) << std::endl;
          status = 1;
        } else {
          std::cout << name << ": " << command << " done" << std::endl;
        }
      }
    }
  } catch (const rp::ConfigError& e) {
    std::cerr << "rp-device: " << e.what() << std::endl;
    status = 2;
  } catch (const rp::ObjectError& e) {
    std::cerr << "rp-device: " << e.what() << std::endl;
    status = 2;
  }
  om.deleteAllObjects();
  return status;
}
