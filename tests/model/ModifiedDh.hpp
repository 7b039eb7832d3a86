#pragma once
// Re-expresses a standard-DH model in modified (Craig) DH, derived by hand: with Craig frame i
// placed at T_{i-1} Rz(theta_i) Tz(d_i) (on joint i's axis, x along the common normal to axis
// i+1), T_i^std = M_i Tx(a_i) Rx(alpha_i) and M_{i+1} = M_i Tx(a_i) Rx(alpha_i) Rz(theta_{i+1})
// Tz(d_{i+1}). So link i+1 takes (a_i, alpha_i) as its (a_{i}, alpha_{i}) of Craig's notation,
// link 1 gets a = alpha = 0, the centre of mass and inertia of link i move into M_i through
// Tx(a_i) Rx(alpha_i), and the tool becomes Tx(a_n) Rx(alpha_n) tool. Test only.
#include <memory>
#include <stdexcept>
#include <vector>

#include "rp/model/ManipulatorModel.hpp"

namespace rp::test {

inline std::unique_ptr<ManipulatorModel> toModifiedDh(const ManipulatorModel& standard) {
  if (standard.getConvention() != DHConvention::Standard) throw std::invalid_argument("toModifiedDh: not a standard-DH model");
  const int n = standard.getNumberOfJoints();
  std::vector<LinkParameters> links;
  for (int i = 0; i < n; ++i) {
    const LinkParameters& s = standard.getLink(i);
    LinkParameters m = s;
    m.a = i == 0 ? 0.0 : standard.getLink(i - 1).a;
    m.alpha = i == 0 ? 0.0 : standard.getLink(i - 1).alpha;
    const Transform post = Transform(translation(s.a, 0, 0) * xRotation(s.alpha));
    const Eigen::Matrix3d R = post.topLeftCorner<3, 3>();
    m.com = Vector<3>(R * Eigen::Vector3d(s.com) + post.topRightCorner<3, 1>());
    m.inertia = Matrix<3, 3>(R * Eigen::Matrix3d(s.inertia) * R.transpose());
    links.push_back(m);
  }
  const LinkParameters& last = standard.getLink(n - 1);
  const Transform tool = Transform(translation(last.a, 0, 0) * xRotation(last.alpha) * standard.getToolTransform());
  return std::make_unique<ManipulatorModel>(standard.getName() + "_mdh", links, standard.getBaseTransform(), tool,
                                            standard.getGravity(), DHConvention::Modified);
}

}  // namespace rp::test
