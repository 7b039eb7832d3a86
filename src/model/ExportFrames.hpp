#pragma once
// Shared by the URDF and MJCF exports: how a link transform splits around its joint's motion, and
// the comments that say what a format cannot carry. Internal to the library.

#include <string>

#include "rp/model/ManipulatorModel.hpp"
#include "rp/model/PhysicalModel.hpp"

namespace rp::internal {

// A_k = pre_k J(q_k) post_k with J a rotation about (or a translation along) z. Standard DH:
// pre = Rz(offset) Tz(d), post = Tx(a) Rx(alpha); modified DH: pre = Rx(alpha) Tx(a) Rz(offset)
// Tz(d), post = 1. The exported link k frame is the joint frame after the motion J, joint k sits
// at post_{k-1} pre_k in link k-1, and link k's inertial data are given at post_k.
struct JointFrames {
  Transform pre, post;
};
JointFrames jointFrames(const ManipulatorModel& model, int k);

// Joint-side Coulomb friction |G| Tc for positive and negative motion (both >= 0), and the one
// symmetric value the formats carry (their mean).
struct JointFriction {
  double positive = 0, negative = 0, symmetric = 0;
};
JointFriction jointFriction(const LinkParameters& l);

// An inertia tensor in principal axes: I = axes diag(moments) axes^T, axes a rotation. A diagonal
// tensor keeps its axes (identity) and order, so that the files stay readable; any other is
// diagonalised here, once, so that readers do not (MuJoCo's own diagonalisation of a full tensor
// is accurate to about 1e-8 only).
struct PrincipalInertia {
  Eigen::Matrix3d axes;
  Eigen::Vector3d moments;
};
PrincipalInertia principalInertia(const Matrix<3, 3>& inertia);

// "%.17g": every double written round-trips exactly.
std::string exact(double x);
// Text as an XML attribute value: & < > " ' escaped (a URDF robot's name may hold any of them).
std::string xmlEscape(const std::string& text);

// "%.6g", for comments.
std::string brief(double x);

// XML comment lines (without the comment markers) listing the corrections of physicalModel().
std::string correctionLines(const PhysicalModel& physical, const std::string& indent);

}  // namespace rp::internal
