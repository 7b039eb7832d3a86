// A class in a shared library loaded at start with `plugin path/to/librp_test_plugin.so` in rp.cfg.
#include "rp/core/PhysicalObject.hpp"
#include "rp/core/TypeDatabase.hpp"

namespace {
class PluginArm : public rp::PhysicalObject {
 public:
  explicit PluginArm(const std::string& name = "") : rp::PhysicalObject(name) {
    addCommand("Wave", [] {}, "waves");
  }
  static void declareSettings(rp::SettingSchema& schema) {
    rp::PhysicalObject::declareSettings(schema);
    schema.addNumbers("reach", 1, "m", "radius");
  }
};
}  // namespace

RP_REGISTER_CLASS(PluginArm);
