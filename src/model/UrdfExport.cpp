// URDF export of manipulator models (rp/model/UrdfExport.hpp).
#include "rp/model/UrdfExport.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace rp {

namespace {

std::string origin(const Transform& t) {
  const Vector<3> rpy = transformToRPY(t);
  char buf[256];
  std::snprintf(buf, sizeof buf, "<origin xyz=\"%.17g %.17g %.17g\" rpy=\"%.17g %.17g %.17g\"/>", t(0, 3), t(1, 3),
                t(2, 3), rpy(0), rpy(1), rpy(2));
  return buf;
}

}  // namespace

std::string toUrdf(const ManipulatorModel& model) {
  std::ostringstream x;
  x.precision(17);
  const int n = model.getNumberOfJoints();
  x << "<?xml version=\"1.0\"?>\n<robot name=\"" << model.getName() << "\">\n";
  x << "  <link name=\"world\"/>\n  <link name=\"base_link\"/>\n";
  x << "  <joint name=\"base\" type=\"fixed\">\n    <parent link=\"world\"/>\n    <child link=\"base_link\"/>\n    "
    << origin(model.getBaseTransform()) << "\n  </joint>\n";
  // A_k = Pre_k Joint(q_k) Post_k: the URDF link k frame is the joint frame after the motion,
  // joint k sits at Post_{k-1} Pre_k in link k-1, link k's inertia at Post_k com.
  Transform previous = Transform::unit();  // Post_{k-1}
  const bool standard = model.getConvention() == DHConvention::Standard;
  for (int k = 0; k < n; ++k) {
    const LinkParameters& l = model.getLink(k);
    const Transform fixed = zRotation(l.offset) * translation(0, 0, l.d);
    const Transform pre = standard ? fixed : model.getPlacement(k);
    const Transform post = standard ? Transform(translation(l.a, 0, 0) * xRotation(l.alpha)) : Transform::unit();
    const std::string link = "link" + std::to_string(k + 1);
    x << "  <link name=\"" << link << "\">\n    <inertial>\n      " << origin(Transform(post * translation(l.com)))
      << "\n      <mass value=\"" << l.mass << "\"/>\n      <inertia ixx=\"" << l.inertia(0, 0) << "\" ixy=\""
      << l.inertia(0, 1) << "\" ixz=\"" << l.inertia(0, 2) << "\" iyy=\"" << l.inertia(1, 1) << "\" iyz=\""
      << l.inertia(1, 2) << "\" izz=\"" << l.inertia(2, 2) << "\"/>\n    </inertial>\n  </link>\n";
    x << "  <joint name=\"joint" << k + 1 << "\" type=\"" << (l.type == JointType::Prismatic ? "prismatic" : "revolute")
      << "\">\n    <parent link=\"" << (k == 0 ? std::string("base_link") : "link" + std::to_string(k))
      << "\"/>\n    <child link=\"" << link << "\"/>\n    " << origin(Transform(previous * pre))
      << "\n    <axis xyz=\"0 0 1\"/>\n    <limit lower=\"" << l.positionMin << "\" upper=\"" << l.positionMax
      << "\" effort=\"" << l.torqueLimit << "\" velocity=\"" << l.velocityLimit << "\"/>\n    <dynamics damping=\""
      << l.viscousFriction * l.gearRatio * l.gearRatio << "\" friction=\""
      << std::abs(l.gearRatio) * 0.5 * (l.coulombFrictionPositive - l.coulombFrictionNegative) << "\"/>\n  </joint>\n";
    previous = post;
  }
  x << "  <link name=\"tool\"/>\n  <joint name=\"tool\" type=\"fixed\">\n    <parent link=\"link" << n
    << "\"/>\n    <child link=\"tool\"/>\n    " << origin(Transform(previous * model.getToolTransform()))
    << "\n  </joint>\n</robot>\n";
  return x.str();
}

}  // namespace rp
