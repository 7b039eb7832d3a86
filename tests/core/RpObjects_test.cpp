// rp-objects and plugins: a class from a shared library named by `plugin` in rp.cfg.
#include <sys/wait.h>

#include <gtest/gtest.h>

#include <cstdio>

#include "TestClasses.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/core/RoboticPlatform.hpp"

namespace rp {
namespace {

struct Result {
  int status;
  std::string output;
};

Result run(const std::string& command) {
  Result r{-1, {}};
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) r.output += buf;
  const int s = pclose(p);
  r.status = WIFEXITED(s) ? WEXITSTATUS(s) : -1;
  return r;
}

std::string cellConfig() {
  return std::string("plugin ") + RP_TEST_PLUGIN +
         "\n\n[arm1]\nclass PluginArm\nposition 300 0 0\nreach 0.8\n\n[arm2]\nclass PluginArm\nsimulationMode off\n";
}

TEST(RpObjects, ListsEveryConfiguredObjectAndExits0) {
  auto dir = test::scratchDirectory("rpobjects");
  test::writeFile(dir / "rp.cfg", cellConfig());
  Result r = run(std::string(RP_OBJECTS) + " -config " + (dir / "rp.cfg").string());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("name  class      settings\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("arm1  PluginArm  position 300 0 0; reach 0.8; (simulated)\n"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("arm2  PluginArm  simulationMode off; (hardware)\n"), std::string::npos) << r.output;
}

TEST(RpObjects, ConfigurationErrorExits2WithFileAndLine) {
  auto dir = test::scratchDirectory("rpobjects_bad");
  test::writeFile(dir / "rp.cfg", cellConfig() + "reach far\n");
  const std::string cfg = (dir / "rp.cfg").string();
  Result r = run(std::string(RP_OBJECTS) + " -config " + cfg);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find(cfg + ":11: setting 'reach': 'far' is not a number"), std::string::npos)
      << r.output;
  Result extra = run(std::string(RP_OBJECTS) + " -config " + (dir / "none.cfg").string());
  EXPECT_EQ(extra.status, 2);
  EXPECT_NE(extra.output.find("none.cfg: cannot read the file: No such file or directory"), std::string::npos);
}

TEST(RpObjects, SettingsPrintsEachClassSchemaWithPluginClasses) {
  auto dir = test::scratchDirectory("rpobjects_settings");
  test::writeFile(dir / "rp.cfg", cellConfig());
  const std::string cfg = (dir / "rp.cfg").string();
  Result one = run(std::string(RP_OBJECTS) + " -config " + cfg + " --settings BarrettHand");
  EXPECT_EQ(one.status, 0) << one.output;
  EXPECT_NE(one.output.find("### BarrettHand\n"), std::string::npos) << one.output;
  EXPECT_NE(one.output.find("| `baud` | integer |  | 1 .. 115200 | 9600 | baud rate: 9600, 19200, 38400, 57600 or 115200 |\n"),
            std::string::npos) << one.output;
  EXPECT_NE(one.output.find("| `display` | choice |  | `off`, `solid`, `wireframe` | solid |"), std::string::npos)
      << one.output;
  EXPECT_EQ(one.output.find("### Puma560"), std::string::npos) << "only the class asked for";
  Result all = run(std::string(RP_OBJECTS) + " -config " + cfg + " --settings");
  EXPECT_EQ(all.status, 0) << all.output;
  EXPECT_NE(all.output.find("### PluginArm\n"), std::string::npos) << "the plugin's class: " << all.output;
  EXPECT_NE(all.output.find("| `reach` |"), std::string::npos) << all.output;
  EXPECT_NE(all.output.find("### DefaultTrajectoryGenerator\n\nNo settings besides `class` and `qmotorConfig`."),
            std::string::npos) << all.output;
  Result unknown = run(std::string(RP_OBJECTS) + " --settings Nope");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.output.find("rp-objects: no class 'Nope' (known: "), std::string::npos) << unknown.output;
}

TEST(Plugin, ClassesFromAPluginAreCreatedByName) {
  auto dir = test::scratchDirectory("plugin");
  test::writeFile(dir / "rp.cfg", cellConfig());
  RoboticPlatform::setConfigurationFileName((dir / "rp.cfg").string());
  RoboticPlatform::loadConfiguration();
  ObjectManager om;
  PhysicalObject* arm = om.createDerivedObject<PhysicalObject>("arm1");
  ASSERT_NE(arm, nullptr);
  EXPECT_EQ(arm->getClassName(), "PluginArm");
  EXPECT_TRUE(arm->getTransform().isApprox(translation(0.3, 0, 0)));
  ASSERT_EQ(arm->getCommands().size(), 1u);
  arm->executeCommand("Wave");
  om.deleteAllObjects();
  RoboticPlatform::setConfiguration(Configuration());
}

}  // namespace
}  // namespace rp
