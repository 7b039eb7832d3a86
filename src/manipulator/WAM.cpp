// The Barrett WAM robot object (rp/manipulator/WAM.hpp).
#include "rp/manipulator/WAM.hpp"

#include <stdexcept>

#include "rp/core/RoboticPlatform.hpp"
#include "rp/core/TypeDatabase.hpp"

namespace rp {

namespace {
int linkCount(const ConfigSection* section, const std::string& name, int links) {
  if (section != nullptr && section->has("links")) links = std::stoi(section->getWord("links"));
  if (links != 4 && links != 7) {
    throw std::invalid_argument("WAM '" + name + "': " + std::to_string(links) + " links; a WAM has 4 or 7");
  }
  return links;
}
}  // namespace

WAM::WAM(const std::string& name, int links) : WAM(ClassSection(name, "WAM"), links, DerivedClass{}) {
  startControlLoop();
}

WAM::WAM(const std::string& name, int links, DerivedClass)
    : DefaultManipulator(name, [this, links](const Transform& base) -> std::unique_ptr<ManipulatorModel> {
        if (linkCount(configSection(), getName(), links) == 4) return std::make_unique<WAM4Model>(base);
        return std::make_unique<WAM7Model>(base);
      }) {}

WAM::~WAM() { stopControlLoop(); }

void WAM::declareSettings(SettingSchema& schema) {
  DefaultManipulator::declareSettings(schema);
  schema.addChoice("links", {"4", "7"}, "number of links: the 4-DOF arm or the 7-DOF arm with wrist");
  schema.setDefault("links", "7 (the constructor's argument)");
}

}  // namespace rp

RP_REGISTER_CLASS_AS(rp::WAM, "WAM");
