// Forward kinematics and Jacobians for standard-DH serial chains (rp/model/Kinematics.hpp).
#include "rp/model/Kinematics.hpp"

#include <cmath>

namespace rp {


const Transform& forwardKinematics(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q) {
  // T_i = T_{i-1} A_i on the affine part only (the last row of a transform is constant).
  const Transform* previous = &model.getBaseTransform();
  for (int i = 0; i < data.n; ++i) {
    const LinkParameters& l = model.getLink(i);
    const double theta = q(i) + l.offset;
    const double ct = std::cos(theta), st = std::sin(theta);
    const double ca = model.getCosAlpha()(i), sa = model.getSinAlpha()(i);
    Eigen::Matrix<double, 3, 4> A;
    A << ct, -st * ca, st * sa, l.a * ct,  //
        st, ct * ca, -ct * sa, l.a * st,   //
        0, sa, ca, l.d;
    Transform& T = data.linkTransforms[static_cast<std::size_t>(i)];
    T.topRows<3>().noalias() = previous->topLeftCorner<3, 3>() * A;
    T.topRightCorner<3, 1>() += previous->topRightCorner<3, 1>();
    T.row(3) << 0, 0, 0, 1;
    previous = &T;
  }
  const Transform& tool = model.getToolTransform();
  data.endEffector.topRows<3>().noalias() = previous->topLeftCorner<3, 3>() * tool.topRows<3>();
  data.endEffector.topRightCorner<3, 1>() += previous->topRightCorner<3, 1>();
  data.endEffector.row(3) << 0, 0, 0, 1;
  return data.endEffector;
}

const Jacobian& jacobian(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                         ReferenceFrame frame) {
  forwardKinematics(model, data, q);
  const Eigen::Vector3d pe = data.endEffector.topRightCorner<3, 1>();
  for (int i = 0; i < data.n; ++i) {
    // Joint i turns about z of the frame before it (the base for the first joint).
    const Transform& before = i == 0 ? model.getBaseTransform() : data.linkTransforms[static_cast<std::size_t>(i - 1)];
    const Eigen::Vector3d z = before.block<3, 1>(0, 2);
    const Eigen::Vector3d p = before.topRightCorner<3, 1>();
    data.jacobian.block<3, 1>(0, i) = z.cross(pe - p);
    data.jacobian.block<3, 1>(3, i) = z;
  }
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
