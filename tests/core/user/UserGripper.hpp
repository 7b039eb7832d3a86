// A gripper class of a user's own program (the docs' MyGripper): defined and registered in the
// program's own files, not in the library.
#pragma once

#include <string>

#include "rp/effector/Gripper.hpp"

namespace user {

class UserGripper : public rp::Gripper {
 public:
  explicit UserGripper(const std::string& name = "");
  ~UserGripper() override;
  static void declareSettings(rp::SettingSchema& schema);
  const std::string& port() const { return port_; }
  int hardwareCalls() const { return hardwareCalls_; }

 protected:
  bool hardwareOpen() override { return ++hardwareCalls_ > 0; }
  bool hardwareClose() override { return ++hardwareCalls_ > 0; }
  bool hardwareRelax() override { return ++hardwareCalls_ > 0; }

 private:
  std::string port_ = "/dev/ttyS0";
  int hardwareCalls_ = 0;
};

}  // namespace user
