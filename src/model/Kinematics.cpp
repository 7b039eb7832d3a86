// Forward kinematics and Jacobians for standard- and modified-DH serial chains (rp/model/Kinematics.hpp).
#include "rp/model/Kinematics.hpp"

#include <cmath>

#include "ChainInternal.hpp"

namespace rp {


const Transform& forwardKinematics(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q) {
  if (model.hasMimicJoints()) {  // the full chain at q_chain = S q + o
    model.toChain(q, data.chainQ);
    forwardKinematics(model.getChain(), *data.chain, data.chainQ);
    internal::framesFromChain(model, data);
    return data.endEffector;
  }
  // T_i = T_{i-1} A_i on the affine part only (the last row of a transform is constant).
  const Transform* previous = &model.getBaseTransform();
  const bool standard = model.getConvention() == DHConvention::Standard;
  for (int i = 0; i < data.n; ++i) {
    Transform& T = data.linkTransforms[static_cast<std::size_t>(i)];
    if (standard) {
      // A_i = Rz(theta) Tz(d) Tx(a) Rx(alpha) applied to T_{i-1}'s columns x, y, z, p: with
      // x' = ct x + st y and y' = ct y - st x, T_i = (x', ca y' + sa z, ca z - sa y', p + a x' + d z):
      // 30 multiplications instead of the 36 of a 3 x 3 by 3 x 4 product and the 6 of A_i.
      const LinkParameters& l = model.getLink(i);
      const bool prismatic = l.type == JointType::Prismatic;
      const double theta = prismatic ? l.offset : q(i) + l.offset;
      const double d = prismatic ? l.d + q(i) : l.d;
      const double ct = std::cos(theta), st = std::sin(theta);
      const double ca = model.getCosAlpha()(i), sa = model.getSinAlpha()(i), a = l.a;
      const double* P = previous->data();  // column-major 4 x 4
      double* t = T.data();
      for (int r = 0; r < 3; ++r) {
        const double x = P[r], y = P[r + 4], z = P[r + 8];
        const double x1 = ct * x + st * y, y1 = ct * y - st * x;
        t[r] = x1;
        t[r + 4] = ca * y1 + sa * z;
        t[r + 8] = ca * z - sa * y1;
        t[r + 12] = P[r + 12] + a * x1 + d * z;
      }
    } else if (const PlacementAxes& ax = model.getPlacementAxes(i); ax.permutation) {
      // P_i's rotation only permutes and flips axes: T_{i-1} P_i's columns are T_{i-1}'s own,
      // (s0 c_a0, s1 c_a1, s2 c_a2, p + R p_i), then Rz(q) or Tz(q): at most 9 + 15 multiplications
      // instead of 48.
      const Transform& Pl = model.getPlacement(i);
      const double* P = previous->data();  // column-major 4 x 4
      const Eigen::Vector3d p = previous->topRightCorner<3, 1>() + previous->topLeftCorner<3, 3>() * Pl.topRightCorner<3, 1>();
      const Eigen::Map<const Eigen::Vector3d> x(P + 4 * ax.axis[0]), y(P + 4 * ax.axis[1]), z(P + 4 * ax.axis[2]);
      if (model.isPrismatic(i)) {
        const Eigen::Vector3d zs = ax.sign[2] * z;
        T.block<3, 1>(0, 0) = ax.sign[0] * x;
        T.block<3, 1>(0, 1) = ax.sign[1] * y;
        T.block<3, 1>(0, 3) = p + q(i) * zs;
        T.block<3, 1>(0, 2) = zs;
      } else {
        // x' = c x + s y, y' = c y - s x with x = s0 c_a0, y = s1 c_a1.
        const double c = std::cos(q(i)), s = std::sin(q(i));
        const double cx = c * ax.sign[0], sx = s * ax.sign[0], cy = c * ax.sign[1], sy = s * ax.sign[1];
        const Eigen::Vector3d x1 = cx * x + sy * y, y1 = cy * y - sx * x, z1 = ax.sign[2] * z;
        T.block<3, 1>(0, 0) = x1;
        T.block<3, 1>(0, 1) = y1;
        T.block<3, 1>(0, 2) = z1;
        T.block<3, 1>(0, 3) = p;
      }
    } else {
      Eigen::Matrix<double, 3, 4> A;
      internal::linkMatrix(model, i, q(i), A);
      T.topRows<3>().noalias() = previous->topLeftCorner<3, 3>() * A;
      T.topRightCorner<3, 1>() += previous->topRightCorner<3, 1>();
    }
    T.row(3) << 0, 0, 0, 1;
    previous = &T;
  }
  if (model.hasIdentityTool()) {
    data.endEffector = *previous;
    return data.endEffector;
  }
  const Transform& tool = model.getToolTransform();
  data.endEffector.topRows<3>().noalias() = previous->topLeftCorner<3, 3>() * tool.topRows<3>();
  data.endEffector.topRightCorner<3, 1>() += previous->topRightCorner<3, 1>();
  data.endEffector.row(3) << 0, 0, 0, 1;
  return data.endEffector;
}

namespace internal {

void jacobianFromKinematics(const ManipulatorModel& model, ManipulatorData& data) {
  if (model.hasMimicJoints()) {  // J S: a mimic joint's column, times its multiplier, on its master's
    jacobianFromKinematics(model.getChain(), *data.chain);
    data.jacobian.setZero();
    const std::vector<JointCoupling>& coupling = model.getCoupling();
    for (std::size_t k = 0; k < coupling.size(); ++k)
      data.jacobian.col(coupling[k].joint) += coupling[k].multiplier * data.chain->jacobian.col(static_cast<int>(k));
    return;
  }
  const Eigen::Vector3d pe = data.endEffector.topRightCorner<3, 1>();
  for (int i = 0; i < data.n; ++i) {
    // Joint i moves about or along the z axis of its axis frame.
    const Transform& axis = internal::axisFrame(model, data, i);
    const Eigen::Vector3d z = axis.block<3, 1>(0, 2);
    if (model.isPrismatic(i)) {
      data.jacobian.block<3, 1>(0, i) = z;
      data.jacobian.block<3, 1>(3, i).setZero();
    } else {
      data.jacobian.block<3, 1>(0, i) = z.cross(pe - Eigen::Vector3d(axis.topRightCorner<3, 1>()));
      data.jacobian.block<3, 1>(3, i) = z;
    }
  }
}

}  // namespace internal

const Jacobian& jacobian(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                         ReferenceFrame frame) {
  forwardKinematics(model, data, q);
  internal::jacobianFromKinematics(model, data);
  if (frame == ReferenceFrame::EndEffector) {
    const Eigen::Matrix3d Rt = data.endEffector.topLeftCorner<3, 3>().transpose();
    for (int i = 0; i < data.n; ++i) {
      data.jacobian.block<3, 1>(0, i) = Rt * data.jacobian.block<3, 1>(0, i);
      data.jacobian.block<3, 1>(3, i) = Rt * data.jacobian.block<3, 1>(3, i);
    }
  }
  return data.jacobian;
}

void endEffectorForceToJointTorque(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                                   const Eigen::Ref<const Eigen::VectorXd>& wrench, Eigen::Ref<Eigen::VectorXd> tau,
                                   ReferenceFrame frame) {
  if (wrench.size() != 3 && wrench.size() != 6) {
    throw MathException("endEffectorForceToJointTorque: the wrench has " + std::to_string(wrench.size()) +
                        " elements; give a force (3) or a force and a moment (6)");
  }
  if (tau.size() != data.n) {
    throw MathException("endEffectorForceToJointTorque: the torque vector has " + std::to_string(tau.size()) +
                        " elements for a " + std::to_string(data.n) + "-joint manipulator");
  }
  jacobian(model, data, q, frame);
  if (wrench.size() == 3) {
    tau.noalias() = data.jacobian.topRows<3>().transpose() * wrench;
  } else {
    tau.noalias() = data.jacobian.transpose() * wrench;
  }
}

}  // namespace rp
