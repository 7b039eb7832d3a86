// The start of a utility program that works on one manipulator (rp-jointmove, rp-teachpendant):
// the program's argument NAME (an rp.cfg section), else the first manipulator rp.cfg describes,
// else a simulated Puma 560 called `puma`; the Scene Viewer opens on the program's page.
#pragma once

#include <chrono>
#include <iostream>
#include <memory>
#include <thread>
#include <string>
#include <vector>

#include "rp/core/Core.hpp"
#include "rp/gui/SceneViewer.hpp"
#include "rp/manipulator/Manipulators.hpp"

namespace rp::apps {

// The program's first own argument, read before init() so that the printed URL can name it.
inline std::string firstProgramArgument(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  try {
    auto rest = RoboticPlatform::parseCommandLine(args);
    if (!rest.empty()) return rest.front();
  } catch (const std::exception&) {
    // init() reports it
  }
  return {};
}

// Creates the manipulator (owned by the ObjectManager, or by `own` for the default Puma).
// Throws ObjectError/ConfigError as ObjectManager::createDerivedObject.
inline Manipulator* chooseManipulator(const std::string& name, std::unique_ptr<Manipulator>& own) {
  ObjectManager om;
  if (!name.empty()) return om.createDerivedObject<Manipulator>(name);
  for (const auto& section : RoboticPlatform::getConfiguration().sections()) {
    const TypeInfo* info = ObjectManager::getTypeDatabase().find(section.className());
    bool isManipulator = false;
    if (info) {
      try {
        info->throwNullPointer();
      } catch (Manipulator*) {
        isManipulator = true;
      } catch (...) {
      }
    }
    if (isManipulator) return om.createDerivedObject<Manipulator>(section.name());
  }
  own = std::make_unique<Puma560>("puma");
  return own.get();
}

// init() with the program's page as the viewer's start page, then the manipulator. Returns nullptr
// (after printing why) on a wrong argument or a manipulator that cannot be created: exit with 2.
inline Manipulator* startUtility(const std::string& program, const std::string& page, int& argc, char** argv,
                                 const std::string& usage, std::unique_ptr<Manipulator>& own) {
  const std::string name = firstProgramArgument(argc, argv);
  SceneViewer::setStartPage(page + (name.empty() ? std::string() : "?object=" + name));
  RoboticPlatform::init(argc, argv, usage);
  if (argc > 2) {
    std::cerr << program << ": unexpected argument '" << argv[2] << "' (usage: " << program << " [-config FILE] [NAME])\n";
    return nullptr;
  }
  if (argc == 2 && argv[1][0] == '-') {  // a --long option the platform left: not a section name
    std::cerr << program << ": unknown option '" << argv[1] << "' (usage: " << program << " [-config FILE] [NAME])\n";
    return nullptr;
  }
  try {
    return chooseManipulator(name, own);
  } catch (const std::exception& e) {
    std::cerr << program << ": " << e.what() << "\n";
    return nullptr;
  }
}

// Prints what the program works on and the URL to open, then waits for Ctrl-C or SIGTERM.
inline void runUntilShutdown(const std::string& program, const std::string& doing, Manipulator& arm) {
  std::cout << program << ": " << doing << " " << arm.getName() << " (" << arm.getClassName() << ", "
            << arm.getNumberOfJoints() << " joints)";
  if (SceneViewer::instance().isRunning()) std::cout << ": open " << SceneViewer::instance().getUrl();
  std::cout << "; Ctrl-C ends it" << std::endl;
  while (!ObjectManager::isShutdownRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ObjectManager::waitForShutdown(10);
}

}  // namespace rp::apps
