#pragma once
// The names the URDF and MJCF exports write: the model's joint and link names (a URDF arm's own,
// joint1.../link1... for the built-in arms), and names for the frames the exports add (the base,
// the tool) that no joint or link of the model has. Internal to the library.

#include <string>
#include <vector>

#include "rp/model/ManipulatorModel.hpp"

namespace rp::internal {

/// The names of the model's joints and links in joint order, and of the frames an export adds.
struct ExportNames {
  std::vector<std::string> joints;  // getJointName(k)
  std::vector<std::string> links;   // getLinkName(k)
  std::string world;                // link: the world frame (URDF)
  std::string base;                 // link or body: the base frame
  std::string baseJoint;            // fixed joint world -> base (URDF)
  std::string tool;                 // link, fixed joint (URDF) or site (MJCF): the end-effector
};

// `wanted`, or if a name in `taken` equals it, `wanted_2`, `wanted_3`, ... (the first that is free).
std::string freeName(const std::string& wanted, const std::vector<std::string>& taken);

// The model's names, and `world`, `base_link`, `base` and `tool` made free of them (links and
// joints are separate name spaces in URDF and MJCF: a link is only kept apart from links).
ExportNames exportNames(const ManipulatorModel& model);

}  // namespace rp::internal
