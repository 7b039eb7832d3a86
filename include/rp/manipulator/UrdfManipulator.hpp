#pragma once
/// @file
/// A manipulator described by a URDF file.

#include "rp/manipulator/DefaultManipulator.hpp"
#include "rp/model/UrdfModel.hpp"

#include <map>
#include <string>
#include <vector>

namespace rp {

/// Any serial arm from a URDF file (see loadUrdf()), with a DefaultPositionControl and gravity
/// compensation on, simulated from the file's inertias.
///
/// rp.cfg settings besides Table 1's: `urdf FILE` (relative paths are relative to the rp.cfg
/// file's folder), `tip LINK` (default: the last movable link of an unbranched chain),
/// `packagePath DIR[:DIR...]` (folders holding the packages of the URDF's `package://` mesh files,
/// searched before `ROS_PACKAGE_PATH`; relative folders are relative to the rp.cfg file's folder)
/// and `offChainPositions JOINT=VALUE ...` (where moving joints off the chain, such as fingers or a
/// jaw, stand when their links are lumped into the arm and drawn: UrdfOptions::offChainPositions in
/// rp.cfg's units, degrees for revolute and millimetres for prismatic joints; a word that is no
/// such pair, a joint the description has no moving joint off the chain of, or a value outside the
/// joint's limits is a ConfigError at the setting's line).
class UrdfManipulator : public DefaultManipulator {
 public:
  /// Creates the arm and starts its servo loop.
  /// @param[in] name      object name (its rp.cfg section, if any); empty for an automatic name
  /// @param[in] urdfFile  URDF path; rp.cfg's `urdf` setting overrides it
  /// @param[in] tip       tip link; rp.cfg's `tip` setting overrides it
  /// @throws UrdfError for a bad file (from rp.cfg: its `urdf` or `tip` line first); no file: ConfigError (an rp.cfg section), else std::invalid_argument
  explicit UrdfManipulator(const std::string& name = "", const std::string& urdfFile = "", const std::string& tip = "");
  ~UrdfManipulator() override;
  /// Declares `urdf`, `tip`, `packagePath` and `offChainPositions`.
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);
  /// The URDF file the arm was loaded from (after rp.cfg's `urdf` setting, relative paths
  /// resolved against the rp.cfg file's folder). The Scene Viewer draws its `<visual>` elements.
  const std::string& getUrdfFile() const { return urdfFile_; }
  /// The tip link asked for (rp.cfg's `tip` or the constructor's); empty for the default.
  const std::string& getTip() const { return tip_; }
  /// The folders of rp.cfg's `packagePath` setting (absolute; empty without the setting), where
  /// the Scene Viewer looks first for the URDF's `package://` mesh files (see resolveMeshUri()).
  std::vector<std::string> getPackagePath() const;
  /// rp.cfg's `offChainPositions` by joint name, in its units (deg, or mm for a prismatic joint;
  /// UrdfOptions::offChainInDegreesAndMillimetres); empty without the setting. The Scene Viewer
  /// draws the links off the chain where these put them.
  std::map<std::string, double> getOffChainPositions() const;

 private:
  std::string urdfFile_, tip_;
};

}  // namespace rp
