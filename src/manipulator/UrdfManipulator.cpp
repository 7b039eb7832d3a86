// A manipulator described by a URDF file (rp/manipulator/UrdfManipulator.hpp).
#include "rp/manipulator/UrdfManipulator.hpp"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "rp/core/RoboticPlatform.hpp"
#include "rp/core/TypeDatabase.hpp"
#include "rp/gui/UrdfVisuals.hpp"

namespace rp {

namespace internal {
bool parseNumber(const std::string& token, double& value);  // Configuration.cpp: a whole token, one sign
}  // namespace internal

namespace {
// The URDF file and tip link: rp.cfg's settings override the constructor's arguments.
std::pair<std::string, std::string> resolve(const ConfigSection* section, std::string file, std::string tip) {
  if (section != nullptr) {
    if (section->has("urdf")) {
      file = section->getWord("urdf");
      const std::filesystem::path p(file);
      if (p.is_relative()) file = (std::filesystem::path(section->fileName()).parent_path() / p).string();
    }
    if (section->has("tip")) tip = section->getWord("tip");
  }
  return {file, tip};
}

// rp.cfg's `offChainPositions joint=value ...` [deg or mm] (empty without the setting); a word that
// is no joint=value pair with a finite number, or a joint given twice, is refused at its line.
std::map<std::string, double> offChainSetting(const ConfigSection* section) {
  std::map<std::string, double> positions;
  if (section == nullptr) return positions;
  const ConfigSetting* setting = section->find("offChainPositions");
  if (setting == nullptr) return positions;
  for (const std::string& word : setting->values) {
    std::string quoted(1, '\'');  // piece by piece: GCC 12 warns (-Wrestrict) about "'" + s
    quoted += ConfigError::excerpt(word);
    quoted += '\'';
    const std::size_t eq = word.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == word.size())
      throw section->errorAt(*setting, "offChainPositions: " + quoted +
                                           " is not a joint=value pair (value in deg, or mm for a prismatic joint)");
    const std::string joint = word.substr(0, eq), text = word.substr(eq + 1);
    double value = 0;
    if (!internal::parseNumber(text, value) || !std::isfinite(value))  // (rp.cfg's numbers: "+-5" is none)
      throw section->errorAt(*setting, "offChainPositions: joint '" + ConfigError::excerpt(joint) + "': '" +
                                           ConfigError::excerpt(text) + "' is not a finite number");
    if (!positions.emplace(joint, value).second)
      throw section->errorAt(*setting, "offChainPositions: joint '" + ConfigError::excerpt(joint) + "' is given twice");
  }
  return positions;
}

std::unique_ptr<ManipulatorModel> loadFor(const ConfigSection* section, const std::string& name,
                                          const std::string& urdfFile, const std::string& tipLink,
                                          const Transform& base) {
  const auto [file, tip] = resolve(section, urdfFile, tipLink);
  if (file.empty()) {
    if (section != nullptr)
      throw ConfigError(section->fileName(), section->line(),
                        "[" + section->name() + "] (class UrdfManipulator) needs 'urdf FILE', the arm's description");
    throw std::invalid_argument("UrdfManipulator '" + name + "': no URDF file (rp.cfg setting 'urdf')");
  }
  UrdfOptions options;
  options.tip = tip;
  options.requireDynamics = true;
  options.offChainPositions = offChainSetting(section);
  options.offChainInDegreesAndMillimetres = true;
  std::vector<std::string> notes;
  options.notes = &notes;
  std::unique_ptr<ManipulatorModel> m;
  try {
    m = loadUrdf(file, options);
  } catch (const UrdfOptionError& e) {  // a joint of rp.cfg's offChainPositions: refused at its line
    const ConfigSetting* setting = section != nullptr ? section->find("offChainPositions") : nullptr;
    if (setting == nullptr) throw;
    throw section->errorAt(*setting, "offChainPositions: " + e.problem() + " in " + file);
  } catch (const UrdfError& e) {
    // A file rp.cfg names: that line first, then the loader's own error (naming the URDF file and
    // the joint or link), so a user of rp.cfg sees where the file came from.
    const ConfigSetting* setting = section != nullptr ? section->find("urdf") : nullptr;
    // An unknown tip that rp.cfg named: that line instead.
    if (const ConfigSetting* t = section != nullptr ? section->find("tip") : nullptr;
        t != nullptr && !t->values.empty() && std::string(e.what()).find("'" + t->values[0] + "'") != std::string::npos)
      setting = t;
    if (setting == nullptr) throw;
    throw UrdfError(section->fileName() + ":" + std::to_string(setting->line) + ": " + setting->name + ": " + e.what());
  }
  for (const std::string& note : notes) std::cerr << "rp: UrdfManipulator '" << name << "': " << note << std::endl;
  // Place the arm where the object stands: the object's pose times the URDF's own base frame.
  const ManipulatorModel& chain = m->getChain();  // with mimic joints: the whole chain, coupled again below
  std::vector<LinkParameters> links;
  for (int i = 0; i < chain.getNumberOfJoints(); ++i) links.push_back(chain.getLink(i));
  auto placed = std::make_unique<ManipulatorModel>(chain.getName(), links, Transform(base * chain.getBaseTransform()),
                                                   chain.getToolTransform(), chain.getGravity(), chain.getConvention());
  if (!m->hasMimicJoints()) return placed;
  return std::make_unique<ManipulatorModel>(std::shared_ptr<const ManipulatorModel>(std::move(placed)), m->getCoupling());
}
}  // namespace

UrdfManipulator::UrdfManipulator(const std::string& name, const std::string& urdfFile, const std::string& tip)
    : DefaultManipulator(ClassSection(name, "UrdfManipulator"), [this, urdfFile, tip](const Transform& base) {
        return loadFor(configSection(), getName(), urdfFile, tip, base);
      }) {
  std::tie(urdfFile_, tip_) = resolve(configSection(), urdfFile, tip);
  startControlLoop();
}

UrdfManipulator::~UrdfManipulator() { stopControlLoop(); }

std::map<std::string, double> UrdfManipulator::getOffChainPositions() const { return offChainSetting(configSection()); }

std::vector<std::string> UrdfManipulator::getPackagePath() const {
  if (const ConfigSection* section = configSection())
    if (section->has("packagePath"))
      return splitPackagePath(section->getWord("packagePath"),
                              std::filesystem::path(section->fileName()).parent_path().string());
  return {};
}

void UrdfManipulator::declareSettings(SettingSchema& schema) {
  DefaultManipulator::declareSettings(schema);
  schema.addWord("urdf", "URDF file of the arm");
  schema.addWord("tip", "last link of the chain");
  schema.addWord("packagePath", "folders holding the packages of package:// mesh files, separated by ':'");
  schema.addWords("offChainPositions", 1, 64,
                   "joint=value pairs: where moving joints off the chain (fingers, a jaw) stand when their links are lumped "
                   "into the arm (revolute in deg, prismatic in mm)",
                   "deg or mm");
  schema.setDefault("offChainPositions", "(zero within each joint's limits; a mimic joint follows its master)");
  schema.setDefault("urdf", "the constructor's argument");
  schema.setDefault("tip", "the constructor's argument");
  schema.setDefault("packagePath", "(none: ROS_PACKAGE_PATH, then the folders above the URDF file)");
}

}  // namespace rp

RP_REGISTER_CLASS_AS(rp::UrdfManipulator, "UrdfManipulator");
