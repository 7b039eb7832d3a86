// The user's gripper class and, next to its definition, its one registration line.
#include "UserGripper.hpp"

#include "rp/core/TypeDatabase.hpp"

namespace user {

UserGripper::UserGripper(const std::string& name) : rp::Gripper(rp::ClassSection(name, "UserGripper")) {
  if (const rp::ConfigSection* s = configSection(); s && s->has("port")) port_ = s->getWord("port");
  addCommand("Open Gripper", [this] { open(); });
  publishObject();
}

UserGripper::~UserGripper() { withdrawObject(); }

void UserGripper::declareSettings(rp::SettingSchema& schema) {
  rp::Gripper::declareSettings(schema);
  schema.addWord("port", "serial device");
}

}  // namespace user

RP_REGISTER_CLASS_AS(user::UserGripper, "UserGripper");
