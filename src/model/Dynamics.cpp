// Recursive Newton-Euler dynamics for serial chains in standard or modified DH or the Placement
// form (which takes the modified-DH path: joint i moves about z_i through frame i's origin), with
// revolute and prismatic joints (rp/model/Dynamics.hpp).
//
// Link quantities live in link coordinates, as in Luh, Walker and Paul's formulation and the
// Robotics Toolbox's rne_dh / rne_mdh: R_i and p_i are the rotation and origin of frame i in frame
// i-1; s_i is joint i's axis in frame i ((0, sin alpha_i, cos alpha_i) in standard DH, z in
// modified DH). The linear acceleration of a frame origin is carried outward through a point on
// the joint axis, which is fixed in both links of a revolute joint: frame i-1's origin in standard
// DH, frame i's in modified DH. A prismatic joint adds its sliding and Coriolis terms.
//
// The inverse dynamics and the Coriolis torques use that recursion. The gravity torque, the mass
// matrix and the forward dynamics (the simulation's step) work in world coordinates after one
// forward kinematics instead: the gravity torque from sums of link mass moments, the mass matrix by
// composite rigid bodies, the velocity products by a Newton-Euler pass on spatial vectors. The
// tests compare each with the recursion above, with KDL and with finite differences.
#include "rp/model/Dynamics.hpp"

#include <array>
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
  if (model.hasMimicJoints()) {  // S^T tau_chain(S q + o, S qd, S qdd)
    ManipulatorData& c = *data.chain;
    model.toChain(q, data.chainQ);
    model.toChain(qd, data.chainQd, false);
    model.toChain(qdd, data.chainQdd, false);
    rnea(model.getChain(), c, data.chainQ, data.chainQd, data.chainQdd, options.gravity, options.motorInertia, options.friction,
         &options.tipWrench, c.tau);
    internal::torqueFromChain(model, c.tau, data.tau);
    return data.tau;
  }
  rnea(model, data, q, qd, qdd, options.gravity, options.motorInertia, options.friction, &options.tipWrench, data.tau);
  return data.tau;
}

namespace {

// The gravity torque from the link frames of the last forward kinematics and sums of link mass
// moments (no Newton-Euler recursion): with the potential energy U = -sum_k m_k g . c_k, a revolute
// joint i turning about the line through o_i along z_i moves the centres of mass of links i..n at
// dc_k/dq_i = z_i x (c_k - o_i), so
//   g_i = dU/dq_i = -z_i . ((H_i - M_i o_i) x g),  H_i = sum_{k>=i} m_k c_k,  M_i = sum_{k>=i} m_k,
// and a prismatic joint along z_i gives g_i = -M_i z_i . g.
// forwardDynamics() takes its gravity part from this same (never inlined) function after the same
// forwardKinematics() call, so that with tau = gravityTorque(q) at rest it subtracts bit-identical
// numbers and the accelerations are exactly zero (simulations with discontinuous Coulomb friction
// rely on that; see forwardDynamics()).
[[gnu::noinline]] void gravityFromKinematics(const ManipulatorModel& model, const ManipulatorData& data,
                                             JointVector& tau) {
  const V3 g = model.getGravity();
  double mass = 0;
  V3 moment = V3::Zero();
  for (int i = data.n - 1; i >= 0; --i) {
    const auto k = static_cast<std::size_t>(i);
    const LinkParameters& l = model.getLink(i);
    const Transform& T = data.linkTransforms[k];
    moment += l.mass * (T.topLeftCorner<3, 3>() * V3(l.com) + V3(T.topRightCorner<3, 1>()));
    mass += l.mass;
    const Transform& axis = internal::axisFrame(model, data, i);
    const V3 z = axis.block<3, 1>(0, 2);
    if (l.type == JointType::Prismatic) {
      tau(i) = -mass * z.dot(g);
    } else {
      tau(i) = -z.dot((moment - mass * V3(axis.topRightCorner<3, 1>())).cross(g));
    }
  }
}

}  // namespace

void gravityTorque(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q, JointVector& tau) {
  forwardKinematics(model, data, q);
  if (model.hasMimicJoints()) {  // S^T g_chain
    gravityFromKinematics(model.getChain(), *data.chain, data.chainTau);
    internal::torqueFromChain(model, data.chainTau, tau);
    return;
  }
  gravityFromKinematics(model, data, tau);
}

void frictionTorque(const ManipulatorModel& model, const JointVector& qd, JointVector& tau) {
  for (int i = 0; i < model.getNumberOfJoints(); ++i) {
    tau(i) = jointFriction(model.getLink(i), qd(i));
  }
}

void coriolisTorque(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q, const JointVector& qd,
                    JointVector& tau) {
  if (model.hasMimicJoints()) {
    ManipulatorData& c = *data.chain;
    model.toChain(q, data.chainQ);
    model.toChain(qd, data.chainQd, false);
    rnea(model.getChain(), c, data.chainQ, data.chainQd, c.zero, false, false, false, nullptr, data.chainTau);
    internal::torqueFromChain(model, data.chainTau, tau);
    return;
  }
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

using M3 = Eigen::Matrix3d;

// After forwardKinematics(), spatial vectors (angular; linear) in world coordinates at the world
// origin: each joint's motion subspace S_i = (z; o x z) for a rotation about the line through o
// along z, (0; z) for a translation; and each link's inertia in the compact form its spatial
// inertia [Io, h^; h^T, m 1] is made of: the mass moment h = m c (c the centre of mass) and the
// rotational inertia about the origin Io = R Ic R^T + m (|c|^2 1 - c c^T). With it, I (w; v) = (Io w + h x v; m v - h x w)
// costs two 3x3 products instead of a 6x6 one, and inertias add as (m, h, Io).
// Joint i's motion subspace S = (z; o x z) (revolute) or (0; z) (prismatic), with z and o the
// axis and origin of its axis frame, from the last forward kinematics.
inline void motionSubspace(const ManipulatorModel& model, const ManipulatorData& data, int i, double* S) {
  const double* a = internal::axisFrame(model, data, i).data();  // column-major 4 x 4: z in 8..10, o in 12..14
  const double zx = a[8], zy = a[9], zz = a[10];
  if (model.getLink(i).type == JointType::Prismatic) {
    S[0] = S[1] = S[2] = 0;
    S[3] = zx, S[4] = zy, S[5] = zz;
  } else {
    const double ox = a[12], oy = a[13], oz = a[14];
    S[0] = zx, S[1] = zy, S[2] = zz;
    S[3] = oy * zz - oz * zy, S[4] = oz * zx - ox * zz, S[5] = ox * zy - oy * zx;
  }
}

// Link i's mass moment h = m c and rotational inertia Io about the world origin, from its link
// frame T (column-major 4 x 4). Io = R Ic R^T + m (|c|^2 1 - c c^T) is symmetric: only its six
// distinct entries (xx, yy, zz, xy, xz, yz) are computed, from R Ic and six dot products, in plain
// scalars (Eigen's products on the 3 x 3 corner of a 4 x 4 matrix took twice the instructions).
// With the inertia's Cholesky factor L (ManipulatorModel::getInertiaFactor(): Ic = L L^T),
// R Ic R^T = G G^T with G = R L: 18 + 18 multiplications instead of 27 + 21.
[[gnu::always_inline]] inline void linkInertia(const ManipulatorModel& model, int i, const Transform& T, double* h,
                                               double* Io) {
  const LinkParameters& l = model.getLink(i);
  // Columns of four (the last row of T is 0 0 0 1) so that Eigen works on pairs of numbers.
  const auto R4 = T.leftCols<3>();
  double J00, J11, J22, J01, J02, J12;  // R Ic R^T
  if (const Eigen::Matrix3d* L = model.getInertiaFactor(i)) {
    const double* f = L->data();  // column-major, lower: f[0] f[1] f[2] / f[4] f[5] / f[8]
    const Eigen::Vector4d g0 = f[0] * T.col(0) + f[1] * T.col(1) + f[2] * T.col(2);
    const Eigen::Vector4d g1 = f[4] * T.col(1) + f[5] * T.col(2);
    const Eigen::Vector4d g2 = f[8] * T.col(2);
    const Eigen::Vector4d d = g0.cwiseProduct(g0) + g1.cwiseProduct(g1) + g2.cwiseProduct(g2);
    J00 = d(0), J11 = d(1), J22 = d(2);
    J01 = g0(0) * g0(1) + g1(0) * g1(1) + g2(0) * g2(1);
    J02 = g0(0) * g0(2) + g1(0) * g1(2) + g2(0) * g2(2);
    J12 = g0(1) * g0(2) + g1(1) * g1(2) + g2(1) * g2(2);
  } else {
    using M43 = Eigen::Matrix<double, 4, 3>;
    M43 A;
    A.noalias() = R4 * l.inertia;  // R Ic
    // R Ic R^T: rows 0 and 1 (a pair each column), and the last diagonal entry.
    Eigen::Matrix<double, 2, 3> J;
    J.noalias() = A.topRows<2>() * T.topLeftCorner<3, 3>().transpose();
    J00 = J(0, 0), J11 = J(1, 1), J01 = J(0, 1), J02 = J(0, 2), J12 = J(1, 2);
    J22 = A.row(2).dot(T.block<1, 3>(2, 0));
  }
  const Eigen::Vector4d c = R4 * l.com + T.col(3);        // c(3) = 1
  const double m = l.mass;
  for (int a = 0; a < 3; ++a) h[a] = m * c(a);
  const double hc = h[0] * c(0) + h[1] * c(1) + h[2] * c(2);
  Io[0] = J00 + hc - h[0] * c(0);
  Io[1] = J11 + hc - h[1] * c(1);
  Io[2] = J22 + hc - h[2] * c(2);
  Io[3] = J01 - h[0] * c(1);
  Io[4] = J02 - h[0] * c(2);
  Io[5] = J12 - h[1] * c(2);
}

// The six entries (xx, yy, zz, xy, xz, yz) as a symmetric 3 x 3 matrix.
void symmetric(const double* s, M3& Io) { Io << s[0], s[3], s[4], s[3], s[1], s[5], s[4], s[5], s[2]; }

void worldLinkInertias(const ManipulatorModel& model, ManipulatorData& data) {
  for (int i = 0; i < data.n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    motionSubspace(model, data, i, data.motionSubspace[k].data());
    double Io[6];
    linkInertia(model, i, data.linkTransforms[k], data.massMoment[k].data(), Io);
    symmetric(Io, data.originInertia[k]);
  }
}

// The full spatial inertias [Io, h^; h^T, m 1] of worldLinkInertias() (for the articulated-body
// algorithm, whose articulated inertias lose that structure).
void worldSpatialInertias(const ManipulatorModel& model, ManipulatorData& data) {
  worldLinkInertias(model, data);
  for (int i = 0; i < data.n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const M3 hx = skew(data.massMoment[k]);
    M6& I = data.articulatedInertia[k];
    I.topLeftCorner<3, 3>() = data.originInertia[k];
    I.topRightCorner<3, 3>() = hx;
    I.bottomLeftCorner<3, 3>() = hx.transpose();
    I.bottomRightCorner<3, 3>() = model.getLink(i).mass * M3::Identity();
  }
}

// The composite-rigid-body algorithm on those quantities, in one pass from the tip: link j's
// (m, h, Io) are added to those of links j+1..n (the composite inertia I^c_j, its rotational part as
// the six numbers of a symmetric matrix), F_j = I^c_j S_j is kept, and row j of M is M_jk = S_j . F_k
// for k >= j (the columns of the links beyond j are already known). No 6 x 6 matrix is formed and
// everything is in scalars. With keepLinks, each link's h and Io and each S_j are kept in data for
// the velocity products of forwardDynamics().
template <bool keepLinks>
void compositeRigidBody(const ManipulatorModel& model, ManipulatorData& data, bool motorInertia) {
  const int n = data.n;
  double* M = data.massMatrix.data();
  const Eigen::Index ld = data.massMatrix.rows();  // column-major
  double m = 0, hx = 0, hy = 0, hz = 0;
  double xx = 0, yy = 0, zz = 0, xy = 0, xz = 0, yz = 0;  // I^c_j's rotational part about the origin
  for (int j = n - 1; j >= 0; --j) {
    const auto k = static_cast<std::size_t>(j);
    const LinkParameters& l = model.getLink(j);
    double h[3], Io[6];
    linkInertia(model, j, data.linkTransforms[k], h, Io);
    if constexpr (keepLinks) {
      data.massMoment[k] << h[0], h[1], h[2];
      symmetric(Io, data.originInertia[k]);
    }
    m += l.mass;
    hx += h[0], hy += h[1], hz += h[2];
    xx += Io[0], yy += Io[1], zz += Io[2], xy += Io[3], xz += Io[4], yz += Io[5];
    double S[6];  // in registers: the loop below reads it n - j times
    motionSubspace(model, data, j, S);
    if constexpr (keepLinks) data.motionSubspace[k] << S[0], S[1], S[2], S[3], S[4], S[5];
    // F = (Io sw + h x sv; m sv - h x sw)
    const double f0 = xx * S[0] + xy * S[1] + xz * S[2] + (hy * S[5] - hz * S[4]);
    const double f1 = xy * S[0] + yy * S[1] + yz * S[2] + (hz * S[3] - hx * S[5]);
    const double f2 = xz * S[0] + yz * S[1] + zz * S[2] + (hx * S[4] - hy * S[3]);
    const double f3 = m * S[3] - (hy * S[2] - hz * S[1]);
    const double f4 = m * S[4] - (hz * S[0] - hx * S[2]);
    const double f5 = m * S[5] - (hx * S[1] - hy * S[0]);
    data.inertiaTimesS[k] << f0, f1, f2, f3, f4, f5;
    // M_jj from the values in registers (reading F_j back right after storing it stalled each row
    // on a failed store-to-load forwarding), then the columns of the links beyond j.
    M[j + j * ld] = (S[0] * f0 + S[1] * f1) + (S[2] * f2 + S[3] * f3) + (S[4] * f4 + S[5] * f5) +
                    (motorInertia ? model.getArmatureInertia()(j) : 0.0);
    for (int c = j + 1; c < n; ++c) {
      const double* Fc = data.inertiaTimesS[static_cast<std::size_t>(c)].data();
      const double Mjc = (S[0] * Fc[0] + S[1] * Fc[1]) + (S[2] * Fc[2] + S[3] * Fc[3]) + (S[4] * Fc[4] + S[5] * Fc[5]);
      M[j + c * ld] = Mjc;
      M[c + j * ld] = Mjc;
    }
  }
}

// The wrench the last link exerts on its environment (at link frame n's origin, in its
// coordinates) is an external force of minus it on that link: it adds to the link's bias force
// (world coordinates, world origin) like an inertial force.
void addTipWrench(ManipulatorData& data, const Vector<6>& tipWrench) {
  const Transform& T = data.linkTransforms[static_cast<std::size_t>(data.n - 1)];
  const V3 f = T.topLeftCorner<3, 3>() * tipWrench.head<3>();
  V6& F = data.biasForce[static_cast<std::size_t>(data.n - 1)];
  F.head<3>() += T.topLeftCorner<3, 3>() * tipWrench.tail<3>() + V3(T.topRightCorner<3, 1>()).cross(f);
  F.tail<3>() += f;
}

// The velocity-product torques C(q, qd) qd plus the torques of the tip wrench, by Newton-Euler on
// the world-frame quantities of worldLinkInertias() (no gravity: that part comes from
// gravityFromKinematics()). Outward: spatial velocities v_i = v_{i-1} + S_i qd_i and accelerations
// a_i = a_{i-1} + v_i x S_i qd_i; each link's force I_i a_i + v_i x* I_i v_i; inward: the summed
// forces F_i and tau_i = S_i . F_i. At qd = 0 with no wrench every term is exactly zero.
void velocityProductTorques(const ManipulatorModel& model, ManipulatorData& data, const JointVector& qd,
                            const Vector<6>& tipWrench, JointVector& tau) {
  const int n = data.n;
  V3 w = V3::Zero(), v = V3::Zero(), aw = V3::Zero(), av = V3::Zero();
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const V6& S = data.motionSubspace[k];
    const V3 jw = S.head<3>() * qd(i), jv = S.tail<3>() * qd(i);
    w += jw;
    v += jv;
    aw += w.cross(jw);
    av += w.cross(jv) + v.cross(jw);
    const double m = model.getLink(i).mass;
    const V3& h = data.massMoment[k];
    const M3& Io = data.originInertia[k];
    const V3 nI = Io * w + h.cross(v), fI = m * v - h.cross(w);
    data.biasForce[k] << Io * aw + h.cross(av) + w.cross(nI) + v.cross(fI), m * av - h.cross(aw) + w.cross(fI);
  }
  addTipWrench(data, tipWrench);
  V6 F = V6::Zero();
  for (int i = n - 1; i >= 0; --i) {
    const auto k = static_cast<std::size_t>(i);
    F += data.biasForce[k];
    tau(i) = data.motionSubspace[k].dot(F);
  }
}

// M = L D L^T in place in data.ldl (M is symmetric positive definite: no pivoting), then
// x <- M^-1 x by forward substitution, division by D and back substitution. O(n^3 / 6). Row j's
// products L(j, k) D(k) are formed once for the whole column below it, and each D(j) is inverted
// once (n divisions instead of n (n + 1) / 2).
void ldlSolveInPlace(ManipulatorData& data, JointVector& x) {
  const int n = data.n;
  JointMatrix& L = data.ldl;
  const JointMatrix& M = data.massMatrix;
  std::array<double, kMaxJoints> inverse, ld;  // 1 / D(j); L(j, k) D(k) of the row being done
  for (int j = 0; j < n; ++j) {
    double d = M(j, j);
    for (int k = 0; k < j; ++k) {
      const double l = L(j, k) * L(k, k);
      ld[static_cast<std::size_t>(k)] = l;
      d -= L(j, k) * l;
    }
    L(j, j) = d;
    const double r = 1.0 / d;
    inverse[static_cast<std::size_t>(j)] = r;
    for (int i = j + 1; i < n; ++i) {
      double s = M(i, j);
      for (int k = 0; k < j; ++k) s -= L(i, k) * ld[static_cast<std::size_t>(k)];
      L(i, j) = s * r;
    }
  }
  for (int i = 0; i < n; ++i) {  // L y = x
    double s = x(i);
    for (int k = 0; k < i; ++k) s -= L(i, k) * x(k);
    x(i) = s;
  }
  for (int i = n - 1; i >= 0; --i) {  // L^T x = D^-1 y
    double s = x(i) * inverse[static_cast<std::size_t>(i)];
    for (int k = i + 1; k < n; ++k) s -= L(k, i) * x(k);
    x(i) = s;
  }
}

}  // namespace

namespace {

// With mimic joints: data.massMatrix = S^T M_chain S from the chain data's mass matrix.
void massFromChain(const ManipulatorModel& model, ManipulatorData& data) {
  const JointMatrix& Mc = data.chain->massMatrix;
  const std::vector<JointCoupling>& coupling = model.getCoupling();
  data.massMatrix.setZero();
  for (std::size_t a = 0; a < coupling.size(); ++a)
    for (std::size_t b = 0; b < coupling.size(); ++b)
      data.massMatrix(coupling[a].joint, coupling[b].joint) +=
          coupling[a].multiplier * coupling[b].multiplier * Mc(static_cast<int>(a), static_cast<int>(b));
}

// massMatrixAndBias() with mimic joints: S^T M S and S^T h, with M and h = g + C qd [+ tip wrench]
// [+ friction] of the chain at S q + o and S qd, h summed in forwardDynamics()'s order (so that
// gravityTorque() at rest again gives exactly zero accelerations).
void coupledMassMatrixAndBias(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                              const JointVector& qd, const DynamicsOptions& options) {
  const ManipulatorModel& chain = model.getChain();
  ManipulatorData& c = *data.chain;
  forwardKinematics(model, data, q);  // the chain's, at data.chainQ
  model.toChain(qd, data.chainQd, false);
  if (options.gravity) {
    gravityFromKinematics(chain, c, c.bias);
  } else {
    c.bias.setZero();
  }
  compositeRigidBody<true>(chain, c, options.motorInertia);  // also the link inertias of the velocity products
  velocityProductTorques(chain, c, data.chainQd, options.tipWrench, c.scratchTau);
  for (int k = 0; k < c.n; ++k) {
    double h = c.bias(k) + c.scratchTau(k);
    if (options.friction) h += jointFriction(chain.getLink(k), data.chainQd(k));
    c.bias(k) = h;
  }
  massFromChain(model, data);
  internal::torqueFromChain(model, c.bias, data.bias);
}

}  // namespace

const JointMatrix& massMatrix(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                              bool motorInertia) {
  if (model.hasMimicJoints()) {
    model.toChain(q, data.chainQ);
    massMatrix(model.getChain(), *data.chain, data.chainQ, motorInertia);
    internal::framesFromChain(model, data);
    massFromChain(model, data);
    return data.massMatrix;
  }
  forwardKinematics(model, data, q);
  compositeRigidBody<false>(model, data, motorInertia);
  return data.massMatrix;
}

const JointVector& massMatrixAndBias(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                                     const JointVector& qd, const DynamicsOptions& options) {
  if (model.hasMimicJoints()) {
    coupledMassMatrixAndBias(model, data, q, qd, options);
    return data.bias;
  }
  // h = g(q) + C(q, qd) qd [+ tip wrench] [+ friction], summed in that order.
  forwardKinematics(model, data, q);
  if (options.gravity) {
    gravityFromKinematics(model, data, data.bias);
  } else {
    data.bias.setZero();
  }
  compositeRigidBody<true>(model, data, options.motorInertia);  // also the link inertias of the velocity products
  velocityProductTorques(model, data, qd, options.tipWrench, data.scratchTau);
  for (int i = 0; i < data.n; ++i) {
    double h = data.bias(i) + data.scratchTau(i);
    if (options.friction) h += jointFriction(model.getLink(i), qd(i));
    data.bias(i) = h;
  }
  return data.bias;
}

const JointVector& forwardDynamics(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                                   const JointVector& qd, const JointVector& tau, const DynamicsOptions& options) {
  massMatrixAndBias(model, data, q, qd, options);
  for (int i = 0; i < data.n; ++i) data.qdd(i) = tau(i) - data.bias(i);
  ldlSolveInPlace(data, data.qdd);
  return data.qdd;
}

const JointVector& forwardDynamicsArticulatedBody(const ManipulatorModel& model, ManipulatorData& data,
                                                  const JointVector& q, const JointVector& qd, const JointVector& tau,
                                                  const DynamicsOptions& options) {
  // The articulated-body recursion has no place for a joint that follows another: S^T M S instead.
  if (model.hasMimicJoints()) return forwardDynamics(model, data, q, qd, tau, options);
  // Featherstone's articulated-body algorithm with every spatial vector (angular; linear) in world
  // coordinates at the world origin: no coordinate transforms between links, so articulated
  // inertias and bias forces add directly into the parent and accelerations carry over as they are.
  const int n = data.n;
  forwardKinematics(model, data, q);
  worldSpatialInertias(model, data);

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
  addTipWrench(data, options.tipWrench);

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
