// MJCF of a standard-DH ManipulatorModel for MuJoCo (Debian's libmujoco-dev), shared by
// bench/simulation_bench and the MuJoCo cross-checks of the simulation tests.
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include "rp/model/Model.hpp"

namespace rp::test {

// MJCF for a standard-DH model: body k sits at frame k-1 and turns about its z axis; link k's
// inertia lives in frame k = Rz(q_k) M_k with M_k = Tz(d) Tx(a) Rx(alpha), so it is given at
// M_k * com with the rotated inertia tensor, and body k+1 is placed at M_k.
// With `damping` false the joints get no damping attribute (the benchmark then applies the viscous
// friction itself, explicitly). `frictionLoss`, if given, is each joint's dry friction [N m]
// (MuJoCo's frictionloss, the same on both sides).
inline std::string mjcf(const ManipulatorModel& model, bool damping = true,
                        const std::vector<double>& frictionLoss = {}) {
  std::ostringstream x;
  x.precision(17);
  // balanceinertia: the Puma's link 1 (Ixx = Izz = 0, Iyy = 0.35) breaks MuJoCo's triangle
  // inequality check; MuJoCo then adjusts that inertia (timing is unaffected).
  x << "<mujoco model=\"" << model.getName() << "\">\n<compiler balanceinertia=\"true\"/>\n"
    << "<option timestep=\"0.001\" integrator=\"Euler\" gravity=\"0 0 -9.81\"><flag contact=\"disable\"/></option>\n"
    << "<worldbody>\n";
  Transform parent = Transform::unit();  // pose of body k's frame in body k-1's frame
  const int n = model.getNumberOfJoints();
  for (int k = 0; k < n; ++k) {
    const LinkParameters& l = model.getLink(k);
    const Transform M = translation(0, 0, l.d) * translation(l.a, 0, 0) * xRotation(l.alpha);
    const Eigen::Quaterniond qp(Eigen::Matrix3d(parent.topLeftCorner<3, 3>()));
    x << "<body name=\"link" << k + 1 << "\" pos=\"" << parent(0, 3) << " " << parent(1, 3) << " " << parent(2, 3)
      << "\" quat=\"" << qp.w() << " " << qp.x() << " " << qp.y() << " " << qp.z() << "\">\n";
    const double G = l.gearRatio;
    x << "<joint name=\"j" << k + 1 << "\" type=\"hinge\" axis=\"0 0 1\" armature=\"" << G * G * l.motorInertia
      << "\" damping=\"" << (damping ? l.viscousFriction * G * G : 0.0) << "\" frictionloss=\""
      << (frictionLoss.empty() ? 0.0 : frictionLoss[static_cast<std::size_t>(k)]) << "\"/>\n";
    const Eigen::Vector3d c = M.topLeftCorner<3, 3>() * Eigen::Vector3d(l.com) + M.topRightCorner<3, 1>();
    const Eigen::Matrix3d I = M.topLeftCorner<3, 3>() * Eigen::Matrix3d(l.inertia) * M.topLeftCorner<3, 3>().transpose();
    const double mass = l.mass > 0 ? l.mass : 1e-6;  // MuJoCo needs mass on a moving body
    x << "<inertial pos=\"" << c(0) << " " << c(1) << " " << c(2) << "\" mass=\"" << mass << "\" fullinertia=\""
      << I(0, 0) + 1e-9 << " " << I(1, 1) + 1e-9 << " " << I(2, 2) + 1e-9 << " " << I(0, 1) << " " << I(0, 2) << " "
      << I(1, 2) << "\"/>\n";
    parent = M;
  }
  for (int k = 0; k < n; ++k) x << "</body>\n";
  x << "</worldbody>\n</mujoco>\n";
  return x.str();
}

}  // namespace rp::test
