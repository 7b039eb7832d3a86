// Shared by the URDF model tests: a description parsed with urdfdom itself, and its poses as
// Transforms, to build the independent references (KDL chains) from the file as written.
#pragma once

#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>

#include <fstream>
#include <sstream>
#include <string>

#include "rp/math/Transform.hpp"

namespace rp::test {

inline Transform pose(const urdf::Pose& p) {
  Transform t = Transform::unit();
  t.topLeftCorner<3, 3>() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).toRotationMatrix();
  t(0, 3) = p.position.x;
  t(1, 3) = p.position.y;
  t(2, 3) = p.position.z;
  return t;
}

inline urdf::ModelInterfaceSharedPtr parse(const std::string& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return urdf::parseURDF(s.str());
}

}  // namespace rp::test
