// libFuzzer target for the rp.cfg parser: any input either parses or throws ConfigError with a
// FILE:LINE message; nothing else may happen (no crash, no other exception, no sanitizer report).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <typeindex>

#include "rp/core/Configuration.hpp"
#include "rp/core/TypeDatabase.hpp"

namespace {

// Classes with the settings of Table 1 and Figure 9, registered without objects behind them.
bool registerClasses() {
  rp::SettingSchema physical;
  physical.addNumbers("position", 3, "mm", "x y z");
  physical.addNumbers("orientation", 3, "deg", "roll pitch yaw");
  physical.addChoice("simulationMode", {"on", "off"}, "simulate");
  physical.addChoice("display", {"off", "solid", "wireframe"}, "display");
  rp::SettingSchema hand = physical;
  hand.addWord("port", "serial device");
  hand.addInteger("baud", "bits per second");
  auto add = [](const char* name, const rp::SettingSchema& schema) {
    rp::TypeDatabase::instance().add(rp::TypeInfo{name, nullptr, [] { throw static_cast<int*>(nullptr); }, schema,
                                                  std::type_index(typeid(int))});
  };
  add("Puma560", physical);
  add("WAM", physical);
  add("BarrettHand", hand);
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool registered = registerClasses();
  (void)registered;
  rp::Configuration::Options options;
  options.loadPlugins = false;      // never dlopen fuzzed paths
  options.readQMotorFiles = false;  // never open fuzzed paths
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    rp::Configuration cfg = rp::Configuration::parse(text, "fuzz.cfg", options);
    for (const auto& section : cfg.sections())
      if (section.className().empty() || section.line() <= 0) std::abort();
  } catch (const rp::ConfigError& e) {
    // The message always names the file (and the line when there is one).
    if (std::string(e.what()).rfind("fuzz.cfg:", 0) != 0) std::abort();
    if (e.line() < 0) std::abort();
    // Words from the input are quoted as short excerpts only.
    if (e.message().size() > 600) std::abort();
  }
  return 0;
}
