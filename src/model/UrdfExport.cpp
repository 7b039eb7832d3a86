// URDF export of manipulator models (rp/model/UrdfExport.hpp).
#include "rp/model/UrdfExport.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "ExportFrames.hpp"
#include "ExportNames.hpp"
#include "rp/model/PhysicalModel.hpp"

namespace rp {

namespace {

using internal::exact;
using internal::xmlEscape;

std::string origin(const Transform& t) {
  const Vector<3> rpy = transformToRPY(t);
  return "<origin xyz=\"" + exact(t(0, 3)) + " " + exact(t(1, 3)) + " " + exact(t(2, 3)) + "\" rpy=\"" + exact(rpy(0)) +
         " " + exact(rpy(1)) + " " + exact(rpy(2)) + "\"/>";
}

}  // namespace

std::string toUrdf(const ManipulatorModel& model) {
  const PhysicalModel physical = physicalModel(model);
  const ManipulatorModel& m = physical.model;
  std::ostringstream x;
  const int n = model.getNumberOfJoints();
  x << "<?xml version=\"1.0\"?>\n<robot name=\"" << internal::xmlEscape(model.getName()) << "\" xmlns:drake=\"http://drake.mit.edu\">\n";
  x << "  <!-- Written by rp (toUrdf). URDF cannot carry everything the model has:\n"
       "       - motor inertia: each <transmission> gives the motor's inertia and gear ratio\n"
       "         (drake:rotor_inertia, drake:gear_ratio; Drake adds G^2 Jm to the joint), which plain URDF\n"
       "         readers (urdfdom, MuJoCo, rp's loadUrdf) ignore; the MJCF export carries it as armature;\n"
       "       - two-sided Coulomb friction: <dynamics friction> has one value, the mean of the two\n"
       "         magnitudes (a comment at each such joint gives both);\n"
       "       - acceleration and jerk limits.\n";
  if (!physical.corrections.empty()) {
    x << "       Inertial data changed so that simulators accept them (rp's physicalModel):\n"
      << internal::correctionLines(physical, "       ");
  }
  x << "  -->\n";
  const internal::ExportNames names = internal::exportNames(model);
  x << "  <link name=\"" << xmlEscape(names.world) << "\"/>\n  <link name=\"" << xmlEscape(names.base) << "\"/>\n";
  x << "  <joint name=\"" << xmlEscape(names.baseJoint) << "\" type=\"fixed\">\n    <parent link=\"" << xmlEscape(names.world)
    << "\"/>\n    <child link=\"" << xmlEscape(names.base) << "\"/>\n    " << origin(model.getBaseTransform())
    << "\n  </joint>\n";
  Transform previous = Transform::unit();  // post_{k-1}
  for (int k = 0; k < n; ++k) {
    const LinkParameters& l = m.getLink(k);
    const internal::JointFrames frames = internal::jointFrames(m, k);
    const internal::JointFriction friction = internal::jointFriction(l);
    const std::string link = xmlEscape(names.links[static_cast<std::size_t>(k)]);
    const std::string joint = xmlEscape(names.joints[static_cast<std::size_t>(k)]);
    const internal::PrincipalInertia principal = internal::principalInertia(l.inertia);
    Transform axes = Transform::unit();
    axes.topLeftCorner<3, 3>() = principal.axes;
    x << "  <link name=\"" << link << "\">\n    <inertial>\n      "
      << origin(Transform(frames.post * translation(l.com) * axes)) << "\n      <mass value=\"" << exact(l.mass)
      << "\"/>\n      <inertia ixx=\"" << exact(principal.moments(0)) << "\" ixy=\"0\" ixz=\"0\" iyy=\""
      << exact(principal.moments(1)) << "\" iyz=\"0\" izz=\"" << exact(principal.moments(2))
      << "\"/>\n    </inertial>\n  </link>\n";
    x << "  <joint name=\"" << joint << "\" type=\"" << (l.type == JointType::Prismatic ? "prismatic" : "revolute")
      << "\">\n    <parent link=\"" << xmlEscape(k == 0 ? names.base : names.links[static_cast<std::size_t>(k - 1)])
      << "\"/>\n    <child link=\"" << link << "\"/>\n    " << origin(Transform(previous * frames.pre))
      << "\n    <axis xyz=\"0 0 1\"/>\n    <limit lower=\"" << exact(l.positionMin) << "\" upper=\""
      << exact(l.positionMax) << "\" effort=\"" << exact(l.torqueLimit) << "\" velocity=\"" << exact(l.velocityLimit)
      << "\"/>\n    <dynamics damping=\"" << exact(l.viscousFriction * l.gearRatio * l.gearRatio) << "\" friction=\""
      << exact(friction.symmetric) << "\"/>\n";
    if (friction.positive != friction.negative) {
      x << "    <!-- Coulomb friction " << internal::brief(friction.positive) << " for positive and "
        << internal::brief(friction.negative) << " for negative motion; URDF has one value: their mean -->\n";
    }
    x << "  </joint>\n";
    if (l.motorInertia != 0 || l.gearRatio != 1) {
      x << "  <transmission name=\"" << joint << "_transmission\">\n"
        << "    <type>transmission_interface/SimpleTransmission</type>\n"
        << "    <joint name=\"" << joint << "\">\n"
        << "      <hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface>\n    </joint>\n"
        << "    <actuator name=\"" << joint << "_motor\">\n"
        << "      <mechanicalReduction>" << exact(l.gearRatio) << "</mechanicalReduction>\n"
        << "      <drake:rotor_inertia value=\"" << exact(l.motorInertia) << "\"/>\n"
        << "      <drake:gear_ratio value=\"" << exact(std::abs(l.gearRatio)) << "\"/>\n"
        << "    </actuator>\n    <!-- armature G^2 Jm = " << internal::brief(m.getArmatureInertia()(k)) << " at the joint -->\n"
        << "  </transmission>\n";
    }
    previous = frames.post;
  }
  const std::string tool = xmlEscape(names.tool);
  x << "  <link name=\"" << tool << "\"/>\n  <joint name=\"" << tool << "\" type=\"fixed\">\n    <parent link=\""
    << xmlEscape(names.links[static_cast<std::size_t>(n - 1)]) << "\"/>\n    <child link=\"" << tool << "\"/>\n    "
    << origin(Transform(previous * model.getToolTransform()))
    << "\n  </joint>\n</robot>\n";
  return x.str();
}

}  // namespace rp
