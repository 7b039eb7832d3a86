#pragma once
// Link transforms and joint axes shared by the kinematics, dynamics and IK algorithms, for both
// DH conventions, the Placement form and both joint types (private to src/model).
#include <cmath>

#include "rp/model/ManipulatorData.hpp"

namespace rp::internal {

// The affine part (3 x 4) of A_i, the pose of link frame i in frame i-1, for joint value qi.
inline void linkMatrix(const ManipulatorModel& model, int i, double qi, Eigen::Matrix<double, 3, 4>& A) {
  const LinkParameters& l = model.getLink(i);
  const bool prismatic = l.type == JointType::Prismatic;
  if (model.getConvention() == DHConvention::Standard) {
    const double theta = prismatic ? l.offset : qi + l.offset;
    const double d = prismatic ? l.d + qi : l.d;
    const double ct = std::cos(theta), st = std::sin(theta);
    const double ca = model.getCosAlpha()(i), sa = model.getSinAlpha()(i);
    // Rz(theta) Tz(d) Tx(a) Rx(alpha)
    A << ct, -st * ca, st * sa, l.a * ct,  //
        st, ct * ca, -ct * sa, l.a * st,   //
        0, sa, ca, d;
  } else {
    // Modified DH and Placement: P_i Rz(q) or P_i Tz(q), with P_i the fixed part (for modified DH
    // Rx(alpha) Tx(a) Rz(offset) Tz(d), precomputed by the model).
    const Transform& P = model.getPlacement(i);
    if (prismatic) {
      A = P.topRows<3>();
      A.col(3) += qi * P.block<3, 1>(0, 2);
    } else {
      const double c = std::cos(qi), s = std::sin(qi);
      A.col(0) = c * P.block<3, 1>(0, 0) + s * P.block<3, 1>(0, 1);
      A.col(1) = c * P.block<3, 1>(0, 1) - s * P.block<3, 1>(0, 0);
      A.rightCols<2>() = P.block<3, 2>(0, 2);
    }
  }
}

// The world frame whose z axis is joint j's axis and whose origin lies on that axis, from the last
// forward kinematics: frame j-1 (the base for j = 0) in standard DH, frame j in modified DH and
// the Placement form.
inline const Transform& axisFrame(const ManipulatorModel& model, const ManipulatorData& data, int j) {
  if (model.getConvention() != DHConvention::Standard) return data.linkTransforms[static_cast<std::size_t>(j)];
  return j == 0 ? model.getBaseTransform() : data.linkTransforms[static_cast<std::size_t>(j - 1)];
}

// With mimic joints: the model's link frames and end-effector from the chain's last forward
// kinematics (link frame i is that of joint i's chain joint).
inline void framesFromChain(const ManipulatorModel& model, ManipulatorData& data) {
  for (int i = 0; i < data.n; ++i)
    data.linkTransforms[static_cast<std::size_t>(i)] = data.chain->linkTransforms[static_cast<std::size_t>(model.getChainIndex(i))];
  data.endEffector = data.chain->endEffector;
}

// With mimic joints: tau = S^T chainTau (each chain joint's torque times its multiplier on the
// joint that moves it).
template <typename Out>
inline void torqueFromChain(const ManipulatorModel& model, const JointVector& chainTau, Out& tau) {
  for (int i = 0; i < model.getNumberOfJoints(); ++i) tau(i) = 0;
  const std::vector<JointCoupling>& coupling = model.getCoupling();
  for (std::size_t k = 0; k < coupling.size(); ++k) tau(coupling[k].joint) += coupling[k].multiplier * chainTau(static_cast<int>(k));
}

// The base-frame Jacobian into data.jacobian from the link frames of the last forward kinematics.
void jacobianFromKinematics(const ManipulatorModel& model, ManipulatorData& data);

}  // namespace rp::internal
