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

// Joint-side friction B G^2 qd + |G| Tc(sign qd) (zero Coulomb part at rest).
double jointFriction(const LinkParameters& l, double qd) {
  const double g = std::abs(l.gearRatio);
  double coulomb = 0;
  if (qd > 0) coulomb = l.coulombFrictionPositive;
  else if (qd < 0) coulomb = l.coulombFrictionNegative;
  return g * (l.viscousFriction * g * qd + coulomb);
}

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
    if (friction) t += jointFriction(l, qd(i));
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
    tau(i) = jointFriction(model.getLink(i), qd(i));
  }
}

void coriolisTorque(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q, const JointVector& qd,
                    JointVector& tau) {
  rnea(model, data, q, qd, data.zero, false, false, false, nullptr, tau);
}

namespace {

using V6 = Eigen::Matrix<double, 6, 1>;
using M6 = Eigen::Matrix<double, 6, 6>;

Eigen::Matrix3d skew(const V3& v) {
  Eigen::Matrix3d m;
  m << 0, -v(2), v(1), v(2), 0, -v(0), -v(1), v(0), 0;
  return m;
}

// Forward kinematics from the link transforms A_i = (data.R, data.pstar) of the last Newton-Euler
// pass: data.linkTransforms and data.endEffector, as forwardKinematics() would give them.
void composeLinkTransforms(const ManipulatorModel& model, ManipulatorData& data) {
  const Transform* previous = &model.getBaseTransform();
  for (int i = 0; i < data.n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    Transform& T = data.linkTransforms[k];
    T.topLeftCorner<3, 3>().noalias() = previous->topLeftCorner<3, 3>() * data.R[k];
    T.topRightCorner<3, 1>() = previous->topLeftCorner<3, 3>() * data.pstar[k] + previous->topRightCorner<3, 1>();
    T.row(3) << 0, 0, 0, 1;
    previous = &T;
  }
  const Transform& tool = model.getToolTransform();
  data.endEffector.topRows<3>().noalias() = previous->topLeftCorner<3, 3>() * tool.topRows<3>();
  data.endEffector.topRightCorner<3, 1>() += previous->topRightCorner<3, 1>();
  data.endEffector.row(3) << 0, 0, 0, 1;
}

// After forwardKinematics(): each joint's motion subspace S_i and each link's rigid spatial
// inertia, as spatial vectors (angular; linear) in world coordinates at the world origin.
// S_i = (z; o x z) for a rotation about the line through o along z, (0; z) for a translation.
// The inertia is [Ic + m (|c|^2 1 - c c^T), h^; h^T, m 1] with c the centre of mass, h = m c and
// Ic the inertia about c.
void worldSubspacesAndInertias(const ManipulatorModel& model, ManipulatorData& data) {
  for (int i = 0; i < data.n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const LinkParameters& l = model.getLink(i);
    const Transform& axis = internal::axisFrame(model, data, i);
    const V3 z = axis.block<3, 1>(0, 2);
    V6& S = data.motionSubspace[k];
    if (l.type == JointType::Prismatic) {
      S << 0, 0, 0, z;
    } else {
      S << z, V3(axis.topRightCorner<3, 1>()).cross(z);
    }
    const Transform& T = data.linkTransforms[k];
    const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    const V3 c = R * V3(l.com) + V3(T.topRightCorner<3, 1>());
    const Eigen::Matrix3d hx = skew(l.mass * c);
    M6& I = data.articulatedInertia[k];
    I.topLeftCorner<3, 3>().noalias() = R * Eigen::Matrix3d(l.inertia) * R.transpose();
    I.topLeftCorner<3, 3>().noalias() -= hx * skew(c);
    I.topRightCorner<3, 3>() = hx;
    I.bottomLeftCorner<3, 3>() = hx.transpose();
    I.bottomRightCorner<3, 3>() = l.mass * Eigen::Matrix3d::Identity();
  }
}

// The composite-rigid-body algorithm on the world-frame quantities above: with Ic_j the summed
// inertia of links j..n, M_ij = S_i . (Ic_j S_j) for i <= j (the inertias stay unchanged).
void compositeRigidBody(const ManipulatorModel& model, ManipulatorData& data, bool motorInertia) {
  const int n = data.n;
  M6 Ic = M6::Zero();
  for (int j = n - 1; j >= 0; --j) {
    const auto k = static_cast<std::size_t>(j);
    Ic += data.articulatedInertia[k];
    const V6 F = Ic * data.motionSubspace[k];
    for (int i = 0; i <= j; ++i) {
      const double m = data.motionSubspace[static_cast<std::size_t>(i)].dot(F);
      data.massMatrix(i, j) = m;
      data.massMatrix(j, i) = m;
    }
    if (motorInertia) data.massMatrix(j, j) += model.getArmatureInertia()(j);
  }
}

}  // namespace

const JointMatrix& massMatrix(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                              bool motorInertia) {
  forwardKinematics(model, data, q);
  worldSubspacesAndInertias(model, data);
  compositeRigidBody(model, data, motorInertia);
  return data.massMatrix;
}

const JointVector& forwardDynamics(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                                   const JointVector& qd, const JointVector& tau, const DynamicsOptions& options) {
  // qdd holds tau - h until it is solved in place (massMatrix() uses scratchTau).
  rnea(model, data, q, qd, data.zero, options.gravity, false, options.friction, &options.tipWrench, data.qdd);
  data.qdd = tau - data.qdd;
  // The mass matrix from the link transforms Newton-Euler left in data.R / data.pstar (no trigonometry).
  composeLinkTransforms(model, data);
  worldSubspacesAndInertias(model, data);
  compositeRigidBody(model, data, options.motorInertia);
  data.ldlt.compute(data.massMatrix);
  data.ldlt.solveInPlace(data.qdd);
  return data.qdd;
}


const JointVector& forwardDynamicsArticulatedBody(const ManipulatorModel& model, ManipulatorData& data,
                                                  const JointVector& q, const JointVector& qd, const JointVector& tau,
                                                  const DynamicsOptions& options) {
  // Featherstone's articulated-body algorithm with every spatial vector (angular; linear) in world
  // coordinates at the world origin: no coordinate transforms between links, so articulated
  // inertias and bias forces add directly into the parent and accelerations carry over as they are.
  const int n = data.n;
  forwardKinematics(model, data, q);

  worldSubspacesAndInertias(model, data);

  // Pass 1, outward: velocities, velocity-product accelerations c_i = v_i x S_i qd_i and bias
  // forces v_i x* (I_i v_i).
  V3 w = V3::Zero(), v = V3::Zero();
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const V6& S = data.motionSubspace[k];
    const V3 vjw = S.head<3>() * qd(i), vjv = S.tail<3>() * qd(i);
    w += vjw;
    v += vjv;
    data.biasAcceleration[k] << w.cross(vjw), w.cross(vjv) + v.cross(vjw);
    // With I v = (nI; fI): v x* (I v) = (w x nI + v x fI; w x fI).
    const M6& I = data.articulatedInertia[k];
    const V3 nI = I.topLeftCorner<3, 3>() * w + I.topRightCorner<3, 3>() * v;
    const V3 fI = I.bottomLeftCorner<3, 3>() * w + I.bottomRightCorner<3, 3>() * v;
    data.biasForce[k] << w.cross(nI) + v.cross(fI), w.cross(fI);
  }
  // The tip wrench the last link exerts on its environment (at link frame n's origin, in its
  // coordinates) is an external force of minus it: it adds to that link's bias force.
  {
    const Transform& T = data.linkTransforms[static_cast<std::size_t>(n - 1)];
    const V3 f = T.topLeftCorner<3, 3>() * options.tipWrench.head<3>();
    V6& pA = data.biasForce[static_cast<std::size_t>(n - 1)];
    pA.head<3>() += T.topLeftCorner<3, 3>() * options.tipWrench.tail<3>() + V3(T.topRightCorner<3, 1>()).cross(f);
    pA.tail<3>() += f;
  }

  // Pass 2, inward: articulated inertias and bias forces, added straight into the parent's.
  for (int i = n - 1; i >= 0; --i) {
    const auto k = static_cast<std::size_t>(i);
    const LinkParameters& l = model.getLink(i);
    const V6& S = data.motionSubspace[k];
    const M6& IA = data.articulatedInertia[k];
    const V6& pA = data.biasForce[k];
    V6& U = data.inertiaTimesS[k];
    U.noalias() = IA * S;
    double D = S.dot(U);
    if (options.motorInertia) D += model.getArmatureInertia()(i);
    double u = tau(i) - S.dot(pA);
    if (options.friction) u -= jointFriction(l, qd(i));
    data.abaD(i) = D;
    data.abaU(i) = u;
    if (i == 0) break;
    // Ia = IA - U U^T / D and pa = pA + Ia c + U u / D go into the parent.
    M6& parent = data.articulatedInertia[k - 1];
    parent += IA;
    parent.noalias() -= (U / D) * U.transpose();
    V6& parentBias = data.biasForce[k - 1];
    parentBias += pA + U * (u / D);
    parentBias.noalias() += IA * data.biasAcceleration[k];
    parentBias.noalias() -= U * (U.dot(data.biasAcceleration[k]) / D);
  }

  // Pass 3, outward: accelerations from the base's -g.
  V6 a = V6::Zero();
  if (options.gravity) a.tail<3>() = -model.getGravity();
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    a += data.biasAcceleration[k];
    const double qddi = (data.abaU(i) - data.inertiaTimesS[k].dot(a)) / data.abaD(i);
    data.qdd(i) = qddi;
    a += data.motionSubspace[k] * qddi;
  }
  return data.qdd;
}

}  // namespace rp
