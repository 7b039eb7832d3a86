// The names the URDF and MJCF exports write (ExportNames.hpp).
#include "ExportNames.hpp"

#include <algorithm>

namespace rp::internal {

std::string freeName(const std::string& wanted, const std::vector<std::string>& taken) {
  auto isTaken = [&](const std::string& name) { return std::find(taken.begin(), taken.end(), name) != taken.end(); };
  if (!isTaken(wanted)) return wanted;
  for (std::size_t i = 2;; ++i) {
    const std::string name = wanted + "_" + std::to_string(i);
    if (!isTaken(name)) return name;
  }
}

ExportNames exportNames(const ManipulatorModel& model) {
  ExportNames names;
  for (int k = 0; k < model.getNumberOfJoints(); ++k) {
    names.joints.push_back(model.getJointName(k));
    names.links.push_back(model.getLinkName(k));
  }
  std::vector<std::string> links = names.links;
  names.world = freeName("world", links);
  links.push_back(names.world);
  names.base = freeName("base_link", links);
  links.push_back(names.base);
  names.tool = freeName("tool", links);
  // The URDF's tool joint is named as its link: kept apart from the model's joints as well.
  std::vector<std::string> joints = names.joints;
  names.baseJoint = freeName("base", joints);
  joints.push_back(names.baseJoint);
  while (std::find(joints.begin(), joints.end(), names.tool) != joints.end()) {
    links.push_back(names.tool);
    names.tool = freeName("tool", links);
  }
  return names;
}

}  // namespace rp::internal
