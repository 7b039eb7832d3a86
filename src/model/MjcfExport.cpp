// MJCF export of manipulator models (rp/model/MjcfExport.hpp).
#include "rp/model/MjcfExport.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "ExportFrames.hpp"
#include "ExportNames.hpp"
#include "rp/model/PhysicalModel.hpp"

namespace rp {

namespace {

using internal::exact;
using internal::xmlEscape;

std::string quaternion(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  return exact(q.w()) + " " + exact(q.x()) + " " + exact(q.y()) + " " + exact(q.z());
}

// pos="..." quat="..." of a transform.
std::string placement(const Transform& t) {
  return "pos=\"" + exact(t(0, 3)) + " " + exact(t(1, 3)) + " " + exact(t(2, 3)) + "\" quat=\"" +
         quaternion(Eigen::Matrix3d(t.topLeftCorner<3, 3>())) + "\"";
}

// <inertial> of a link whose centre of mass and inertia (about it) are given in link frame k,
// written in body coordinates (frame k = body * post) and in principal axes.
std::string inertial(const LinkParameters& l, const Transform& post) {
  const Eigen::Matrix3d R = post.topLeftCorner<3, 3>();
  const Eigen::Vector3d c = R * Eigen::Vector3d(l.com) + Eigen::Vector3d(post.topRightCorner<3, 1>());
  const internal::PrincipalInertia principal = internal::principalInertia(l.inertia);
  const Eigen::Vector3d& moments = principal.moments;
  return "<inertial pos=\"" + exact(c(0)) + " " + exact(c(1)) + " " + exact(c(2)) + "\" quat=\"" +
         quaternion(R * principal.axes) + "\" mass=\"" + exact(l.mass) + "\" diaginertia=\"" + exact(moments(0)) + " " +
         exact(moments(1)) + " " + exact(moments(2)) + "\"/>";
}

}  // namespace

std::string exportMjcf(const ManipulatorModel& model, const MjcfOptions& options) {
  if (!(options.timestep > 0) || !std::isfinite(options.timestep)) {
    throw std::invalid_argument("exportMjcf: the time step must be a positive finite number of seconds");
  }
  if (options.integrator != "Euler" && options.integrator != "RK4" && options.integrator != "implicit") {
    throw std::invalid_argument("exportMjcf: unknown integrator '" + options.integrator + "' (Euler, RK4 or implicit)");
  }
  const int n = model.getNumberOfJoints();
  double totalMass = 0;
  for (int k = 0; k < n; ++k) totalMass += model.getLink(k).mass;
  if (!(totalMass > 0)) {
    throw std::invalid_argument("exportMjcf: model '" + model.getName() +
                                "' has no mass (kinematics only); MuJoCo needs the inertial data of every moving link");
  }
  const PhysicalModel physical = physicalModel(model);
  const ManipulatorModel& m = physical.model;
  std::ostringstream x;
  x << "<mujoco model=\"" << internal::xmlEscape(model.getName()) << "\">\n";
  x << "  <!-- Written by rp (exportMjcf). Joints carry the model's range, armature G^2 Jm, damping B G^2 and\n"
       "       friction loss |G| Tc (one value for both directions: the mean where the model's two differ, see\n"
       "       the comment at the joint). Velocity, acceleration and jerk limits are not carried.\n";
  if (!physical.corrections.empty()) {
    x << "       Inertial data changed so that simulators accept them (rp's physicalModel):\n"
      << internal::correctionLines(physical, "       ");
  }
  x << "  -->\n";
  x << "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n";
  const Vector<3>& g = model.getGravity();
  x << "  <option timestep=\"" << exact(options.timestep) << "\" integrator=\"" << options.integrator
    << "\" gravity=\"" << exact(g(0)) << " " << exact(g(1)) << " " << exact(g(2)) << "\"/>\n";
  x << "  <worldbody>\n";
  std::string indent = "    ";
  const internal::ExportNames names = internal::exportNames(model);
  x << indent << "<body name=\"" << xmlEscape(names.base) << "\" " << placement(model.getBaseTransform()) << ">\n";
  Transform previous = Transform::unit();  // post_{k-1}
  for (int k = 0; k < n; ++k) {
    indent += "  ";
    const LinkParameters& l = m.getLink(k);
    const internal::JointFrames frames = internal::jointFrames(m, k);
    const internal::JointFriction friction = internal::jointFriction(l);
    x << indent << "<body name=\"" << xmlEscape(names.links[static_cast<std::size_t>(k)]) << "\" "
      << placement(Transform(previous * frames.pre)) << ">\n";
    x << indent << "  <joint name=\"" << xmlEscape(names.joints[static_cast<std::size_t>(k)]) << "\" type=\""
      << (l.type == JointType::Prismatic ? "slide" : "hinge") << "\" axis=\"0 0 1\" limited=\"true\" range=\""
      << exact(l.positionMin) << " " << exact(l.positionMax) << "\" armature=\"" << exact(m.getArmatureInertia()(k))
      << "\" damping=\"" << exact(l.viscousFriction * l.gearRatio * l.gearRatio) << "\" frictionloss=\""
      << exact(friction.symmetric) << "\"/>\n";
    if (friction.positive != friction.negative) {
      x << indent << "  <!-- Coulomb friction " << internal::brief(friction.positive) << " for positive and "
        << internal::brief(friction.negative) << " for negative motion; MuJoCo has one value: their mean -->\n";
    }
    x << indent << "  " << inertial(l, frames.post) << "\n";
    previous = frames.post;
  }
  x << indent << "  <site name=\"" << xmlEscape(names.tool) << "\" " << placement(Transform(previous * model.getToolTransform())) << "/>\n";
  for (int k = n; k >= 0; --k) {
    x << indent << "</body>\n";
    indent.resize(indent.size() - 2);
  }
  x << "  </worldbody>\n  <actuator>\n";
  for (int k = 0; k < n; ++k) {
    const double limit = m.getTorqueLimit()(k);
    x << "    <motor name=\"motor" << k + 1 << "\" joint=\"" << xmlEscape(names.joints[static_cast<std::size_t>(k)])
      << "\" ctrllimited=\"true\" ctrlrange=\"" << exact(-limit) << " " << exact(limit) << "\"/>\n";
  }
  x << "  </actuator>\n  <keyframe>\n    <key name=\"home\" qpos=\"";
  for (int k = 0; k < n; ++k) x << (k ? " " : "") << exact(model.getHomePosition()(k));
  x << "\"/>\n  </keyframe>\n</mujoco>\n";
  return x.str();
}

}  // namespace rp
