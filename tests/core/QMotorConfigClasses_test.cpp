// qmotorConfig works for every class that runs a control program, not only manipulators: a user's
// gripper and a user's sensor that derive from ControlProgram, created by name from rp.cfg or
// constructed by the program, get their file applied before the loop starts; an unknown key in
// it is an error naming FILE:LINE; a class that runs no control program (DefaultGripper) with a
// qmotorConfig is an error at the rp.cfg line instead of a file silently ignored.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

// A gripper with a force loop: a control program with a tunable force limit.
class ForceGripper : public Gripper, public ControlProgram {
 public:
  explicit ForceGripper(const std::string& name = "") : Gripper(ClassSection(name, "QmForceGripper")) {
    registerParameter("maxForce", maxForce, 0, 200, "N", "largest grasp force");
    registerLogVariable("force", force, "N");
    setLogWriter(nullptr);
  }
  ~ForceGripper() override { stopControlLoop(); }
  ControlProgram* getControlProgram() override { return this; }
  double maxForce = 20, force = 0;

 protected:
  void control() override { force = maxForce / 2; }
  bool hardwareOpen() override { return true; }
  bool hardwareClose() override { return true; }
  bool hardwareRelax() override { return true; }
};

// A sensor whose filter runs in a control program (a plain PhysicalObject, the program's class).
class FilteredSensor : public PhysicalObject, public ControlProgram {
 public:
  explicit FilteredSensor(const std::string& name = "") : PhysicalObject(ClassSection(name, "QmFilteredSensor")) {
    registerParameter("cutoff", cutoff, 0.1, 1000, "Hz");
    setLogWriter(nullptr);
    startControlLoop();  // constructed by the program: the most-derived constructor starts it
  }
  ~FilteredSensor() override { stopControlLoop(); }
  ControlProgram* getControlProgram() override { return this; }
  double cutoff = 10;

 protected:
  void control() override {}
};

}  // namespace
}  // namespace rp

RP_REGISTER_CLASS_AS(rp::ForceGripper, "QmForceGripper");
RP_REGISTER_CLASS_AS(rp::FilteredSensor, "QmFilteredSensor");

namespace rp {
namespace {

class QMotorConfigClasses : public ::testing::Test {
 protected:
  void SetUp() override {
    RoboticPlatform::setSimulationModeOn();
    dir_ = std::filesystem::temp_directory_path() / ("rp_qmotor_classes_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    ObjectManager().deleteAllObjects();
    RoboticPlatform::setConfiguration(Configuration());
    std::filesystem::remove_all(dir_);
  }
  // Writes rp.cfg and the control-program file hand.cfg, and reads rp.cfg.
  void configure(const std::string& rpcfg, const std::string& hand) {
    std::ofstream(dir_ / "hand.cfg") << hand;
    std::ofstream(dir_ / "rp.cfg") << rpcfg;
    RoboticPlatform::setConfiguration(Configuration::read((dir_ / "rp.cfg").string()));
  }
  std::string path(const std::string& f) const { return (dir_ / f).string(); }
  // The ConfigError message of `create`, or "no error".
  template <typename F>
  static std::string configError(F create) {
    try {
      create();
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "no error";
  }
  std::filesystem::path dir_;
};

TEST_F(QMotorConfigClasses, AGripperCreatedByNameGetsItsFileBeforeTheLoopStarts) {
  configure("[hand]\nclass QmForceGripper\nqmotorConfig hand.cfg\n", "rate 250\nmaxForce 55\n");
  ObjectManager om;
  auto* hand = dynamic_cast<ForceGripper*>(om.createDerivedObject<Gripper>("hand"));
  ASSERT_NE(hand, nullptr);
  EXPECT_EQ(hand->maxForce, 55.0);
  EXPECT_EQ(hand->getRate(), 250.0);
  EXPECT_TRUE(hand->isRunning());
  EXPECT_EQ(hand->getProgramName(), "hand");
  EXPECT_EQ(hand->getQMotorConfigFile(), path("hand.cfg"));
  EXPECT_EQ(hand->getQMotorConfigFolder(), dir_.string());
}

TEST_F(QMotorConfigClasses, AnUnknownKeyInAGrippersFileIsAnErrorWithFileAndLine) {
  configure("[hand]\nclass QmForceGripper\nqmotorConfig hand.cfg\n", "maxForce 55\nmaxForse 60\n");
  ObjectManager om;
  EXPECT_EQ(configError([&] { om.createDerivedObject<Gripper>("hand"); }),
            path("hand.cfg") + ":2: 'maxForse' is not a parameter of hand (known: rate, priority, logEvery, "
                               "logBufferSize, log, maxForce)");
  EXPECT_EQ(om.findObject("hand"), nullptr) << "the object was not kept";
}

TEST_F(QMotorConfigClasses, ASensorConstructedByTheProgramGetsItsFile) {
  configure("[filter]\nclass QmFilteredSensor\nqmotorConfig hand.cfg\n", "cutoff 42.5\n");
  FilteredSensor sensor("filter");
  EXPECT_EQ(sensor.cutoff, 42.5);
  EXPECT_TRUE(sensor.isRunning());
  configure("[filter2]\nclass QmFilteredSensor\nqmotorConfig hand.cfg\n", "cutoff 5000\n");
  EXPECT_EQ(configError([] { FilteredSensor bad("filter2"); }),
            path("hand.cfg") + ":1: ControlProgram filter2: parameter 'cutoff' = 5000 is outside [0.1, "
                               "1000] Hz");
}

TEST_F(QMotorConfigClasses, AClassThatRunsNoControlProgramRefusesTheFileAtTheRpCfgLine) {
  configure("[gripper]\nclass DefaultGripper\nposition 0 0 0\nqmotorConfig hand.cfg\n", "maxForce 55\n");
  ObjectManager om;
  EXPECT_EQ(configError([&] { om.createDerivedObject<Gripper>("gripper"); }),
            path("rp.cfg") + ":4: setting 'qmotorConfig': gripper (DefaultGripper) runs no control program, so nothing "
                             "would apply '" + path("hand.cfg") +
                "' (only a class that runs one, e.g. derived from ControlProgram, takes the file)");
}

// rp.cfg's executor settings reach the object's control program before its loop starts: `thread
// own` gives it a thread of its own, `cpu N` pins it; an object without a control program refuses
// them at their line.
TEST_F(QMotorConfigClasses, ThreadAndCpuSettingsReachTheControlProgram) {
  configure("[filter]\nclass QmFilteredSensor\nthread own\ncpu 0\n", "");
  {
    FilteredSensor sensor("filter");
    EXPECT_TRUE(sensor.isRunning());
    EXPECT_EQ(sensor.getThreadMode(), ThreadMode::Own);
    EXPECT_EQ(sensor.getCpuAffinity(), 0);
    EXPECT_TRUE(sensor.getStatistics().ownThread);
  }
  configure("[filter]\nclass QmFilteredSensor\nthread shared\n", "");
  {
    FilteredSensor sensor("filter");
    EXPECT_EQ(sensor.getThreadMode(), ThreadMode::Shared);
    EXPECT_EQ(sensor.getCpuAffinity(), -1);
  }
  configure("[gripper]\nclass DefaultGripper\nthread own\n", "");
  ObjectManager om;
  EXPECT_EQ(configError([&] { om.createDerivedObject<Gripper>("gripper"); }),
            path("rp.cfg") + ":3: setting 'thread': gripper (DefaultGripper) runs no control program, so it has no "
                             "thread to choose or pin");
}

}  // namespace
}  // namespace rp
