#pragma once
// A six-joint standard-DH arm with two prismatic joints (revolute, prismatic, revolute, prismatic,
// revolute, revolute), twisted and offset links, made-up masses, inertias and friction: the DH
// model the modified-DH tests re-express (URDF arms load in the Placement form). Test only.
#include <memory>
#include <vector>

#include "rp/model/ManipulatorModel.hpp"

namespace rp::test {

inline std::unique_ptr<ManipulatorModel> prismaticDhArm() {
  struct Row {
    JointType type;
    double a, alpha, d, offset, mass, cx, cy, cz, ixx, iyy, izz, ixy, min, max;
  };
  const Row rows[] = {
      {JointType::Revolute, 0.1, 0.0, 0.4, 0.4, 3.0, 0.02, 0.01, -0.1, 0.03, 0.025, 0.01, 0.001, -3, 3},
      {JointType::Prismatic, 0.2, 1.5707963267948966, 0.05, 0.1, 2.5, -0.05, 0.0, 0.02, 0.01, 0.04, 0.04, 0.0, -0.2, 0.4},
      {JointType::Revolute, 0.3, -1.3, 0.03, 0.2, 1.8, -0.12, 0.01, 0.0, 0.004, 0.03, 0.03, 0.0005, -2.2, 2.2},
      {JointType::Prismatic, 0.02, 0.7, 0.1, -0.3, 1.1, 0.0, 0.0, -0.08, 0.01, 0.01, 0.002, 0.0, 0.0, 0.35},
      {JointType::Revolute, 0.0, -1.5707963267948966, 0.05, 0.0, 0.5, 0.0, 0.02, 0.0, 0.0008, 0.0006, 0.0008, 0.0, -3, 3},
      {JointType::Revolute, 0.01, 1.5707963267948966, 0.08, 0.5, 0.2, 0.0, 0.0, 0.02, 0.0002, 0.0002, 0.0001, 0.0, -3, 3},
  };
  std::vector<LinkParameters> links;
  for (const Row& r : rows) {
    LinkParameters l;
    l.type = r.type;
    l.a = r.a;
    l.alpha = r.alpha;
    l.d = r.d;
    l.offset = r.offset;
    l.mass = r.mass;
    l.com = Vector<3>{{r.cx}, {r.cy}, {r.cz}};
    l.inertia << r.ixx, r.ixy, 0, r.ixy, r.iyy, 0, 0, 0, r.izz;
    l.positionMin = r.min;
    l.positionMax = r.max;
    l.viscousFriction = 0.3;
    l.coulombFrictionPositive = 0.5;
    l.coulombFrictionNegative = -0.4;
    links.push_back(l);
  }
  return std::make_unique<ManipulatorModel>("prismatic_dh", links, Transform(translation(0.05, 0.02, 0.1)),
                                            Transform(translation(0, 0, 0.12)));
}

}  // namespace rp::test
