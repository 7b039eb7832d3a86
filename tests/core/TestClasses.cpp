#include "TestClasses.hpp"

#include "rp/core/TypeDatabase.hpp"

namespace {
// Figure 9 names: use the library's classes once they exist, stand-ins until then.
struct StandIn : rp::PhysicalObject {
  explicit StandIn(const std::string& name = "") : rp::PhysicalObject(name) {}
  static void declareSettings(rp::SettingSchema& schema) {
    rp::PhysicalObject::declareSettings(schema);
    schema.addWord("port", "serial device");
  }
};
struct Puma560StandIn : StandIn { using StandIn::StandIn; };
struct WAMStandIn : StandIn { using StandIn::StandIn; };
struct BarrettHandStandIn : StandIn { using StandIn::StandIn; };

bool registerStandIns() {
  auto& db = rp::TypeDatabase::instance();
  if (!db.contains("Puma560")) rp::TypeDatabase::registerClass<Puma560StandIn>("Puma560");
  if (!db.contains("WAM")) rp::TypeDatabase::registerClass<WAMStandIn>("WAM");
  if (!db.contains("BarrettHand")) rp::TypeDatabase::registerClass<BarrettHandStandIn>("BarrettHand");
  return true;
}
}  // namespace

RP_REGISTER_CLASS_AS(rp::test::TestArm, "TestArm");
RP_REGISTER_CLASS_AS(rp::test::TestFunction, "TestFunction");
RP_REGISTER_CLASS_AS(rp::test::SlowShutdown, "SlowShutdown");

namespace rp::test {
// Called by each test's SetUp, after every static registration of the library has run.
bool standInsRegistered = registerStandIns();
}  // namespace rp::test
