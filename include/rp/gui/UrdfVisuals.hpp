#pragma once
/// @file
/// The `<visual>` elements of a URDF arm as shapes of its 3D model (drawn by the Scene Viewer).

#include <map>
#include <string>
#include <vector>

#include "rp/core/PhysicalObject.hpp"

namespace rp {

/// Where readUrdfVisuals() looks and which chain it follows.
struct UrdfVisualOptions {
  /// Tip link, as UrdfOptions::tip (empty: the last movable link of an unbranched chain).
  std::string tip;
  /// Folders searched for `package://PKG/...` mesh files, in order, each holding package folders
  /// (the `ROS_PACKAGE_PATH` convention: PKG is the folder `DIR/PKG`, or a folder of that name
  /// deeper down, see resolveMeshUri()). The environment variable `ROS_PACKAGE_PATH` and the
  /// folders above the description are searched after these.
  std::vector<std::string> packagePath;
  /// Where moving joints off the chain stand, as UrdfOptions::offChainPositions (checked the same
  /// way; a UrdfOptionError for a bad entry): their links are drawn where loadUrdf() lumps them.
  std::map<std::string, double> offChainPositions;
  /// Whether offChainPositions are in degrees and millimetres, as
  /// UrdfOptions::offChainInDegreesAndMillimetres.
  bool offChainInDegreesAndMillimetres = false;
};

/// One `<visual>` element of a URDF link as the Scene Viewer draws it.
struct UrdfVisual {
  /// The visual as a shape in its model frame; a mesh's `meshFile` is the absolute path of the
  /// file found, or empty when none was (see meshError).
  Shape shape;
  std::string link;       ///< name of the URDF link the visual belongs to
  std::string meshUri;    ///< a mesh's file name as the URDF gives it (empty for other shapes)
  std::string meshError;  ///< why the mesh cannot be drawn (no such file, format not drawn); empty if fine
  /// The image file of the visual's material `<texture filename>` (absolute path of a PNG or
  /// JPEG file found as mesh files are); empty without a texture or when it cannot be used.
  std::string textureFile;
  std::string textureUri;    ///< the texture's file name as the URDF gives it (empty: none)
  std::string textureError;  ///< why the texture cannot be drawn (no such file, not PNG/JPEG); empty if fine
  /// The link's `<collision>` elements in the same frame (meshes resolved as the visuals; a mesh
  /// not found is left out): what is drawn instead of a mesh that cannot be.
  std::vector<Shape> collision;
};

/// Reads the `<visual>` elements of the links of a URDF arm and returns them as shapes attached
/// to the frames of the manipulator model loadUrdf() makes of the same file and tip: a link
/// before the first movable joint goes to frame `base`, a link after the k-th movable joint of
/// the chain (including links fixed to it) to frame `linkk` (with mimic joints on the chain: the
/// k-th chain joint's frame `chaink`), with the constant pose of the visual in that frame. Links
/// moved by joints off the chain (fingers, a jaw) go to the frame of the chain link they hang on,
/// at the configuration where loadUrdf() lumps them: `options.offChainPositions`, else zero within
/// the joint's limits, a mimic joint following its master.
/// Boxes, cylinders (along z, as in URDF), spheres and meshes (scaled by `scale`) keep their
/// sizes; mesh file names are resolved by resolveMeshUri(). Colours come from the visual's
/// material or the robot's material of that name (default grey).
/// @param[in] urdfFile  path of the URDF file
/// @param[in] options   tip link, package path and the positions of joints off the chain
/// @return the visuals in file order (empty if the file has none)
/// @throws UrdfError naming the file, as loadUrdf()
/// Real-time safe: no.
std::vector<UrdfVisual> readUrdfVisuals(const std::string& urdfFile, const UrdfVisualOptions& options = {});

/// The shapes of readUrdfVisuals() with the given tip and the default package path (a mesh not
/// found has an empty `meshFile`).
/// @param[in] urdfFile  path of the URDF file
/// @param[in] tip       tip link, as UrdfOptions::tip (empty: the last movable link of an unbranched chain)
/// @return the shapes (empty if the file has no visuals)
/// @throws UrdfError naming the file, as loadUrdf()
/// Real-time safe: no.
std::vector<Shape> loadUrdfVisuals(const std::string& urdfFile, const std::string& tip = "");

/// The file a URDF mesh file name names, which must exist as a regular file:
/// - `http://` and `https://` URLs are returned as they are (the page loads them itself);
/// - `file://PATH` and plain paths (relative to the URDF file's folder) as the absolute path;
/// - `package://PKG/REST` is looked up as `DIR/PKG/REST` for each DIR of `packagePath`, then of the
///   environment variable `ROS_PACKAGE_PATH` (colon-separated), then among the folders above the
///   URDF file (a folder named PKG, or a folder holding a folder PKG); the first file that exists wins.
/// @param[in] uri          the `filename` of a URDF `<mesh>`
/// @param[in] urdfFile     path of the URDF file
/// @param[in] packagePath  folders searched first for `package://` names
/// @param[out] searched    if not null, the places looked at, for an error message
/// @return the absolute path (or URL); empty if no such file was found
/// Real-time safe: no.
std::string resolveMeshUri(const std::string& uri, const std::string& urdfFile,
                           const std::vector<std::string>& packagePath, std::string* searched = nullptr);

/// Splits a colon-separated folder list (`ROS_PACKAGE_PATH`, rp.cfg `packagePath`) into folders,
/// relative ones made absolute against `base`; empty entries are skipped.
/// @param[in] list  folders separated by ':'
/// @param[in] base  folder relative entries are relative to (empty: the working directory)
/// @return the folders
std::vector<std::string> splitPackagePath(const std::string& list, const std::string& base = "");

}  // namespace rp
