// Unnamed objects configured from rp.cfg: a section named after the class ([Puma560]) configures
// the objects of that class without a section of their own (the paper's `Puma560 puma;` of
// Figures 21 and 23), and a section named after the object wins.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

// A class that names itself for class sections, and one whose constructor creates objects in
// turn (they must not take its ClassSection).
class Widget : public PhysicalObject {
 public:
  explicit Widget(const std::string& name = "") : PhysicalObject(ClassSection(name, "Widget")) {}
};
class Holder : public PhysicalObject {
 public:
  explicit Holder(const std::string& name = "") : PhysicalObject(ClassSection(name, "Holder")) {}
  // Made by the Holder's base constructor's caller while the Holder's ClassSection is alive.
  std::unique_ptr<PhysicalObject> plain = std::make_unique<PhysicalObject>();
  std::unique_ptr<Widget> widget = std::make_unique<Widget>();
};
// A class that does not name itself: configured from its class section only when created by name.
class Quiet : public PhysicalObject {
 public:
  explicit Quiet(const std::string& name = "") : PhysicalObject(name) {}
};
// A Puma of the program's own, which names itself: its own class section wins over [Puma560].
// It starts the servo loop itself, once it is complete.
class MyPuma : public Puma560 {
 public:
  explicit MyPuma(const std::string& name = "") : Puma560(ClassSection(name, "MyPuma"), DerivedClass{}) {
    startControlLoop();
  }
  ~MyPuma() override { stopControlLoop(); }
};

}  // namespace
}  // namespace rp

RP_REGISTER_CLASS_AS(rp::Widget, "Widget");
RP_REGISTER_CLASS_AS(rp::Holder, "Holder");
RP_REGISTER_CLASS_AS(rp::Quiet, "Quiet");
RP_REGISTER_CLASS_AS(rp::MyPuma, "MyPuma");

namespace rp {
namespace {

double xOf(const PhysicalObject& o) { return getPosition(o.getTransform())(0); }

class ClassSectionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RoboticPlatform::setSimulationModeOn();
    ObjectManager::resetShutdown();
  }
  void TearDown() override {
    ObjectManager().deleteAllObjects();
    RoboticPlatform::setConfiguration(Configuration());
  }
  static void configure(const std::string& text) {
    RoboticPlatform::setConfiguration(Configuration::parse(text, "cell.cfg"));
  }
};

TEST_F(ClassSectionTest, PumaSectionConfiguresAnUnnamedPumaAndANamedSectionWins) {
  configure(
      "[Puma560]\nclass Puma560\nposition 300 0 0\npedestalHeight 0.5\n\n"
      "[leader]\nclass Puma560\nposition 100 0 0\n");
  Puma560 puma;  // the paper's Figure 21
  EXPECT_TRUE(puma.hasAutomaticName());
  ASSERT_NE(puma.configSection(), nullptr);
  EXPECT_EQ(puma.configSection()->name(), "Puma560");
  EXPECT_NEAR(xOf(puma), 0.3, 1e-12) << "position 300 mm of [Puma560]";
  EXPECT_NEAR(getPosition(puma.getModel().getBaseTransform())(0), 0.3, 1e-12) << "the model stands there";
  // pedestalHeight of [Puma560] reached the model (d1, read by Puma560's own constructor level).
  EXPECT_NEAR(puma.getModel().getLink(0).d, 0.5, 1e-12);

  Puma560 leader("leader");  // named: its own section, not merged with the class's
  ASSERT_NE(leader.configSection(), nullptr);
  EXPECT_EQ(leader.configSection()->name(), "leader");
  EXPECT_NEAR(xOf(leader), 0.1, 1e-12);
  EXPECT_NEAR(leader.getModel().getLink(0).d, 0.67183, 1e-12)
      << "the default pedestal height: [Puma560]'s is not merged into [leader]";

  Puma560 other("other");  // named, without a section: the class's
  ASSERT_NE(other.configSection(), nullptr);
  EXPECT_EQ(other.configSection()->name(), "Puma560");
  EXPECT_NEAR(xOf(other), 0.3, 1e-12);
}

TEST_F(ClassSectionTest, FigureTwentyThreeBothUnnamedPumasTakeTheClassSection) {
  configure("[Puma560]\nclass Puma560\norientation 0 0 90\n");
  Puma560 puma;
  Puma560 pumaSimulated;
  pumaSimulated.setSimulationModeOn();
  for (const Puma560* p : {&puma, &pumaSimulated}) {
    const Transform t = p->getTransform();
    EXPECT_NEAR(t(1, 0), 1.0, 1e-12) << p->getName() << ": yaw 90 degrees";
  }
}

TEST_F(ClassSectionTest, WithoutAClassSectionAnUnnamedObjectIsNotConfigured) {
  configure("[leader]\nclass Puma560\nposition 100 0 0\n");
  Puma560 puma;
  EXPECT_EQ(puma.configSection(), nullptr);
  EXPECT_NEAR(xOf(puma), 0.0, 1e-12);
}

TEST_F(ClassSectionTest, TheMostDerivedClassNamesTheSection) {
  configure("[Puma560]\nclass Puma560\nposition 300 0 0\n\n[MyPuma]\nclass MyPuma\nposition 200 0 0\n");
  MyPuma mine;
  ASSERT_NE(mine.configSection(), nullptr);
  EXPECT_EQ(mine.configSection()->name(), "MyPuma");
  EXPECT_EQ(mine.getConfiguredClass(), "MyPuma");
  EXPECT_NEAR(xOf(mine), 0.2, 1e-12);
  Puma560 puma;
  EXPECT_NEAR(xOf(puma), 0.3, 1e-12);
}

TEST_F(ClassSectionTest, ObjectsMadeByAConstructorDoNotTakeItsClass) {
  configure("[Holder]\nclass Holder\nposition 100 0 0\n\n[Widget]\nclass Widget\nposition 0 50 0\n");
  Holder holder;
  EXPECT_NEAR(xOf(holder), 0.1, 1e-12);
  EXPECT_EQ(holder.plain->configSection(), nullptr) << "a plain object made while [Holder] applied";
  ASSERT_NE(holder.widget->configSection(), nullptr);
  EXPECT_EQ(holder.widget->configSection()->name(), "Widget");
  Widget widget;  // after the Holder: nothing left over in this thread
  EXPECT_EQ(widget.configSection()->name(), "Widget");
  PhysicalObject plain;
  EXPECT_EQ(plain.configSection(), nullptr);
}

TEST_F(ClassSectionTest, CreatedByNameAClassNeedsNoClassSectionOfItsOwn) {
  configure("[Quiet]\nclass Quiet\nposition 400 0 0\n");
  Quiet direct;  // declared: its constructor names no class
  EXPECT_EQ(direct.configSection(), nullptr);
  ObjectManager om;
  auto* created = dynamic_cast<Quiet*>(om.createClassObject("Quiet"));
  ASSERT_NE(created, nullptr);
  EXPECT_TRUE(created->hasAutomaticName());
  EXPECT_NEAR(xOf(*created), 0.4, 1e-12);
  EXPECT_THROW(om.createClassObject("Nonesuch"), ObjectError);
}

TEST_F(ClassSectionTest, CreateAllObjectsCreatesNoObjectForAClassSection) {
  configure("[Widget]\nclass Widget\n\n[w1]\nclass Widget\n");
  ObjectManager om;
  const auto objects = om.createAllObjects();
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_EQ(objects[0]->getName(), "w1");
}

TEST_F(ClassSectionTest, AClassSectionOfAnotherClassIsRefused) {
  try {
    configure("[arm]\nclass WAM\n\n[Puma560]\nclass WAM\n");
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              "cell.cfg:5: section [Puma560] is named after a class: it configures the Puma560 objects without a "
              "section of their own, so its class must be Puma560, not WAM");
  }
}

}  // namespace
}  // namespace rp
