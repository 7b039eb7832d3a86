// Wrapper of docs/models.md's fragments, as the page says: #include "rp/RoboticPlatform.hpp" and
// `using namespace rp;`, in main(), with the inputs the fragments name (joint velocities and
// accelerations, options, outputs, a pose and a seed; `links`, `base`, `tool` of an arm).
#include "rp/RoboticPlatform.hpp"

using namespace rp;

int main() {
  Puma560Model puma;
  JointVector qd = JointVector::Zero(6), qdd = JointVector::Zero(6), g(6), c(6), f(6), torque(6), qSolution(6);
  DynamicsOptions options;
  Vector<6> wrench;
  wrench = 0, 0, 10, 0, 0, 0;
  IkOptions ikOptions;
  JointVector seed = puma.getHomePosition();
  ManipulatorData scratch(puma);
  Transform pose = forwardKinematics(puma, scratch, seed);
  std::vector<LinkParameters> links;
  for (int i = 0; i < puma.getNumberOfJoints(); ++i) links.push_back(puma.getLink(i));
  Transform base = Transform::unit(), tool = Transform::unit();
@FRAGMENT@
  return 0;
}
