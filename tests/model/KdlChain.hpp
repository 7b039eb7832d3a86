#pragma once
// Builds an Orocos KDL chain from a ManipulatorModel's parameters with KDL's own API (standard-DH
// frames, rigid-body inertias about the centre of mass, a fixed tool segment), so that KDL is an
// independent reference for forward kinematics, Jacobians and dynamics. Test and benchmark only.
#include <kdl/chain.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/rotationalinertia.hpp>

#include "rp/model/ManipulatorModel.hpp"

namespace rp::test {

inline KDL::Chain kdlChain(const ManipulatorModel& model) {
  KDL::Chain chain;
  for (int i = 0; i < model.getNumberOfJoints(); ++i) {
    const LinkParameters& l = model.getLink(i);
    const KDL::RigidBodyInertia inertia(
        l.mass, KDL::Vector(l.com(0), l.com(1), l.com(2)),
        KDL::RotationalInertia(l.inertia(0, 0), l.inertia(1, 1), l.inertia(2, 2), l.inertia(0, 1), l.inertia(0, 2),
                               l.inertia(1, 2)));
    // Rz(q + offset) Tz(d) Tx(a) Rx(alpha): a joint about z, then KDL's DH frame.
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotZ, 1.0, l.offset),
                                  KDL::Frame::DH(l.a, l.alpha, l.d, 0.0), inertia));
  }
  const Transform& tool = model.getToolTransform();
  KDL::Frame f;
  for (int r = 0; r < 3; ++r) {
    f.p(r) = tool(r, 3);
    for (int c = 0; c < 3; ++c) f.M(r, c) = tool(r, c);
  }
  chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::Fixed), f));
  return chain;
}

inline KDL::JntArray kdlJoints(const JointVector& q) {
  KDL::JntArray a(static_cast<unsigned>(q.size()));
  for (Eigen::Index i = 0; i < q.size(); ++i) a(static_cast<unsigned>(i)) = q(i);
  return a;
}

}  // namespace rp::test
