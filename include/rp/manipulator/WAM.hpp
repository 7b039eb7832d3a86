#pragma once
/// @file
/// The Barrett Whole Arm Manipulator, 4- or 7-link (paper section 3.3).

#include "rp/manipulator/DefaultManipulator.hpp"
#include "rp/model/WAMModel.hpp"

namespace rp {

/// The Barrett WAM in its 7-link (WAM7Model) or 4-link (WAM4Model) configuration, with a
/// DefaultPositionControl and gravity compensation on.
///
/// rp.cfg settings besides Table 1's: `links 4|7` (default 7).
class WAM : public DefaultManipulator {
 public:
  /// Creates the robot and starts its servo loop.
  /// @param[in] name   object name (its rp.cfg section, if any); empty for an automatic name
  /// @param[in] links  4 or 7; rp.cfg's `links` setting overrides it
  /// @throws std::invalid_argument for another number of links; ConfigError for a bad setting
  explicit WAM(const std::string& name = "", int links = 7);
  ~WAM() override;
  /// Declares `links`.
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);

 protected:
  /// Creates the robot without starting its servo loop: the derived class's constructor calls
  /// startControlLoop() last (see BarrettArm).
  /// @param[in] name   object name, with the derived class's ClassSection
  /// @param[in] links  4 or 7; rp.cfg's `links` setting overrides it
  /// @throws std::invalid_argument for another number of links; ConfigError for a bad setting
  WAM(const std::string& name, int links, DerivedClass);
};

}  // namespace rp
