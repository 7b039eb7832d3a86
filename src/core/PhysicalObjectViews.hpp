// What the Scene Viewer may read of physical objects that are not published (a class of the
// user's whose constructor does not call publishObject()): from the end of PhysicalObject's
// constructor to the start of its destructor, their PhysicalObject part (pose, mount, display
// mode) is complete and guarded by its own lock, so it is read without any virtual call.
#pragma once

#include <string>
#include <vector>

#include "rp/core/PhysicalObject.hpp"

namespace rp::internal {

struct PhysicalObjectView {
  std::string name;
  Transform transform;                  // getTransform()
  const PhysicalObject* mount = nullptr;  // getConnection(): compare only, never dereference
  std::string mountName;                // the mount's name if it is known to be alive, else empty
  std::string mountFrame;               // getConnectionFrame()
  DisplayMode display = DisplayMode::Solid;
  Model3D model;  // PhysicalObject's own get3DModel() (not an override: no virtual call)
};

// Every PhysicalObject constructed as far as PhysicalObject, not yet being destroyed, and not
// published now, in construction order.
std::vector<PhysicalObjectView> unpublishedPhysicalObjects();

}  // namespace rp::internal
