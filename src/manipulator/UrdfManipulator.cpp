// A manipulator described by a URDF file (rp/manipulator/UrdfManipulator.hpp).
#include "rp/manipulator/UrdfManipulator.hpp"

#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "rp/core/RoboticPlatform.hpp"
#include "rp/core/TypeDatabase.hpp"
#include "rp/gui/UrdfVisuals.hpp"

namespace rp {

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

std::unique_ptr<ManipulatorModel> loadFor(const ConfigSection* section, const std::string& name,
                                          const std::string& urdfFile, const std::string& tipLink,
                                          const Transform& base) {
  const auto [file, tip] = resolve(section, urdfFile, tipLink);
  if (file.empty()) throw std::invalid_argument("UrdfManipulator '" + name + "': no URDF file (rp.cfg setting 'urdf')");
  UrdfOptions options;
  options.tip = tip;
  options.requireDynamics = true;
  std::vector<std::string> notes;
  options.notes = &notes;
  std::unique_ptr<ManipulatorModel> m = loadUrdf(file, options);
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
  schema.setDefault("urdf", "the constructor's argument");
  schema.setDefault("tip", "the constructor's argument");
  schema.setDefault("packagePath", "(none: ROS_PACKAGE_PATH, then the folders above the URDF file)");
}

}  // namespace rp

RP_REGISTER_CLASS_AS(rp::UrdfManipulator, "UrdfManipulator");
