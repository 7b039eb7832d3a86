// Recursive Newton-Euler dynamics for serial chains in standard or modified DH, with revolute and
// prismatic joints (rp/model/Dynamics.hpp).
//
// Link quantities live in link coordinates, as in Luh, Walker and Paul's formulation and the
// Robotics Toolbox's rne_dh / rne_mdh: R_i and p_i are the rotation and origin of frame i in frame
// i-1; s_i is joint i's axis in frame i ((0, sin alpha_i, cos alpha_i) in standard DH, z in
// modified DH). The linear acceleration of a frame origin is carried outward through a point on
// the joint axis, which is fixed in both links of a revolute joint: frame i-1's origin in standard
// DH, frame i's in modified DH. A prismatic joint adds its sliding and Coriolis terms.
#include "rp/model/Dynamics.hpp"

#include <cmath>

#include "ChainInternal.hpp"
#include "rp/model/Kinematics.hpp"

namespace rp {

namespace {

using V3 = Eigen::Vector3d;

// The recursion itself, writing into `tau`. qd or qdd may be data.zero.
void rnea(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q, const JointVector& qd,
          const JointVector& qdd, bool gravity, bool motorInertia, bool friction, const Vector<6>* tipWrench,
          JointVector& tau) {
  const int n = data.n;
  const bool standard = model.getConvention() == DHConvention::Standard;
  V3 w = V3::Zero(), wd = V3::Zero();
  // Base acceleration -g (in base coordinates) accounts for gravity.
  V3 vd = V3::Zero();
  if (gravity) vd = -(model.getBaseTransform().topLeftCorner<3, 3>().transpose() * model.getGravity());

  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const LinkParameters& l = model.getLink(i);
    Eigen::Matrix<double, 3, 4> A;
    internal::linkMatrix(model, i, q(i), A);
    Matrix<3, 3>& R = data.R[k];
    R = A.leftCols<3>();
    Vector<3>& p = data.pstar[k];  // origin of frame i in frame i-1
    p = A.col(3);
    const Eigen::Matrix3d Rt = R.transpose();
    const V3 s = standard ? V3(R.row(2).transpose()) : V3::UnitZ();
    if (l.type == JointType::Prismatic) {
      vd = Rt * (vd + wd.cross(p) + w.cross(w.cross(p)));
      w = Rt * w;
      wd = Rt * wd;
      vd += 2 * qd(i) * w.cross(s) + qdd(i) * s;
    } else if (standard) {
      // Through frame i-1's origin (on the axis): p* = R^T p is fixed in link i.
      const V3 wi = Rt * w;
      w = wi + s * qd(i);
      wd = Rt * wd + s * qdd(i) + wi.cross(s * qd(i));
      const V3 ps = Rt * p;
      vd = wd.cross(ps) + w.cross(w.cross(ps)) + Rt * vd;
    } else {
      // Through frame i's origin (on the axis), fixed in link i-1.
      vd = Rt * (vd + wd.cross(p) + w.cross(w.cross(p)));
      const V3 wi = Rt * w;
      w = wi + s * qd(i);
      wd = Rt * wd + s * qdd(i) + wi.cross(s * qd(i));
    }
    const V3 vc = wd.cross(l.com) + w.cross(w.cross(l.com)) + vd;
    data.F[k] = l.mass * vc;
    data.N[k] = l.inertia * wd + w.cross(l.inertia * w);
  }

  // f, nn: force and moment (about frame i's origin, in frame i) that link i-1 exerts on link i.
  V3 f = V3::Zero(), nn = V3::Zero();
  if (tipWrench != nullptr) {
    f = tipWrench->head<3>();
    nn = tipWrench->tail<3>();
  }
  for (int i = n - 1; i >= 0; --i) {
    const auto k = static_cast<std::size_t>(i);
    const LinkParameters& l = model.getLink(i);
    if (i == n - 1) {
      nn = nn + l.com.cross(data.F[k]) + data.N[k];
    } else {
      const Eigen::Matrix3d& Rn = data.R[k + 1];
      f = Rn * f;
      nn = Rn * nn + V3(data.pstar[k + 1]).cross(f) + l.com.cross(data.F[k]) + data.N[k];
    }
    f += data.F[k];
    const Eigen::Matrix3d& R = data.R[k];
    const V3 s = standard ? V3(R.row(2).transpose()) : V3::UnitZ();
    double t;
    if (l.type == JointType::Prismatic) {
      t = s.dot(f);
    } else if (standard) {
      // Moment about frame i-1's origin, which lies on the axis.
      t = s.dot(nn + V3(R.transpose() * data.pstar[k]).cross(f));
    } else {
      t = nn(2);
    }
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
  // centre of mass in the world frame: column j <= k is (z_j x (c_k - p_j), z_j) for a revolute
  // joint and (z_j, 0) for a prismatic one, z_j and p_j joint j's axis and a point on it.
  forwardKinematics(model, data, q);
  const int n = data.n;
  data.massMatrix.setZero();
  for (int k = 0; k < n; ++k) {
    const LinkParameters& l = model.getLink(k);
    const Transform& Tk = data.linkTransforms[static_cast<std::size_t>(k)];
    const Eigen::Matrix3d Rk = Tk.topLeftCorner<3, 3>();
    const V3 c = Rk * Eigen::Vector3d(l.com) + Tk.topRightCorner<3, 1>();
    const Eigen::Matrix3d I = Rk * Eigen::Matrix3d(l.inertia) * Rk.transpose();
    for (int j = 0; j <= k; ++j) {
      const auto jj = static_cast<std::size_t>(j);
      const Transform& axis = internal::axisFrame(model, data, j);
      const V3 z = axis.block<3, 1>(0, 2);
      if (model.isPrismatic(j)) {
        data.pstar[jj] = z;            // Jv column
        data.wd[jj].setZero();         // Jw column
      } else {
        data.pstar[jj] = z.cross(c - V3(axis.topRightCorner<3, 1>()));
        data.wd[jj] = z;
      }
      data.w[jj] = I * data.wd[jj];  // I Jw column
    }
    for (int i = 0; i <= k; ++i) {
      const V3& vi = data.pstar[static_cast<std::size_t>(i)];
      const V3& zi = data.wd[static_cast<std::size_t>(i)];
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
