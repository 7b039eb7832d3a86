#pragma once
/// @file
/// The Barrett arm as the paper's section 3.6 names it among the manipulators that generic code
/// creates by name (`Puma560`, `BarrettArm` or `WAM`).

#include "rp/manipulator/WAM.hpp"

namespace rp {

/// The Barrett Whole Arm Manipulator under the name `BarrettArm` (paper section 3.6): a WAM in
/// its 4-link (WAM4Model) or 7-link (WAM7Model) configuration, chosen by rp.cfg's `links 4|7`,
/// driven through the Manipulator interface like any other arm (a DefaultPositionControl,
/// gravity compensation on, simulated unless rp.cfg wires it to a hardware server).
///
/// rp.cfg settings: the WAM's (`links 4|7`, default 7, besides Table 1's and the simulation's).
/// @code
/// [leader]
/// class BarrettArm
/// links 4
/// @endcode
class BarrettArm : public WAM {
 public:
  /// Creates the robot and starts its servo loop.
  /// @param[in] name   object name (its rp.cfg section, if any); empty for an automatic name
  ///                   (then configured from a `[BarrettArm]` class section, if any)
  /// @param[in] links  4 or 7; rp.cfg's `links` setting overrides it
  /// @throws std::invalid_argument for another number of links; ConfigError for a bad setting
  /// Real-time safe: no.
  explicit BarrettArm(const std::string& name = "", int links = 7);
  /// Brings a moving arm to rest, then stops the servo loop.
  ~BarrettArm() override;
};

}  // namespace rp
