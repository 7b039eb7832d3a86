// rp-objects: creates every object rp.cfg describes (and one unnamed object of the class of each
// class section, such as [Puma560]), prints name, class and settings, shuts them down and exits 0;
// on a configuration error prints FILE:LINE: message and exits 2.
// rp-objects --settings [CLASS]: prints the settings reference of every registered class (or of
// CLASS) from the classes' own setting schemas, as Markdown (docs/settings.md holds the same).
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "SettingsReference.hpp"
#include "rp/core/Core.hpp"

int main(int argc, char** argv) {
  rp::RoboticPlatform::setGuiOff();
  rp::RoboticPlatform::init(argc, argv,
                            "rp-objects creates every object of the configuration file, lists them and shuts them "
                            "down: the configuration checker.\n"
                            "rp-objects --settings [CLASS] prints the settings every registered class (or CLASS) "
                            "accepts in rp.cfg: type, unit, range, default and meaning.");
  if (argc > 1 && std::string(argv[1]) == "--settings") {
    if (argc > 3) {
      std::cerr << "rp-objects: unexpected argument '" << argv[3] << "' (usage: rp-objects --settings [CLASS])\n";
      return 2;
    }
    const std::string className = argc == 3 ? argv[2] : "";
    if (!rp::apps::printSettingsReference(std::cout, className)) {
      std::cerr << "rp-objects: no class '" << className << "' (known: " << rp::TypeDatabase::instance().knownNames()
                << ")\n";
      return 2;
    }
    return 0;
  }
  if (argc > 1) {
    std::cerr << "rp-objects: unexpected argument '" << argv[1]
              << "' (usage: rp-objects [-config FILE] or rp-objects --settings [CLASS])\n";
    return 2;
  }
  rp::ObjectManager om;
  std::vector<rp::RoboticObject*> objects;
  try {
    objects = om.createAllObjects();
    // A class section configures the objects of its class without a section of their own: one
    // unnamed object of the class checks it.
    for (const auto& section : rp::RoboticPlatform::getConfiguration().sections())
      if (section.isClassSection()) objects.push_back(om.createClassObject(section.className()));
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    om.deleteAllObjects();
    return 2;
  }
  std::size_t nameWidth = 4, classWidth = 5;
  for (auto* o : objects) {
    nameWidth = std::max(nameWidth, o->getName().size());
    classWidth = std::max(classWidth, o->getClassName().size());
  }
  std::printf("%-*s  %-*s  %s\n", static_cast<int>(nameWidth), "name", static_cast<int>(classWidth), "class",
              "settings");
  for (auto* o : objects) {
    std::string settings;
    if (const rp::ConfigSection* s = o->configSection()) {
      if (s->name() != o->getName()) settings = "[" + s->name() + "]";
      for (const auto& setting : s->settings()) {
        if (!settings.empty()) settings += settings.back() == ']' ? " " : "; ";
        settings += setting.name;
        for (const auto& v : setting.values) settings += " " + v;
      }
    }
    if (auto* p = dynamic_cast<rp::PhysicalObject*>(o))
      settings += std::string(settings.empty() ? "" : "; ") + (p->isSimulationModeOn() ? "(simulated)" : "(hardware)");
    std::printf("%-*s  %-*s  %s\n", static_cast<int>(nameWidth), o->getName().c_str(), static_cast<int>(classWidth),
                o->getClassName().c_str(), settings.c_str());
  }
  auto pending = om.shutdownAllObjects("rp-objects finished");
  om.deleteAllObjects();
  for (const auto& name : pending) std::cerr << "rp-objects: " << name << " did not complete its shutdown\n";
  return pending.empty() ? 0 : 1;
}
