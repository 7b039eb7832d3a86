// Recursive Newton-Euler dynamics for standard-DH serial chains (rp/model/Dynamics.hpp).
//
// Link quantities live in link coordinates, as in Luh, Walker and Paul's formulation and the
// Robotics Toolbox's rne_dh: frame i sits at the distal end of link i and joint i turns about
// z_{i-1}; p*_i = (a_i, d_i sin alpha_i, d_i cos alpha_i) is the origin of frame i seen from frame
// i-1, in frame i.
#include "rp/model/Dynamics.hpp"

#include <cmath>

#include "rp/model/Kinematics.hpp"

namespace rp {

namespace {

using V3 = Eigen::Vector3d;

// The recursion itself, writing into `tau`. qd or qdd may be data.zero.
void rnea(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q, const JointVector& qd,
          const JointVector& qdd, bool gravity, bool motorInertia, bool friction, const Vector<6>* tipWrench,
          JointVector& tau) {
  const int n = data.n;
  const V3 z0(0, 0, 1);
  V3 w = V3::Zero(), wd = V3::Zero();
  // Base acceleration -g (in base coordinates) accounts for gravity.
  V3 vd = V3::Zero();
  if (gravity) vd = -(model.getBaseTransform().topLeftCorner<3, 3>().transpose() * model.getGravity());

  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const LinkParameters& l = model.getLink(i);
    const double theta = q(i) + l.offset;
    const double ct = std::cos(theta), st = std::sin(theta);
    const double ca = model.getCosAlpha()(i), sa = model.getSinAlpha()(i);
    Matrix<3, 3>& R = data.R[k];
    R(0, 0) = ct;
    R(0, 1) = -st * ca;
    R(0, 2) = st * sa;
    R(1, 0) = st;
    R(1, 1) = ct * ca;
    R(1, 2) = -ct * sa;
    R(2, 0) = 0;
    R(2, 1) = sa;
    R(2, 2) = ca;
    Vector<3>& ps = data.pstar[k];
    ps(0) = l.a;
    ps(1) = l.d * sa;
    ps(2) = l.d * ca;

    const Eigen::Matrix3d Rt = R.transpose();
    const V3 wPrev = w;
    w = Rt * (wPrev + z0 * qd(i));
    wd = Rt * (wd + z0 * qdd(i) + wPrev.cross(z0 * qd(i)));
    vd = wd.cross(ps) + w.cross(w.cross(ps)) + Rt * vd;
    const V3 vc = wd.cross(l.com) + w.cross(w.cross(l.com)) + vd;
    data.F[k] = l.mass * vc;
    data.N[k] = l.inertia * wd + w.cross(l.inertia * w);
  }

  V3 f = V3::Zero(), nn = V3::Zero();
  if (tipWrench != nullptr) {
    f = tipWrench->head<3>();
    nn = tipWrench->tail<3>();
  }
  for (int i = n - 1; i >= 0; --i) {
    const auto k = static_cast<std::size_t>(i);
    const LinkParameters& l = model.getLink(i);
    const V3& ps = data.pstar[k];
    if (i == n - 1) {
      nn = nn + ps.cross(f) + (ps + l.com).cross(data.F[k]) + data.N[k];
      f = f + data.F[k];
    } else {
      const Eigen::Matrix3d& Rn = data.R[k + 1];
      nn = Rn * (nn + (Rn.transpose() * ps).cross(f)) + (ps + l.com).cross(data.F[k]) + data.N[k];
      f = Rn * f + data.F[k];
    }
    // Joint axis z_{i-1} in frame i is the third row of R_i.
    double t = nn.dot(data.R[k].row(2).transpose());
    if (motorInertia) t += model.getArmatureInertia()(i) * qdd(i);
    if (friction) {
      const double g = std::abs(l.gearRatio);
      double coulomb = 0;
      if (qd(i) > 0) coulomb = l.coulombFrictionPositive;
      else if (qd(i) < 0) coulomb = l.coulombFrictionNegative;
      t += g * (l.viscousFriction * g * qd(i) + coulomb);
    }
    tau(i) = t;
  }
}

}  // namespace

const JointVector& inverseDynamics(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                                   const JointVector& qd, const JointVector& qdd, const DynamicsOptions& options) {
  rnea(model, data, q, qd, qdd, options.gravity, options.motorInertia, options.friction, &options.tipWrench, data.tau);
  return data.tau;
}

void gravityTorque(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q, JointVector& tau) {
  rnea(model, data, q, data.zero, data.zero, true, false, false, nullptr, tau);
}

void frictionTorque(const ManipulatorModel& model, const JointVector& qd, JointVector& tau) {
  for (int i = 0; i < model.getNumberOfJoints(); ++i) {
    const LinkParameters& l = model.getLink(i);
    const double g = std::abs(l.gearRatio);
    double coulomb = 0;
    if (qd(i) > 0) coulomb = l.coulombFrictionPositive;
    else if (qd(i) < 0) coulomb = l.coulombFrictionNegative;
    tau(i) = g * (l.viscousFriction * g * qd(i) + coulomb);
  }
}

void coriolisTorque(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q, const JointVector& qd,
                    JointVector& tau) {
  rnea(model, data, q, qd, data.zero, false, false, false, nullptr, tau);
}

const JointMatrix& massMatrix(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                              bool motorInertia) {
  // M = sum over links k of m_k Jv_k^T Jv_k + Jw_k^T I_k Jw_k, with the Jacobians of each link's
  // centre of mass in the world frame: column j <= k is (z_{j-1} x (c_k - p_{j-1}), z_{j-1}).
  forwardKinematics(model, data, q);
  const int n = data.n;
  data.massMatrix.setZero();
  const Transform& base = model.getBaseTransform();
  for (int k = 0; k < n; ++k) {
    const LinkParameters& l = model.getLink(k);
    const Transform& Tk = data.linkTransforms[static_cast<std::size_t>(k)];
    const Eigen::Matrix3d Rk = Tk.topLeftCorner<3, 3>();
    const V3 c = Rk * Eigen::Vector3d(l.com) + Tk.topRightCorner<3, 1>();
    const Eigen::Matrix3d I = Rk * Eigen::Matrix3d(l.inertia) * Rk.transpose();
    for (int j = 0; j <= k; ++j) {
      const Transform& before = j == 0 ? base : data.linkTransforms[static_cast<std::size_t>(j - 1)];
      const V3 z = before.block<3, 1>(0, 2);
      data.pstar[static_cast<std::size_t>(j)] = z.cross(c - V3(before.topRightCorner<3, 1>()));  // Jv column
      data.w[static_cast<std::size_t>(j)] = I * z;                                                // I z
    }
    for (int i = 0; i <= k; ++i) {
      const Transform& bi = i == 0 ? base : data.linkTransforms[static_cast<std::size_t>(i - 1)];
      const V3 zi = bi.block<3, 1>(0, 2);
      const V3& vi = data.pstar[static_cast<std::size_t>(i)];
      for (int j = 0; j <= i; ++j) {
        const double m = l.mass * vi.dot(data.pstar[static_cast<std::size_t>(j)]) + zi.dot(data.w[static_cast<std::size_t>(j)]);
        data.massMatrix(i, j) += m;
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    if (motorInertia) data.massMatrix(i, i) += model.getArmatureInertia()(i);
    for (int j = 0; j < i; ++j) data.massMatrix(j, i) = data.massMatrix(i, j);
  }
  return data.massMatrix;
}

const JointVector& forwardDynamics(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                                   const JointVector& qd, const JointVector& tau, const DynamicsOptions& options) {
  // qdd holds tau - h until it is solved in place (massMatrix() uses scratchTau).
  rnea(model, data, q, qd, data.zero, options.gravity, false, options.friction, &options.tipWrench, data.qdd);
  data.qdd = tau - data.qdd;
  massMatrix(model, data, q, options.motorInertia);
  data.ldlt.compute(data.massMatrix);
  data.ldlt.solveInPlace(data.qdd);
  return data.qdd;
}

}  // namespace rp
