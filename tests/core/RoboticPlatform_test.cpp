// RoboticPlatform::init and the Table 3 switches.
#include "rp/core/RoboticPlatform.hpp"

#include <gtest/gtest.h>

#include "TestClasses.hpp"
#include "rp/rt/Clock.hpp"

namespace rp {
namespace {

TEST(RoboticPlatform, SwitchesSetTheirCppEquivalents) {
  auto rest = RoboticPlatform::parseCommandLine(
      {"-sim", "-nogui", "-config", "cell.cfg", "-qmotor", "-log", "out.csv", "input.txt", "--rate", "500", "-5"});
  EXPECT_EQ(rest, (std::vector<std::string>{"input.txt", "--rate", "500", "-5"}));
  EXPECT_TRUE(RoboticPlatform::isSimulationModeOn());
  EXPECT_TRUE(RoboticPlatform::isSimulationModeForced());
  EXPECT_FALSE(RoboticPlatform::isGuiOn());
  EXPECT_TRUE(RoboticPlatform::isQMotorOn());
  EXPECT_EQ(RoboticPlatform::getConfigurationFileName(), "cell.cfg");
  EXPECT_EQ(RoboticPlatform::getLogFileName(), "out.csv");
  RoboticPlatform::parseCommandLine({"-nosim", "-gui"});
  EXPECT_FALSE(RoboticPlatform::isSimulationModeOn());
  EXPECT_FALSE(RoboticPlatform::isSimulationModeForced());
  EXPECT_TRUE(RoboticPlatform::isGuiOn());
  // Everything after -- belongs to the program, even platform switches.
  EXPECT_EQ(RoboticPlatform::parseCommandLine({"--", "-sim", "x"}), (std::vector<std::string>{"--", "-sim", "x"}));
  EXPECT_FALSE(RoboticPlatform::getDefaultClock().isSimulated());
  RoboticPlatform::parseCommandLine({"-simclock"});
  EXPECT_TRUE(RoboticPlatform::getDefaultClock().isSimulated());
  RoboticPlatform::useRealClock();
  RoboticPlatform::setLogFileName("");
}

TEST(RoboticPlatform, SwitchErrors) {
  try {
    RoboticPlatform::parseCommandLine({"-simm"});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "unknown platform switch '-simm' (known: -sim, -nosim, -gui, -nogui, -gui-address, -gui-port, "
                 "-gui-token, -config, -qmotor, -log, -simclock, --help)");
  }
  try {
    RoboticPlatform::parseCommandLine({"-config"});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "switch '-config' needs a value (a file name)");
  }
  EXPECT_THROW(RoboticPlatform::parseCommandLine({"-log"}), std::invalid_argument);
  // A switch with its opposite (the last used to win: -sim -nosim drove the hardware).
  for (const auto& [first, second] : std::vector<std::pair<std::string, std::string>>{
           {"-sim", "-nosim"}, {"-nosim", "-sim"}, {"-gui", "-nogui"}, {"-nogui", "-gui"}}) {
    try {
      RoboticPlatform::parseCommandLine({first, second});
      ADD_FAILURE() << first << " " << second;
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()), "switches '" + first + "' and '" + second + "' contradict each other");
    }
  }
  // A port is digits only (std::stoi took " 80" and "+80").
  for (const char* port : {" 80", "+80", "80 ", "0x50"}) {
    try {
      RoboticPlatform::parseCommandLine({"-gui-port", port});
      ADD_FAILURE() << "'" << port << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("-gui-port"), std::string::npos) << e.what();
    }
  }
}

class InitDeathTest : public ::testing::Test {
 protected:
  void SetUp() override { GTEST_FLAG_SET(death_test_style, "threadsafe"); }
};

// Calls init with `args` (argv[0] = "prog"); returns the arguments init left for the program.
std::vector<std::string> initWith(std::vector<std::string> args, const std::string& usage = "") {
  args.insert(args.begin(), "prog");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  int argc = static_cast<int>(args.size());
  RoboticPlatform::init(argc, argv.data(), usage);
  std::vector<std::string> rest;
  for (int i = 1; i < argc; ++i) rest.emplace_back(argv[static_cast<std::size_t>(i)]);
  if (argv[static_cast<std::size_t>(argc)] != nullptr) rest.emplace_back("argv not terminated");
  return rest;
}

TEST_F(InitDeathTest, BadConfigurationExitsWithStatus2AndTheMessage) {
  auto dir = test::scratchDirectory("init", false);
  const std::string cfg = (dir / "rp.cfg").string();
  test::writeFile(dir / "rp.cfg", "[a]\nclass TestArm\npositon 1 2 3\n");
  EXPECT_EXIT(initWith({"-config", cfg, "-nogui"}), ::testing::ExitedWithCode(2),
              // (the threadsafe death test re-runs this body in a child, in the same folder)
              "rp_core_test_init/rp.cfg:3: setting 'positon' is not known for class TestArm \\(known: ");
}

TEST_F(InitDeathTest, MissingConfigFileGivenExplicitlyExits2) {
  EXPECT_EXIT(initWith({"-config", "/nonexistent/cell.cfg"}), ::testing::ExitedWithCode(2),
              "/nonexistent/cell.cfg: cannot read the file");
}

TEST_F(InitDeathTest, UnknownSwitchExits2AndHelpExits0) {
  EXPECT_EXIT(initWith({"-nosuch"}), ::testing::ExitedWithCode(2), "prog: unknown platform switch '-nosuch'");
  EXPECT_EXIT(initWith({"--help"}, "  --mine   my option"), ::testing::ExitedWithCode(0), "");
}

void initKeepsArguments(const std::filesystem::path& dir) {
  test::writeFile(dir / "rp.cfg", "[arm]\nclass TestArm\n");
  auto rest = initWith({"in.txt", "-config", (dir / "rp.cfg").string(), "-nogui", "--rate", "9"});
  const bool ok = rest == std::vector<std::string>{"in.txt", "--rate", "9"} &&
                  RoboticPlatform::getConfiguration().findSection("arm") != nullptr && RoboticPlatform::isInitialized();
  std::_Exit(ok ? 42 : 1);
}

TEST_F(InitDeathTest, InitKeepsTheProgramsArgumentsAndSaysSimulationOnce) {
  const auto dir = test::scratchDirectory("init2", false);  // made here, so that the parent removes it
  EXPECT_EXIT(initKeepsArguments(dir), ::testing::ExitedWithCode(42),
              "no hardware configured: every object runs in simulation mode");
}

}  // namespace
}  // namespace rp
