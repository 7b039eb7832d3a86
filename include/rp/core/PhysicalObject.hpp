#pragma once
/// @file
/// The base class of objects that exist in the work cell (paper section 3.2, Figure 6).

#include <string>
#include <vector>

#include "rp/core/RoboticObject.hpp"
#include "rp/math/Matrix.hpp"
#include "rp/math/Transform.hpp"

namespace rp {

/// How the Scene Viewer shows an object.
enum class DisplayMode {
  Off,        ///< hidden
  Solid,      ///< shaded surfaces
  Wireframe,  ///< edges only
};

/// An RGBA colour, each component in [0, 1].
struct Color {
  double r = 0.7;  ///< red
  double g = 0.7;  ///< green
  double b = 0.7;  ///< blue
  double a = 1.0;  ///< opacity
};

/// The kind of a 3D shape.
enum class ShapeKind {
  Box,       ///< size = (x, y, z) edge lengths [m]
  Cylinder,  ///< size = (radius, length along z, unused) [m]
  Sphere,    ///< size = (radius, unused, unused) [m]
  Mesh,      ///< `meshFile` (STL, glTF, Collada, VRML), scaled by size (default 1, 1, 1)
};

/// One shape of an object's 3D model, attached to a named frame of the object.
struct Shape {
  ShapeKind kind = ShapeKind::Box;  ///< what the shape is
  std::string frame = "base";       ///< name of the object frame the shape moves with
  Transform pose = Transform::unit();  ///< pose of the shape in that frame [m]
  Vector<3> size = Vector<3>::Ones();      ///< dimensions, see ShapeKind
  std::string meshFile;                     ///< mesh file path or URL (Mesh only)
  Color color;                              ///< colour
};

/// An object's 3D model description (the role of Open Inventor's scene graph in the paper):
/// plain data the browser viewer draws. Frame poses at run time come from the object's state.
struct Model3D {
  std::vector<std::string> frames{"base"};  ///< the object's frames; "base" is its own pose
  std::vector<Shape> shapes;                ///< shapes, each attached to one of `frames`
  /// A manipulator's shapes draw its links: the viewer adds no generic links between its frames.
  bool linksDrawn = false;
};

/// Base class of manipulators, grippers, sensors and every other physical object: 3D model,
/// mounting connection, pose, simulation mode and display mode.
///
/// rp.cfg settings (Table 1): `position x y z` [mm], `orientation r p y` [deg],
/// `simulationMode on|off`, `display off|solid|wireframe`.
class PhysicalObject : public RoboticObject {
 public:
  /// Creates the object and applies the settings of its rp.cfg section, if any.
  /// @param[in] name  object name; empty for an automatic name
  /// @throws ConfigError if a setting is invalid
  /// Real-time safe: no.
  explicit PhysicalObject(const std::string& name = "");
  ~PhysicalObject() override;

  /// Declares `position`, `orientation`, `simulationMode` and `display`.
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);

  /// The 3D model; the default is a 0.1 m grey cube at the base frame. Real-time safe: no.
  virtual Model3D get3DModel() const;

  /// Mounts this object on another one (e.g. a gripper on an end-effector frame).
  /// @param[in] mount  the object carrying this one (must outlive the connection)
  /// @param[in] frame  frame of `mount` this object is attached to (`base` for its base)
  /// @throws std::invalid_argument if the connection would make a cycle (the object itself, or
  ///         an object mounted on it)
  /// @throws anything the object's physicalSetupChanged() throws; the connection is then unchanged
  /// Real-time safe: no.
  void setConnection(PhysicalObject& mount, const std::string& frame = "base");
  /// Removes the connection: the pose is again relative to the world.
  /// @throws anything the object's physicalSetupChanged() throws; the connection is then unchanged
  /// Real-time safe: no.
  void clearConnection();
  /// The object this one is mounted on, or nullptr.
  PhysicalObject* getConnection() const;
  /// The frame of getConnection() this one is attached to.
  std::string getConnectionFrame() const;

  /// Sets the pose relative to the world, or to the mounting frame if connected.
  /// @param[in] t  pose [m]
  /// @throws std::invalid_argument if `t` is not a rigid transform
  /// @throws anything the object's physicalSetupChanged() throws; the pose is then unchanged
  /// Real-time safe: no.
  void setTransform(const Transform& t);
  /// The pose set by setTransform() or rp.cfg [m]. Real-time safe: no.
  Transform getTransform() const;
  /// The pose of this object's base in the world [m]: getTransform() composed with the pose of
  /// the mounting frame (through the chain of connections, evaluated now).
  /// Real-time safe: no.
  Transform getWorldTransform() const;
  /// The world pose of one of this object's frames (those its 3D model names) [m]. The default
  /// knows only `base`, the pose of getWorldTransform(); classes with moving frames
  /// (manipulators) override it.
  /// @param[in] frame  frame name
  /// @throws std::invalid_argument if the object has no such frame
  /// Real-time safe: no.
  virtual Transform getFrameTransform(const std::string& frame) const;

  /// Locks the object into simulation mode (no hardware I/O).
  /// @throws anything the object's physicalSetupChanged() throws; the mode is then unchanged
  /// Real-time safe: no.
  void setSimulationModeOn();
  /// Uses the hardware (unless the platform runs with `-sim`).
  /// @throws anything the object's physicalSetupChanged() throws; the mode is then unchanged
  /// Real-time safe: no.
  void setSimulationModeOff();
  /// Whether the object simulates its hardware: its own setting if given (code or rp.cfg),
  /// otherwise the platform's (`-sim`/`-nosim`, default on); `-sim` forces it on.
  /// Real-time safe: yes.
  bool isSimulationModeOn() const;

  /// Hides the object in the Scene Viewer.
  void setDisplayOff() { setDisplayMode(DisplayMode::Off); }
  /// Shows the object with shaded surfaces.
  void setDisplaySolid() { setDisplayMode(DisplayMode::Solid); }
  /// Shows the object's edges only.
  void setDisplayWireframe() { setDisplayMode(DisplayMode::Wireframe); }
  /// Sets the display mode.
  /// @param[in] mode  the new mode
  void setDisplayMode(DisplayMode mode);
  /// The display mode (default Solid).
  DisplayMode getDisplayMode() const;

 protected:
  /// Called after setTransform(), setConnection(), clearConnection(), setSimulationModeOn() and
  /// setSimulationModeOff() changed the object: a class that built something from its pose or
  /// its simulation mode (a manipulator's model, its hardware connection) applies the change
  /// here. If it throws, the change is undone and the exception reaches the caller. The default
  /// does nothing. Not called from PhysicalObject's constructor (rp.cfg's settings are there
  /// before any derived part is built).
  virtual void physicalSetupChanged() {}

 private:
  template <typename Undo>
  void changed(const Undo& undo);  // calls physicalSetupChanged(); undo() and rethrow if it throws

  struct Impl;
  std::unique_ptr<Impl> pimpl_;
};

/// Base class of objects that are functions rather than things (trajectory generators, servo
/// controls); the symmetric counterpart of PhysicalObject, with nothing of its own.
class FunctionalObject : public RoboticObject {
 public:
  /// Creates the object (see RoboticObject::RoboticObject).
  /// @param[in] name  object name; empty for an automatic name
  explicit FunctionalObject(const std::string& name = "") : RoboticObject(name) {}
};

}  // namespace rp
