#pragma once
/// @file
/// The `<visual>` elements of a URDF arm as shapes of its 3D model (drawn by the Scene Viewer).

#include <string>
#include <vector>

#include "rp/core/PhysicalObject.hpp"

namespace rp {

/// Reads the `<visual>` elements of the links of a URDF arm and returns them as shapes attached
/// to the frames of the manipulator model loadUrdf() makes of the same file and tip: a link
/// before the first movable joint goes to frame `base`, a link after the k-th movable joint of
/// the chain (including links fixed to it) to frame `linkk`, with the constant pose of the visual
/// in that Denavit-Hartenberg frame. Links on branches with movable joints of their own (not
/// modelled) are left out. Boxes, cylinders (along z, as in URDF), spheres and meshes (scaled by
/// `scale`) keep their sizes; a mesh path relative to the URDF file, `file://` or `package://NAME/...`
/// (NAME looked up among the folders above the URDF file) becomes an absolute path. Colours come from
/// the visual's material or the robot's material of that name (default grey).
/// @param[in] urdfFile  path of the URDF file
/// @param[in] tip       tip link, as UrdfOptions::tip (empty: the last movable link of an unbranched chain)
/// @return the shapes (empty if the file has no visuals)
/// @throws UrdfError naming the file, as loadUrdf()
/// Real-time safe: no.
std::vector<Shape> loadUrdfVisuals(const std::string& urdfFile, const std::string& tip = "");

}  // namespace rp
