#pragma once
// Builds an Orocos KDL chain from a ManipulatorModel's parameters with KDL's own API (KDL's DH
// frames: Frame::DH for standard DH, Frame::DH_Craig1989 for modified DH, the placement for the
// Placement form; joints RotZ / TransZ or
// about / along a KDL-computed axis; rigid-body inertias about the centre of mass; a fixed tool
// segment), so that KDL is an independent reference for forward kinematics, Jacobians and
// dynamics. Test and benchmark only.
#include <kdl/chain.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/rotationalinertia.hpp>

#include "rp/model/ManipulatorModel.hpp"

namespace rp::test {

inline KDL::Frame kdlFrame(const Transform& t) {
  KDL::Frame f;
  for (int r = 0; r < 3; ++r) {
    f.p(r) = t(r, 3);
    for (int c = 0; c < 3; ++c) f.M(r, c) = t(r, c);
  }
  return f;
}

inline KDL::Chain kdlChain(const ManipulatorModel& model) {
  KDL::Chain chain;
  if (!model.getBaseTransform().isIdentity(0.0)) {
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::Fixed), kdlFrame(model.getBaseTransform())));
  }
  for (int i = 0; i < model.getNumberOfJoints(); ++i) {
    const LinkParameters& l = model.getLink(i);
    const KDL::RigidBodyInertia inertia(
        l.mass, KDL::Vector(l.com(0), l.com(1), l.com(2)),
        KDL::RotationalInertia(l.inertia(0, 0), l.inertia(1, 1), l.inertia(2, 2), l.inertia(0, 1), l.inertia(0, 2),
                               l.inertia(1, 2)));
    const bool prismatic = l.type == JointType::Prismatic;
    if (model.getConvention() == DHConvention::Standard) {
      // Rz(q) or Tz(q), then KDL's DH frame Rz(offset) Tz(d) Tx(a) Rx(alpha). (KDL's Segment
      // divides out the joint's pose at q = 0, so the offset goes into the frame, not the joint.)
      const KDL::Joint joint(prismatic ? KDL::Joint::TransZ : KDL::Joint::RotZ);
      chain.addSegment(KDL::Segment(joint, KDL::Frame::DH(l.a, l.alpha, l.d, l.offset), inertia));
    } else {
      // Rx(alpha) Tx(a) Rz(offset) Tz(d) at q = 0 (KDL's Craig frame), or the link's placement; the
      // joint moves about or along that frame's z axis, which KDL's Joint(origin, axis) expresses in
      // the previous frame.
      const KDL::Frame f0 = model.getConvention() == DHConvention::Modified
                                ? KDL::Frame::DH_Craig1989(l.a, l.alpha, l.d, l.offset)
                                : kdlFrame(l.placement);
      const KDL::Joint joint("j", f0.p, f0.M.UnitZ(), prismatic ? KDL::Joint::TransAxis : KDL::Joint::RotAxis);
      chain.addSegment(KDL::Segment(joint, f0, inertia));
    }
  }
  chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::Fixed), kdlFrame(model.getToolTransform())));
  return chain;
}

inline KDL::JntArray kdlJoints(const JointVector& q) {
  KDL::JntArray a(static_cast<unsigned>(q.size()));
  for (Eigen::Index i = 0; i < q.size(); ++i) a(static_cast<unsigned>(i)) = q(i);
  return a;
}

}  // namespace rp::test
