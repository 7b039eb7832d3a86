// rp.cfg parsing: the paper's Figure 9 verbatim, and malformed files, each with its exact message.
#include "rp/core/Configuration.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include "TestClasses.hpp"
#include "rp/core/TypeDatabase.hpp"

namespace rp {
namespace {

// Figure 9 of the paper, character for character.
const char* kFigure9 =
    "[leader]\n"
    "class Puma560\n"
    "qmotorConfig leader.cfg\n"
    "\n"
    "[secondrobot]\n"
    "class WAM\n"
    "position 300 0 0\n"
    "simulationMode on\n"
    "display solid\n"
    "\n"
    "[gripper]\n"
    "class BarrettHand\n"
    "port /dev/ser1\n";

TEST(Configuration, Figure9Verbatim) {
  auto dir = test::scratchDirectory("fig9");
  test::writeFile(dir / "rp.cfg", kFigure9);
  test::writeFile(dir / "leader.cfg", "# gains of the leader\nkp 100 100 100 50 50 50\nlogEvery 2\n");
  Configuration cfg = Configuration::read((dir / "rp.cfg").string());
  ASSERT_EQ(cfg.sections().size(), 3u);
  const ConfigSection* leader = cfg.findSection("leader");
  ASSERT_NE(leader, nullptr);
  EXPECT_EQ(leader->className(), "Puma560");
  EXPECT_EQ(leader->line(), 1);
  EXPECT_EQ(leader->classLine(), 2);
  ASSERT_NE(leader->qmotorConfig(), nullptr);
  ASSERT_EQ(leader->qmotorConfig()->entries().size(), 2u);
  EXPECT_EQ(leader->qmotorConfig()->entries()[0].name, "kp");
  EXPECT_EQ(leader->qmotorConfig()->entries()[0].values.size(), 6u);
  EXPECT_EQ(leader->qmotorConfig()->entries()[1].line, 3);
  const ConfigSection* second = cfg.findSection("secondrobot");
  ASSERT_NE(second, nullptr);
  EXPECT_EQ(second->className(), "WAM");
  EXPECT_EQ(second->getNumbers("position"), (std::vector<double>{300, 0, 0}));
  EXPECT_EQ(second->getWord("simulationMode"), "on");
  EXPECT_EQ(second->getWord("display"), "solid");
  EXPECT_EQ(second->find("display")->line, 9);
  const ConfigSection* gripper = cfg.findSection("gripper");
  ASSERT_NE(gripper, nullptr);
  EXPECT_EQ(gripper->className(), "BarrettHand");
  EXPECT_EQ(gripper->getWord("port"), "/dev/ser1");
  EXPECT_EQ(cfg.findSection("nothing"), nullptr);
  EXPECT_EQ(cfg.sectionNames(), "leader, secondrobot, gripper");
}

TEST(Configuration, CommentsBlankLinesCrLfAndSigns) {
  Configuration cfg = Configuration::parse(
      "# a comment\r\n\r\n  [arm]   # trailing comment\r\nclass TestArm\r\n\tposition +1 -2.5 3e2  # mm\r\n"
      "orientation 0 0 90\r\nport /dev/a#b\r\n");
  const ConfigSection* arm = cfg.findSection("arm");
  ASSERT_NE(arm, nullptr);
  EXPECT_EQ(arm->getNumbers("position"), (std::vector<double>{1, -2.5, 300}));
  EXPECT_EQ(arm->getWord("port"), "/dev/a#b");  // '#' inside a word is not a comment
  EXPECT_EQ(arm->find("orientation")->line, 6);
}

TEST(Configuration, ThePapersVectorFormGivesTheSameValues) {
  // Table 1 writes `position <x,y,z> orientation <r,p,y>`; spaces after the commas are allowed.
  const Configuration cfg = Configuration::parse(
      "[secondrobot]\nclass TestArm\nposition <300,0, -12.5>\norientation < 0 , 0 , 90 >\n", "rp.cfg");
  const ConfigSection* s = cfg.findSection("secondrobot");
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->getNumbers("position"), (std::vector<double>{300, 0, -12.5}));
  EXPECT_EQ(s->getNumbers("orientation"), (std::vector<double>{0, 0, 90}));
}

TEST(Configuration, EmptyFileHasNoSections) {
  EXPECT_TRUE(Configuration::parse("").sections().empty());
  EXPECT_TRUE(Configuration::parse("\n# only comments\n\n").sections().empty());
}

TEST(Configuration, ErrorCarriesFileAndLine) {
  try {
    Configuration::parse("[a]\nclass TestArm\npositon 1 2 3\n", "cell.cfg");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "cell.cfg");
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(std::string(e.what()), "cell.cfg:" + std::to_string(e.line()) + ": " + e.message());
  }
}

struct Malformed {
  std::string text;
  std::string message;
};

std::string known() { return TypeDatabase::instance().knownNames(); }
const std::string kArmSettings =
    "count, cpu, display, gain, mode, orientation, port, position, qmotorConfig, simulationMode, thread";

class MalformedFile : public ::testing::TestWithParam<Malformed> {};

TEST_P(MalformedFile, GivesExactMessage) {
  const Malformed& m = GetParam();
  try {
    Configuration::parse(m.text, "rp.cfg");
    FAIL() << "no error for:\n" << m.text;
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), m.message);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Configuration, MalformedFile,
    ::testing::Values(
        Malformed{"[leader\nclass TestArm\n", "rp.cfg:1: section header '[leader' is missing ']'"},
        Malformed{"[]\nclass TestArm\n", "rp.cfg:1: empty section name '[]'"},
        Malformed{"[lead er]\nclass TestArm\n",
                  "rp.cfg:1: section name 'lead er' must start with a letter or '_' and contain only letters, "
                  "digits, '_' and '-'"},
        Malformed{"[a] extra\nclass TestArm\n", "rp.cfg:1: unexpected text 'extra' after section header [a]"},
        Malformed{"[a]\nclass TestArm\n\n[a]\nclass TestArm\n", "rp.cfg:4: duplicate section [a] (first at line 1)"},
        Malformed{"class TestArm\n[a]\n",
                  "rp.cfg:1: setting 'class' is outside a section (start one with a [name] line)"},
        Malformed{"# settings first\nposition 1 2 3\n",
                  "rp.cfg:2: setting 'position' is outside a section (start one with a [name] line)"},
        Malformed{"[a]\nposition 1 2 3\n[b]\nclass TestArm\n", "rp.cfg:1: section [a] has no 'class' setting"},
        Malformed{"[a]\nclass TestArm WAM\n", "rp.cfg:2: setting 'class' needs 1 value (a class name), got 2"},
        Malformed{"[a]\nclass\n", "rp.cfg:2: setting 'class' needs 1 value (a class name), got 0"},
        Malformed{"[a]\nclass TestArm\nclass TestArm\n",
                  "rp.cfg:3: setting 'class' is given twice in [a] (first at line 2)"},
        Malformed{"[a]\nclass TestArm\nposition 1 2 3\nposition 1 2 3\n",
                  "rp.cfg:4: setting 'position' is given twice in [a] (first at line 3)"},
        Malformed{"[a]\nclass TestArm\npositon 1 2 3\n",
                  "rp.cfg:3: setting 'positon' is not known for class TestArm (known: " + kArmSettings + ")"},
        Malformed{"[a]\nclass TestArm\nposition 1 2\n",
                  "rp.cfg:3: setting 'position' needs 3 values (x y z [mm]), got 2"},
        Malformed{"[a]\nclass TestArm\nposition <1, 2>\n",
                  "rp.cfg:3: setting 'position' needs 3 values (x y z [mm]), got 2"},
        Malformed{"[a]\nclass TestArm\nposition <1, 2, 3\n", "rp.cfg:3: setting 'position': '<' without a closing '>'"},
        Malformed{"[a]\nclass TestArm\nposition <1,,3>\n",
                  "rp.cfg:3: setting 'position': '<1,,3>' is not a list of values like <x,y,z>"},
        Malformed{"[a]\nclass TestArm\nposition <1 2 3>\n",
                  "rp.cfg:3: setting 'position': '<1 2 3>' is not a list of values like <x,y,z>"},
        Malformed{"[a]\nclass TestArm\nposition <1,2,3> 4\n", "rp.cfg:3: setting 'position': unexpected text after '>'"},
        Malformed{"[a]\nclass TestArm\nposition 1 2 3 4\n",
                  "rp.cfg:3: setting 'position' needs 3 values (x y z [mm]), got 4"},
        Malformed{"[a]\nclass TestArm\norientation 1,2,3\n",
                  "rp.cfg:3: setting 'orientation' needs 3 values (roll pitch yaw [deg]), got 1"},
        Malformed{"[a]\nclass TestArm\nposition 1 abc 3\n", "rp.cfg:3: setting 'position': 'abc' is not a number"},
        Malformed{"[a]\nclass TestArm\nposition 1 2 -\n", "rp.cfg:3: setting 'position': '-' is not a number"},
        Malformed{"[a]\nclass TestArm\nposition 1 2 3mm\n", "rp.cfg:3: setting 'position': '3mm' is not a number"},
        // One sign only (both used to be taken as -5).
        Malformed{"[a]\nclass TestArm\nposition +-5 0 0\n", "rp.cfg:3: setting 'position': '+-5' is not a number"},
        Malformed{"[a]\nclass TestArm\ncount +-5\n", "rp.cfg:3: setting 'count': '+-5' is not an integer"},
        Malformed{"[a]\nclass TestArm\nposition nan 0 0\n",
                  "rp.cfg:3: setting 'position': 'nan' is not a finite number"},
        Malformed{"[a]\nclass TestArm\nposition 0 inf 0\n",
                  "rp.cfg:3: setting 'position': 'inf' is not a finite number"},
        Malformed{"[a]\nclass TestArm\nsimulationMode maybe\n",
                  "rp.cfg:3: setting 'simulationMode': 'maybe' is not one of on, off"},
        Malformed{"[a]\nclass TestArm\nsimulationMode on off\n",
                  "rp.cfg:3: setting 'simulationMode' needs 1 value (on, off), got 2"},
        Malformed{"[a]\nclass TestArm\ndisplay shaded\n",
                  "rp.cfg:3: setting 'display': 'shaded' is not one of off, solid, wireframe"},
        Malformed{"[a]\nclass TestArm\ndisplay\n",
                  "rp.cfg:3: setting 'display' needs 1 value (off, solid, wireframe), got 0"},
        Malformed{"[a]\nclass TestArm\ncount 2.5\n", "rp.cfg:3: setting 'count': '2.5' is not an integer"},
        Malformed{"[a]\nclass TestArm\ngain 1\n", "rp.cfg:3: setting 'gain' needs 2 values (kp kd [N/m]), got 1"},
        Malformed{"[a]\nclass TestArm\n3d on\n", "rp.cfg:3: '3d' is not a valid setting name"},
        Malformed{"[a]\nclass TestFunction\nposition 0 0 0\n",
                  "rp.cfg:3: setting 'position' is not known for class TestFunction (known: cpu, qmotorConfig, thread)"},
        Malformed{"[a]\nclass TestArm\nthread mine\n", "rp.cfg:3: setting 'thread' needs 1 value (own, shared), got 'mine'"},
        Malformed{"[a]\nclass TestArm\nthread\n", "rp.cfg:3: setting 'thread' needs 1 value (own, shared), got 0 values"},
        Malformed{"[a]\nclass TestArm\ncpu -1\n", "rp.cfg:3: setting 'cpu' needs 1 value, a CPU number in 0..1023, got '-1'"},
        Malformed{"[a]\nclass TestArm\ncpu 1.5\n", "rp.cfg:3: setting 'cpu' needs 1 value, a CPU number in 0..1023, got '1.5'"},
        Malformed{"[a]\nclass TestArm\nqmotorConfig a.cfg b.cfg\n",
                  "rp.cfg:3: setting 'qmotorConfig' needs 1 value (a file name), got 2"},
        Malformed{"[a]\nclass TestArm\nqmotorConfig rp_no_such_file.cfg\n",
                  "rp.cfg:3: qmotorConfig file 'rp_no_such_file.cfg' cannot be read: No such file or directory"},
        Malformed{"plugin\n", "rp.cfg:1: setting 'plugin' needs 1 value (a shared library path), got 0"},
        Malformed{"plugin /nonexistent/librp_nothing.so\n",
                  "rp.cfg:1: plugin '/nonexistent/librp_nothing.so' cannot be loaded: /nonexistent/librp_nothing.so: "
                  "cannot open shared object file: No such file or directory"},
        Malformed{std::string("[a]\nclass Test\0Arm\n", 19), "rp.cfg:2: the file is not a text file (byte 0x00 in column 11)"},
        Malformed{"[a]\nclass TestArm\nport \x01\n", "rp.cfg:3: the file is not a text file (byte 0x01 in column 6)"},
        // Ranges (issue 19): a huge position used to fail later with neither the setting nor the line.
        Malformed{"[a]\nclass TestArm\nposition 1e308 1e308 1e308\n",
                  "rp.cfg:3: setting 'position': '1e308' is outside -1000000..1000000 [mm]"},
        Malformed{"[a]\nclass TestArm\nposition 0 0 -1000000.5\n",
                  "rp.cfg:3: setting 'position': '-1000000.5' is outside -1000000..1000000 [mm]"},
        Malformed{"[a]\nclass TestArm\norientation 0 361 0\n",
                  "rp.cfg:3: setting 'orientation': '361' is outside -360..360 [deg]"},
        Malformed{"[a]\nclass TestArm\nposition 1e400 0 0\n",
                  "rp.cfg:3: setting 'position': '1e400' is out of the range of numbers"},
        Malformed{"[a]\nclass TestArm\ncount 2147483648\n",
                  "rp.cfg:3: setting 'count': '2147483648' is outside -2147483648..2147483647"},
        Malformed{"[a]\nclass TestArm\ncount -99999999999999999999999\n",
                  "rp.cfg:3: setting 'count': '-99999999999999999999999' is outside -2147483648..2147483647"},
        // Quoted text is cut to an excerpt.
        Malformed{"[a]\nclass TestArm\nposition 1 2 " + std::string(100, '7') + "x\n",
                  "rp.cfg:3: setting 'position': '" + std::string(37, '7') + "...' is not a number"}));

// A UTF-8 byte-order mark (Windows editors) is not part of the first line of either kind of file.
TEST(Configuration, ByteOrderMarkIsSkipped) {
  Configuration cfg = Configuration::parse("\xEF\xBB\xBF[a]\nclass TestArm\n");
  ASSERT_EQ(cfg.sections().size(), 1u);
  EXPECT_EQ(cfg.sections()[0].name(), "a");
  EXPECT_EQ(cfg.sections()[0].line(), 1);
  ParameterFile p = ParameterFile::parse("\xEF\xBB\xBFkp 1 2\n", "leader.cfg");
  ASSERT_EQ(p.entries().size(), 1u);
  EXPECT_EQ(p.entries()[0].name, "kp");
  // Only at the very start: elsewhere the bytes are text as before.
  EXPECT_THROW(Configuration::parse("[a]\nclass TestArm\n\xEF\xBB\xBFport x\n"), ConfigError);
}

// A 10 MB token is quoted as a short excerpt, in both kinds of file.
TEST(Configuration, HugeTokensAreQuotedShort) {
  const std::string huge(10 << 20, 'x');
  auto message = [](auto&& parse) -> std::string {
    try {
      parse();
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "no error";
  };
  const std::string excerpt = "'" + std::string(37, 'x') + "...'";
  for (const std::string& text : {"[a]\nclass TestArm\nposition 1 2 " + huge + "\n", "[" + huge + "\n",
                                  "[a] " + huge + "\n", "[a]\nclass " + huge + "\n", huge + " 1\n",
                                  "[a]\nclass TestArm\n" + huge + " 1\n"}) {
    const std::string m = message([&] { Configuration::parse(text); });
    EXPECT_LT(m.size(), 300u) << m.substr(0, 300);
    EXPECT_EQ(m.rfind("rp.cfg:", 0), 0u) << m.substr(0, 300);
  }
  EXPECT_EQ(message([&] { ParameterFile::parse("kp " + huge + "\n", "leader.cfg"); }),
            "leader.cfg:1: 'kp': " + excerpt + " is not a number");
  // Cut at a character boundary: no half of a two-byte UTF-8 character.
  const std::string umlauts = std::string(36, 'a') + "\xC3\xA4\xC3\xA4\xC3\xA4";
  EXPECT_EQ(ConfigError::excerpt(umlauts), std::string(36, 'a') + "...");
  EXPECT_EQ(ConfigError::excerpt("short"), "short");
  EXPECT_EQ(ConfigError::excerpt(std::string(40, 'a')), std::string(40, 'a'));
}

// How many objects a file may create is bounded.
TEST(Configuration, SectionCountIsBounded) {
  std::string text;
  for (std::size_t i = 0; i < ConfigLimits::kMaxSections; ++i) text += "[o" + std::to_string(i) + "]\nclass TestArm\n";
  EXPECT_EQ(Configuration::parse(text).sections().size(), ConfigLimits::kMaxSections);
  text += "[last]\nclass TestArm\n";
  try {
    Configuration::parse(text);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "rp.cfg:2001: too many sections: a file may configure at most 1000 objects");
  }
}

// Messages whose text depends on the registered classes or on files.
TEST(Configuration, UnknownClassListsTheKnownOnes) {
  try {
    Configuration::parse("\n[leader]\nclass Puma\n");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "rp.cfg:3: class 'Puma' is not known (known: " + known() + ")");
    EXPECT_NE(known().find("TestArm"), std::string::npos);
  }
}

TEST(Configuration, BinaryNulByteAnywhere) {
  std::string text("[a]\nclass TestArm\n", 17);
  text += std::string("\0\0\0", 3);
  EXPECT_THROW(Configuration::parse(text), ConfigError);
}

TEST(Configuration, UnreadableFiles) {
  try {
    Configuration::read("/nonexistent/rp.cfg");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/rp.cfg: cannot read the file: No such file or directory");
    EXPECT_EQ(e.line(), 0);
  }
  auto dir = test::scratchDirectory("dir");
  try {
    Configuration::read(dir.string());
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), dir.string() + ": cannot read the file: it is a directory");
  }
}

// Only regular files are read, up to a size cap: /dev/zero used to be read until std::bad_alloc
// aborted the process, and a FIFO blocked it.
TEST(Configuration, OnlyRegularFilesOfBoundedSize) {
  auto message = [](const std::string& file) -> std::string {
    try {
      Configuration::read(file);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(message("/dev/zero"), "/dev/zero: cannot read the file: it is not a regular file");
  EXPECT_EQ(message("/dev/null"), "/dev/null: cannot read the file: it is not a regular file");
  auto dir = test::scratchDirectory("special");
  const std::string fifo = (dir / "fifo.cfg").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(message(fifo), fifo + ": cannot read the file: it is not a regular file");
  // The largest file accepted, and one byte more.
  std::string text = "[a]\nclass TestArm\n";
  text += std::string(ConfigLimits::kMaxFileBytes - text.size() - 1, '#') + "\n";
  test::writeFile(dir / "big.cfg", text);
  EXPECT_EQ(message((dir / "big.cfg").string()), "no error");
  test::writeFile(dir / "big.cfg", text + "\n");
  EXPECT_EQ(message((dir / "big.cfg").string()),
            (dir / "big.cfg").string() + ": cannot read the file: it is larger than 1048576 bytes (1 MiB)");
  // The same for a qmotorConfig file, reported at the rp.cfg line that names it.
  for (const std::string& q : {std::string("/dev/zero"), fifo, (dir / "big.cfg").string()}) {
    test::writeFile(dir / "rp.cfg", "[leader]\nclass TestArm\nqmotorConfig " + q + "\n");
    const std::string m = message((dir / "rp.cfg").string());
    EXPECT_EQ(m.rfind((dir / "rp.cfg").string() + ":3: qmotorConfig file '", 0), 0u) << m;
    EXPECT_NE(m.find("' cannot be read: it is "), std::string::npos) << m;
  }
  test::writeFile(dir / "rp.cfg", "[leader]\nclass TestArm\nqmotorConfig " + std::string(5000, 'p') + "\n");
  EXPECT_EQ(message((dir / "rp.cfg").string()),
            (dir / "rp.cfg").string() + ":3: setting 'qmotorConfig': the path is longer than 4095 bytes");
}

TEST(Configuration, QMotorFileErrorsNameThatFile) {
  auto dir = test::scratchDirectory("qmotor");
  const std::string cfg = (dir / "rp.cfg").string();
  const std::string q = (dir / "leader.cfg").string();
  auto message = [&](const std::string& qmotorText) {
    test::writeFile(dir / "leader.cfg", qmotorText);
    test::writeFile(dir / "rp.cfg", "[leader]\nclass TestArm\nqmotorConfig leader.cfg\n");
    try {
      Configuration::read(cfg);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message("kp 1\nkd abc\n"), q + ":2: 'kd': 'abc' is not a number");
  EXPECT_EQ(message("kp 1\nkp 2\n"), q + ":2: 'kp' is given twice (first at line 1)");
  EXPECT_EQ(message("\n\n[gains]\n"), q + ":3: sections ('[...]') are not allowed in a control-program file");
  EXPECT_EQ(message("kp\n"), q + ":1: 'kp' has no value");
  EXPECT_EQ(message("k-p 1\n"), q + ":1: 'k-p' is not a valid parameter name");
  EXPECT_EQ(message("log q tau\nkp 1 2\n"), "no error");  // `log` takes words
}

TEST(Configuration, OptionsSkipChecks) {
  Configuration::Options lax;
  lax.checkClasses = false;
  lax.readQMotorFiles = false;
  lax.loadPlugins = false;
  Configuration cfg = Configuration::parse("plugin libx.so\n[a]\nclass Nope\nanything 1\nqmotorConfig none.cfg\n",
                                           "dir/rp.cfg", lax);
  ASSERT_EQ(cfg.plugins().size(), 1u);
  EXPECT_EQ(cfg.plugins()[0].values[0], "dir/libx.so");  // relative to the file's folder
  EXPECT_EQ(cfg.findSection("a")->qmotorConfig(), nullptr);
}

TEST(SettingSchema, DeclarationsAndKnownNames) {
  SettingSchema s;
  PhysicalObject::declareSettings(s);
  EXPECT_NE(s.find("position"), nullptr);
  EXPECT_EQ(s.find("position")->unit, "mm");
  EXPECT_EQ(s.find("orientation")->unit, "deg");
  EXPECT_EQ(s.find("nothing"), nullptr);
  EXPECT_EQ(s.knownNames(), "cpu, display, orientation, position, qmotorConfig, simulationMode, thread");
}

TEST(SettingSchema, DefaultsForTheReference) {
  SettingSchema s;
  s.addInteger("port", "TCP port", 1, 65535);
  EXPECT_EQ(s.find("port")->defaultValue, "");
  s.setDefault("port", "502");
  EXPECT_EQ(s.find("port")->defaultValue, "502");
  EXPECT_EQ(s.find("port")->minValue, 1);
  EXPECT_EQ(s.find("port")->maxValue, 65535);
  EXPECT_THROW(s.setDefault("prot", "502"), std::logic_error);  // a typo is a programming error
  PhysicalObject::declareSettings(s);
  EXPECT_EQ(s.find("display")->defaultValue, "solid");
}

// addWords(): a list of words with a count range, checked where rp.cfg is read (the gripper's
// `graspable` list takes 1 to 64 names).
TEST(SettingSchema, WordListsTakeTheirRangeOfWords) {
  SettingSchema s;
  s.addWords("names", 2, 5, "objects", "deg");
  const SettingSpec* w = s.find("names");
  ASSERT_NE(w, nullptr);
  EXPECT_EQ(w->kind, SettingKind::Word);
  EXPECT_EQ(w->minValues, 2);
  EXPECT_EQ(w->maxValues, 5);
  EXPECT_EQ(w->unit, "deg");
  std::string words;
  for (int i = 0; i < 65; ++i) words += " piece" + std::to_string(i);
  const auto message = [](const std::string& graspable) {
    try {
      Configuration::parse("[g]\nclass DefaultGripper\ngraspable" + graspable + "\n", "grip.cfg");
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string needs =
      "grip.cfg:3: setting 'graspable' needs 1 to 64 values (names of the objects the simulated gripper can pick up), got ";
  EXPECT_EQ(message(words), needs + "65");
  EXPECT_EQ(message(words.substr(0, words.find(" piece64"))), "no error");
  EXPECT_EQ(message(""), needs + "0");
}

}  // namespace
}  // namespace rp
