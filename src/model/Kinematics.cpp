// Forward kinematics and Jacobians for standard-DH serial chains (rp/model/Kinematics.hpp).
#include "rp/model/Kinematics.hpp"

#include <cmath>

namespace rp {

namespace {

// A_i = Rz(theta) Tz(d) Tx(a) Rx(alpha), written out.
void dhTransform(const LinkParameters& l, double q, Transform& A) {
  const double theta = q + l.offset;
  const double ct = std::cos(theta), st = std::sin(theta), ca = std::cos(l.alpha), sa = std::sin(l.alpha);
  A(0, 0) = ct;
  A(0, 1) = -st * ca;
  A(0, 2) = st * sa;
  A(0, 3) = l.a * ct;
  A(1, 0) = st;
  A(1, 1) = ct * ca;
  A(1, 2) = -ct * sa;
  A(1, 3) = l.a * st;
  A(2, 0) = 0;
  A(2, 1) = sa;
  A(2, 2) = ca;
  A(2, 3) = l.d;
  A(3, 0) = 0;
  A(3, 1) = 0;
  A(3, 2) = 0;
  A(3, 3) = 1;
}

}  // namespace

const Transform& forwardKinematics(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q) {
  Transform A;
  const Transform* previous = &model.getBaseTransform();
  for (int i = 0; i < data.n; ++i) {
    dhTransform(model.getLink(i), q(i), A);
    data.linkTransforms[static_cast<std::size_t>(i)] = *previous * A;
    previous = &data.linkTransforms[static_cast<std::size_t>(i)];
  }
  data.endEffector = *previous * model.getToolTransform();
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
