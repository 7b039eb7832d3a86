// Orocos KDL built from a URDF file by kdl_parser (Debian's libkdl-parser-dev:
// kdl_parser::treeFromFile, then KDL::Tree::getChain from the root link to the tip), the
// independent reference of the URDF model tests. kdl_parser makes each link a segment as the file
// says it (the joint's origin, then its motion about or along its axis; the link's inertial data),
// but it knows no mimic joints (each is a joint of the chain of its own) and a chain leaves out the
// links off it. So the reference adds, with KDL's own segments and arithmetic, the inertia of the
// subtrees hanging off each chain link (fixed links; links moved by joints off the chain at the
// value loadUrdf() lumps them at), and says for each chain joint which independent joint moves it
// (from urdfdom's <mimic>): the tests compare at q_chain = S q + o. Test only: kdl_parser is never
// linked into the library.
#pragma once

#include <gtest/gtest.h>

#include <kdl_parser/kdl_parser.hpp>
#include <urdf_parser/urdf_parser.h>

#include <kdl/chain.hpp>
#include <kdl/tree.hpp>

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace rp::test {

// The chain root -> tip of a URDF as KDL segments, and how many movable joints it has.
struct KdlArm {
  KDL::Chain chain;
  int joints = 0;
  bool allInertial = true;  // the child link of every movable joint (or a link lumped into it) has inertial data
  // Per movable chain joint: the independent joint that moves it (its own name unless a mimic,
  // mimics of mimics followed to the end), and the multiplier and offset from it.
  std::vector<std::string> master;
  std::vector<double> multiplier, offset;
};

// The value at which a moving joint off the chain is lumped: `given` (by joint name), else zero
// within its limits, or for a mimic joint its master's times the multiplier plus the offset.
inline double offChainValue(const urdf::ModelInterfaceSharedPtr& robot, const urdf::JointConstSharedPtr& j,
                            const std::map<std::string, double>& given = {}) {
  if (const auto it = given.find(j->name); it != given.end()) return it->second;
  if (j->mimic)
    return j->mimic->multiplier * offChainValue(robot, robot->getJoint(j->mimic->joint_name), given) + j->mimic->offset;
  return j->limits && j->type != urdf::Joint::CONTINUOUS ? std::clamp(0.0, j->limits->lower, j->limits->upper) : 0.0;
}

// KDL's chain of `file` (parsed by urdfdom as `robot`, for the mimic joints and the joint types
// kdl_parser turns into fixed ones) from the root to `tip`; `offChain` sets joints off the chain
// as UrdfOptions::offChainPositions does.
inline KdlArm kdlArm(const std::string& file, const urdf::ModelInterfaceSharedPtr& robot, const std::string& tip,
                     const std::map<std::string, double>& offChain = {}) {
  KdlArm arm;
  KDL::Tree tree;
  if (!kdl_parser::treeFromFile(file, tree)) {
    ADD_FAILURE() << "kdl_parser cannot read " << file;
    return arm;
  }
  KDL::Chain path;
  if (!tree.getChain(tree.getRootSegment()->first, tip, path)) {
    ADD_FAILURE() << "kdl_parser's tree of " << file << " has no chain to " << tip;
    return arm;
  }
  std::set<std::string> onChain;
  for (unsigned s = 0; s < path.getNrOfSegments(); ++s) onChain.insert(path.getSegment(s).getName());
  for (unsigned s = 0; s < path.getNrOfSegments(); ++s) {
    const KDL::Segment& segment = path.getSegment(s);
    KDL::RigidBodyInertia inertia = segment.getInertia();
    bool any = robot->getLink(segment.getName())->inertial != nullptr;
    // The subtrees off the chain, each segment at its pose in this segment's frame.
    std::vector<std::pair<KDL::SegmentMap::const_iterator, KDL::Frame>> todo{
        {tree.getSegment(segment.getName()), KDL::Frame::Identity()}};
    while (!todo.empty()) {
      const auto [element, frame] = todo.back();
      todo.pop_back();
      for (const KDL::SegmentMap::const_iterator& child : GetTreeElementChildren(element->second)) {
        const KDL::Segment& c = GetTreeElementSegment(child->second);
        if (onChain.count(c.getName())) continue;
        const urdf::JointConstSharedPtr j = robot->getJoint(c.getJoint().getName());
        // kdl_parser makes floating and planar joints fixed; loadUrdf() carries no such body.
        if (j->type == urdf::Joint::FLOATING || j->type == urdf::Joint::PLANAR) continue;
        const KDL::Frame f = frame * c.pose(j->type == urdf::Joint::FIXED ? 0.0 : offChainValue(robot, j, offChain));
        inertia = inertia + f * c.getInertia();
        any = any || robot->getLink(c.getName())->inertial != nullptr;
        todo.emplace_back(child, f);
      }
    }
    if (segment.getJoint().getType() != KDL::Joint::Fixed) {
      if (!any) arm.allInertial = false;
      ++arm.joints;
      double a = 1, b = 0;
      urdf::JointConstSharedPtr m = robot->getJoint(segment.getJoint().getName());
      for (; m->mimic; m = robot->getJoint(m->mimic->joint_name)) {
        b += a * m->mimic->offset;
        a *= m->mimic->multiplier;
      }
      arm.master.push_back(m->name);
      arm.multiplier.push_back(a);
      arm.offset.push_back(b);
    }
    arm.chain.addSegment(KDL::Segment(segment.getName(), segment.getJoint(), segment.getFrameToTip(), inertia));
  }
  return arm;
}

}  // namespace rp::test
