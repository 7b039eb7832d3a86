#pragma once
/// @file
/// Homogeneous transformations and the transformation functions of Table 2: translation,
/// rotations about x, y, z and an arbitrary axis, Euler (ZYZ) and roll-pitch-yaw angles.

#include <string>

#include "rp/math/Matrix.hpp"

namespace rp {

/// A 4x4 homogeneous transformation \f$\begin{pmatrix} R & p \\ 0 & 1 \end{pmatrix}\f$:
/// rotation `R` (3x3, orthonormal) and translation `p` [m]. All Matrix operations apply;
/// `t.getColumn(4)` is the homogeneous position \f$(p, 1)\f$.
using Transform = Matrix<4, 4, double>;

/// A pure translation by (`x`, `y`, `z`) [m]. Real-time safe: yes.
Transform translation(double x, double y, double z);
/// A pure translation by `p` [m]. Real-time safe: yes.
Transform translation(const Vector<3>& p);

/// A rotation by `angle` [rad] about the x axis (right-handed). Real-time safe: yes.
Transform xRotation(double angle);
/// A rotation by `angle` [rad] about the y axis (right-handed). Real-time safe: yes.
Transform yRotation(double angle);
/// A rotation by `angle` [rad] about the z axis (right-handed). Real-time safe: yes.
Transform zRotation(double angle);
/// A rotation by `angle` [rad] about the axis through the origin along `axis` (any length > 0).
/// @throws MathException if `axis` has zero length. Real-time safe: yes (throws only on bad input).
Transform rotation(const Vector<3>& axis, double angle);

/// The rotation of Euler angles in the ZYZ convention:
/// \f$R = R_z(\phi) R_y(\theta) R_z(\psi)\f$ (angles in [rad]). Real-time safe: yes.
Transform eulerToTransform(double phi, double theta, double psi);
/// Euler angles (ZYZ) of the rotation part of `t`: returns \f$(\phi, \theta, \psi)\f$ [rad] with
/// \f$\theta \in [0, \pi]\f$ and \f$\phi, \psi \in (-\pi, \pi]\f$.
///
/// Singular cases: when \f$\theta = 0\f$ only \f$\phi + \psi\f$ is defined, and when
/// \f$\theta = \pi\f$ only \f$\psi - \phi\f$ is; both return \f$\phi = 0\f$ and put the whole
/// rotation about z into \f$\psi\f$. `eulerToTransform` of the result always gives back `t`'s
/// rotation. Real-time safe: yes.
Vector<3> transformToEuler(const Transform& t);

/// The rotation of roll `r`, pitch `p` and yaw `y` [rad] about the fixed x, y and z axes:
/// \f$R = R_z(y) R_y(p) R_x(r)\f$ (the convention of rp.cfg's `orientation r p y`).
/// Real-time safe: yes.
Transform rpyToTransform(double r, double p, double y);
/// Roll, pitch and yaw (as `rpyToTransform` takes them) of the rotation part of `t` [rad], with
/// \f$p \in [-\pi/2, \pi/2]\f$ and \f$r, y \in (-\pi, \pi]\f$.
///
/// Singular case: at \f$p = \pm\pi/2\f$ only \f$y \mp r\f$ is defined; then \f$r = 0\f$ is
/// returned and the whole rotation about the vertical goes into \f$y\f$. `rpyToTransform` of the
/// result always gives back `t`'s rotation. Real-time safe: yes.
Vector<3> transformToRPY(const Transform& t);

/// The translation part \f$p\f$ of `t` [m]. Real-time safe: yes.
Vector<3> getPosition(const Transform& t);
/// The rotation part \f$R\f$ of `t`. Real-time safe: yes.
Matrix<3, 3> getRotation(const Transform& t);
/// A transform from a rotation `R` (orthonormal) and a translation `p` [m]. Real-time safe: yes.
Transform makeTransform(const Matrix<3, 3>& R, const Vector<3>& p);
/// The inverse of a rigid transform, \f$(R^T, -R^T p)\f$: faster and more exact than the general
/// inverse; `t`'s rotation must be orthonormal. Real-time safe: yes.
Transform rigidInverse(const Transform& t);
/// `t` applied to the point `p` [m]: \f$R p + p_t\f$. Real-time safe: yes.
inline Vector<3> transformPoint(const Transform& t, const Vector<3>& p) {
  return Vector<3>(t.topLeftCorner<3, 3>() * p + t.topRightCorner<3, 1>());
}

/// Largest deviation accepted by rigidTransformError(): of \f$R^T R\f$ from the identity (each
/// element), enough for a rotation typed with three or four decimals.
constexpr double kRigidTransformTolerance = 1e-3;

/// Checks that `pose` is a rigid transform: every element finite, the last row exactly
/// `0 0 0 1`, and the rotation block a proper rotation (\f$R^T R = I\f$ within `tolerance` for
/// each element, \f$\det R > 0\f$).
/// @param[in] pose       the 4 x 4 matrix to check
/// @param[in] tolerance  largest deviation of \f$R^T R\f$ from the identity accepted
/// @return an empty string if it is one, else what is wrong (e.g. `its rotation block is not
///         orthonormal (R^T R differs from I by 3)`), to follow a description of the pose
/// Real-time safe: only when it returns an empty string.
std::string rigidTransformError(const Transform& pose, double tolerance = kRigidTransformTolerance);

}  // namespace rp
