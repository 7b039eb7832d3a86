#pragma once
/// @file
/// A simulated work piece: a box a simulated gripper picks up and that falls when released.

#include <cstdint>
#include <memory>
#include <string>

#include "rp/core/PhysicalObject.hpp"

namespace rp {

/// A simulated work piece (the paper's Figure 21 picks one up): a solid box with a mass, drawn in
/// the Scene Viewer, that lies on a table. Its pose is that of its centre.
///
/// A closed Gripper whose fingers are around it holds it (see Gripper): it is attached to the
/// gripper's frame and moves with it, and its mass is the arm's payload. Released, it falls
/// freely under gravity (9.81 m/s^2 along -z) from where it was let go, starting at rest, until it
/// lies on the table: its centre is then half its height above `tableHeight` (its height being its
/// extent along z in the orientation it had; it keeps that orientation and does not topple). The
/// fall runs in a control loop of its own on the platform's clock (1 kHz; on the simulated clock
/// of `-simclock` it is deterministic): at each cycle time t the centre is
/// \f$z = z_0 - \frac12 g (t - t_0)^2\f$, \f$t_0\f$ the loop's first cycle (within one period
/// of the release), until that reaches the table.
///
/// rp.cfg settings (besides PhysicalObject's `position`, the centre, and `orientation`):
/// | setting | meaning | default |
/// |---|---|---|
/// | `mass M` | mass [kg] | 0.5 |
/// | `size X Y Z` | edge lengths [mm] | 40 40 40 |
/// | `tableHeight H` | height of the surface it falls onto [mm] | 0 |
class WorkPiece : public PhysicalObject {
 public:
  /// Gravity of the fall [m/s^2].
  static constexpr double kGravity = 9.81;

  /// Creates the work piece from its rp.cfg section, if any.
  /// @param[in] name  object name (rp.cfg section); empty for an automatic name
  /// @throws ConfigError if a setting is invalid
  /// Real-time safe: no.
  explicit WorkPiece(const std::string& name = "");
  /// Stops a fall under way.
  ~WorkPiece() override;

  /// Declares `mass`, `size` and `tableHeight`.
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);

  /// Sets the mass. @param[in] kg  mass [kg], > 0 @throws std::invalid_argument otherwise
  void setMass(double kg);
  /// The mass [kg].
  double getMass() const;
  /// Sets the edge lengths. @param[in] meters  x, y, z edges [m], each > 0
  /// @throws std::invalid_argument otherwise
  void setSize(const Vector<3>& meters);
  /// The edge lengths [m].
  Vector<3> getSize() const;
  /// Sets the height of the table it falls onto. @param[in] meters  height [m], finite
  /// @throws std::invalid_argument otherwise
  void setTableHeight(double meters);
  /// The height of the table [m].
  double getTableHeight() const;

  /// A box of the piece's size at its centre. Real-time safe: no.
  Model3D get3DModel() const override;

  /// Attaches the piece to `holder`'s base frame where it is now (a gripper grasping it); stops a
  /// fall under way. Real-time safe: no.
  /// @param[in] holder  the object that holds it (must outlive the attachment)
  void attachTo(PhysicalObject& holder);
  /// Lets the piece go where it is now: detached from its holder, it falls to the table.
  /// Real-time safe: no.
  void release();
  /// Whether the piece is falling. Real-time safe: no.
  bool isFalling() const;
  /// The last step of the last fall: consistent with each other, so that a test can check them.
  struct FallState {
    double time = 0;    ///< time since the fall's first cycle [s]
    double height = 0;  ///< height of the centre then [m]
    double from = 0;    ///< height of the centre where it was let go [m]
    bool landed = false;  ///< whether it lay on the table then
    std::uint64_t steps = 0;  ///< cycles of the fall so far (0: no fall yet)
  };
  /// The last step of the last fall. Real-time safe: no.
  FallState getFallState() const;
  /// Waits until a fall under way has ended.
  /// @param[in] timeoutSeconds  longest wait in real time [s]
  /// @return true if the piece is not falling
  bool waitUntilLanded(double timeoutSeconds = 60) const;
  /// The centre's height at rest on the table for `orientation`: table height plus half the
  /// piece's extent along z [m].
  /// @param[in] pose  a pose of the piece (its rotation counts)
  double restingHeight(const Transform& pose) const;

 private:
  class Fall;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rp
