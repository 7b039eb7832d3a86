// The Puma 560 robot object (rp/manipulator/Puma560.hpp).
#include "rp/manipulator/Puma560.hpp"

#include "rp/core/RoboticPlatform.hpp"
#include "rp/core/TypeDatabase.hpp"

namespace rp {

namespace {
double pedestalHeight(const ConfigSection* section) {
  if (section != nullptr && section->has("pedestalHeight")) return section->getNumbers("pedestalHeight").at(0);
  return 0.67183;
}
}  // namespace

Puma560::Puma560(const std::string& name) : Puma560(ClassSection(name, "Puma560"), DerivedClass{}) {
  startControlLoop();
}

Puma560::Puma560(const std::string& name, DerivedClass)
    : DefaultManipulator(name, [this](const Transform& base) {
        return std::make_unique<Puma560Model>(pedestalHeight(configSection()), base);
      }) {}

Puma560::~Puma560() { stopControlLoop(); }

void Puma560::declareSettings(SettingSchema& schema) {
  DefaultManipulator::declareSettings(schema);
  schema.addNumbers("pedestalHeight", 1, "m", "height of the shoulder above the mounting surface");
  schema.setDefault("pedestalHeight", "0.67183");
}

}  // namespace rp

RP_REGISTER_CLASS_AS(rp::Puma560, "Puma560");
