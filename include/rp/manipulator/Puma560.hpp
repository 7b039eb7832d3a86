#pragma once
/// @file
/// The Puma 560 robot (paper section 3.3).

#include "rp/manipulator/DefaultManipulator.hpp"
#include "rp/model/Puma560Model.hpp"

namespace rp {

/// The Unimation Puma 560 with its Puma560Model (Robotics Toolbox parameters), a
/// DefaultPositionControl and gravity compensation on.
///
/// rp.cfg settings besides Table 1's: `pedestalHeight h` [m] (default 0.67183).
/// Example: `Puma560 puma;` creates it with an automatic name and starts its servo loop.
class Puma560 : public DefaultManipulator {
 public:
  /// Creates the robot and starts its servo loop.
  /// @param[in] name  object name (its rp.cfg section, if any); empty for an automatic name
  /// @throws ConfigError for a bad setting; std::runtime_error if simulation is off and no
  ///         hardware is configured
  explicit Puma560(const std::string& name = "");
  ~Puma560() override;
  /// Declares `pedestalHeight`.
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);

 protected:
  /// Creates the robot without starting its servo loop, for a class derived from Puma560: its
  /// constructor passes its own ClassSection and calls startControlLoop() last; its destructor
  /// calls stopControlLoop() first.
  /// @param[in] name  object name, with the derived class's ClassSection
  /// @throws ConfigError for a bad setting
  Puma560(const std::string& name, DerivedClass);
};

}  // namespace rp
