// The Scene Viewer's view of the objects: the scene description (JSON, replayed to every page)
// and the binary state frames, built in the server thread from the ObjectManager's objects.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "rp/core/PhysicalObject.hpp"
#include "rp/core/RoboticObject.hpp"
#include "rp/gui/UrdfVisuals.hpp"

namespace rp {
class ControlProgram;
class Manipulator;
struct ManipulatorData;
}  // namespace rp

namespace rp::internal {
struct PhysicalObjectView;

// Magic number at the start of every binary state frame: "RPS1" read as a little-endian u32.
inline constexpr std::uint32_t kStateFrameMagic = 0x31535052u;

class SceneState {
 public:
  SceneState();
  ~SceneState();
  SceneState(const SceneState&) = delete;
  SceneState& operator=(const SceneState&) = delete;

  // Looks at the object list: published objects are described (through ObjectReferences, so
  // none can be destroyed meanwhile), objects not published yet are listed by name only, and a
  // withdrawn object keeps its last description until it leaves the list. Returns true if the
  // scene description changed (then sceneMessage() has a new version).
  bool refresh();
  // The scene message: {"type": "scene", "protocol", "version", "objects": [...]}.
  const std::string& sceneMessage() const { return sceneMessage_; }
  std::uint32_t version() const { return version_; }

  // Builds one binary state frame of every described object that still exists.
  std::string buildFrame();

  // The mesh file of shape `shape` of the described object `name` (empty if there is none). A
  // URDF arm's collision meshes (drawn instead of visuals that cannot be) follow its shapes: the
  // shape's `fallback` entries in the scene give their numbers.
  std::string meshFile(const std::string& name, std::size_t shape) const;

  // A page could not draw mesh `shape` of object `name` (`why`, from the page): prints it on
  // stderr once per file (returns true then). Only files the scene names are reported.
  bool reportMeshFailure(const std::string& name, std::size_t shape, const std::string& why);

 private:
  struct Entry {
    RoboticObject* object = nullptr;
    std::string name;
    bool described = false;
    PhysicalObject* physical = nullptr;
    Manipulator* manipulator = nullptr;
    ControlProgram* program = nullptr;  // the object's control loop, if it has one
    std::vector<std::string> frames;
    std::unique_ptr<ManipulatorData> data;
    int index = -1;  // position in the scene's object array
    nlohmann::json description;  // the last description
    std::vector<std::string> meshes;  // mesh file of each shape (empty for other shapes)
    bool urdfLoaded = false;          // a UrdfManipulator's visuals were looked for
    std::vector<UrdfVisual> urdfVisuals;  // its URDF <visual> elements (empty: none)
    std::string urdfError;            // why they could not be read
  };
  nlohmann::json describe(Entry& e);
  // A physical object of a class that does not publish itself (see unpublishedPhysicalObjects()).
  nlohmann::json describeUnpublished(const PhysicalObjectView& v, const std::map<std::string, RoboticObject*>& published);
  // The world pose of `world` given relative to frame `frame` of `mount`, through the chain of
  // mounts as far as they are published (in `live`; others are not read).
  Transform mountedPose(Transform world, PhysicalObject* mount, std::string frame, const std::set<const RoboticObject*>& live);
  void loadVisuals(Entry& e);
  // Prints `what` about mesh `file` on stderr unless it was printed for that file already.
  bool reportOnce(const std::string& file, const std::string& what);

  std::map<RoboticObject*, Entry> entries_;
  std::map<std::string, int> unpublishedIndex_;  // scene index of each unpublished physical object drawn
  std::string sceneMessage_;
  std::string lastObjects_;
  std::uint32_t version_ = 0;
  std::set<std::string> reportedMeshes_;  // mesh files whose problem was printed on stderr
};

}  // namespace rp::internal
