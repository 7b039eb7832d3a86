// Internal: straight-line Cartesian motion as a joint path (CartesianPath.hpp).
#include "CartesianPath.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "rp/model/InverseKinematics.hpp"
#include "rp/model/Kinematics.hpp"

namespace rp::internal {

namespace {

struct Line {
  Vector<3> p0, dp;           // position p(s) = p0 + s dp
  Eigen::Matrix3d R0;         // orientation R(s) = R0 * AngleAxis(s * angle, axis)
  Eigen::Vector3d axis;       // in the start's frame
  double angle = 0;           // [rad], in [0, pi]
  Eigen::Matrix<double, 6, 1> twist;  // d(p, rotation)/ds in the world: (dp, R0 axis angle)

  Transform at(double s) const {
    const Eigen::Matrix3d R = R0 * Eigen::AngleAxisd(s * angle, axis).toRotationMatrix();
    Transform T = Transform::unit();
    T.block<3, 3>(0, 0) = R;
    T.block<3, 1>(0, 3) = p0 + s * dp;
    return T;
  }
};

// Whether a Jacobian with these singular values (largest first) has lost rank: fewer than six,
// or the smallest below 1e-4 of the largest. No straight line is defined there.
bool rankDeficient(const Eigen::VectorXd& sv) { return sv.size() < 6 || sv(5) < 1e-4 * std::max(1.0, sv(0)); }

std::string point(const Transform& T) {
  std::ostringstream s;
  s.precision(4);
  s << "(" << T(0, 3) << ", " << T(1, 3) << ", " << T(2, 3) << ") m";
  return s.str();
}

// Nodes q, dq/ds, d2q/ds2 at `intervals` + 1 uniform values of s. Throws when the line leaves
// the workspace or passes a singularity; returns false if the joints jump between two nodes by
// more than `jump` [rad] (too few nodes near a fast-turning stretch, or a branch change).
bool sampleNodes(const ManipulatorModel& model, ManipulatorData& data, const Line& line, const JointVector& qStart,
                 int intervals, JointPath& path, const std::string& who, double jump) {
  const int n = model.getNumberOfJoints();
  const std::size_t nodes = static_cast<std::size_t>(intervals) + 1;
  path.joints = n;
  path.intervals = intervals;
  path.q.assign(nodes * n, 0);
  path.dq.assign(nodes * n, 0);
  path.ddq.assign(nodes * n, 0);
  std::vector<JointVector> q(nodes, JointVector(n));
  q[0] = qStart;
  IkOptions options;
  options.positionTolerance = 1e-11;
  options.orientationTolerance = 1e-11;
  options.maxAttempts = 1;  // no random restarts: they would change the configuration
  options.maxIterations = 100;
  const double h = 1.0 / intervals;
  for (std::size_t k = 1; k < nodes; ++k) {
    const double s = static_cast<double>(k) * h;
    JointVector seed = q[k - 1];
    if (k >= 2) seed = q[k - 1] + (q[k - 1] - q[k - 2]);
    for (int i = 0; i < n; ++i) seed(i) = std::clamp(seed(i), model.getPositionMin()(i), model.getPositionMax()(i));
    const Transform T = line.at(s);
    if (inverseKinematics(model, data, T, seed, q[k], options) != IkStatus::Solved) {
      throw std::invalid_argument(who + "the straight line leaves the workspace or the joint limits at " +
                                  std::to_string(static_cast<int>(std::lround(100 * s))) + " % of the way, at " +
                                  point(T));
    }
    if ((q[k] - q[k - 1]).cwiseAbs().maxCoeff() > jump) return false;
  }
  // dq/ds from the Jacobian; the null-space part (redundant arms) from the node sequence.
  std::vector<JointVector> dq(nodes, JointVector(n));
  for (std::size_t k = 0; k < nodes; ++k) {
    const Eigen::MatrixXd J = jacobian(model, data, q[k], ReferenceFrame::Base);
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const Eigen::VectorXd sv = svd.singularValues();
    if (rankDeficient(sv)) {
      throw std::invalid_argument(who + "the straight line passes through a singularity at " + point(line.at(k * h)));
    }
    Eigen::VectorXd d = svd.solve(line.twist);
    if (n > 6) {
      const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 < nodes ? k + 1 : k;
      const Eigen::VectorXd drift = (q[b] - q[a]) / (static_cast<double>(b - a) * h);
      const Eigen::MatrixXd V = svd.matrixV();
      d += drift - V * (V.transpose() * drift);  // null-space projection of the drift
    }
    dq[k] = d;
  }
  for (std::size_t k = 0; k < nodes; ++k) {
    JointVector dd(n);
    if (k == 0) dd = (-3 * dq[0] + 4 * dq[1] - dq[2]) / (2 * h);
    else if (k + 1 == nodes) dd = (3 * dq[k] - 4 * dq[k - 1] + dq[k - 2]) / (2 * h);
    else dd = (dq[k + 1] - dq[k - 1]) / (2 * h);
    for (int i = 0; i < n; ++i) {
      path.q[k * n + i] = q[k](i);
      path.dq[k * n + i] = dq[k](i);
      path.ddq[k * n + i] = dd(i);
    }
  }
  return true;
}

// Largest distance between the interpolated path's end-effector and the line, at the midpoints.
double deviation(const ManipulatorModel& model, ManipulatorData& data, const Line& line, const JointPath& path) {
  const int n = path.joints;
  JointVector q0(n), q1(n), q2(n);
  double worst = 0;
  for (int k = 0; k < path.intervals; ++k) {
    const double s = (k + 0.5) / path.intervals;
    path.evaluate(s, q0, q1, q2);
    const Transform& T = forwardKinematics(model, data, q0);
    const Transform L = line.at(s);
    worst = std::max(worst, (T.block<3, 1>(0, 3) - L.block<3, 1>(0, 3)).norm());
  }
  return worst;
}

}  // namespace

bool isSingular(const ManipulatorModel& model, const JointVector& q) {
  ManipulatorData data(model);
  const Eigen::MatrixXd J = jacobian(model, data, q, ReferenceFrame::Base);
  return rankDeficient(Eigen::JacobiSVD<Eigen::MatrixXd>(J).singularValues());
}

SegmentPlan planCartesianLine(const ManipulatorModel& model, const JointVector& qStart, const Transform& goal,
                              const CartesianLimits& limits, const JointVector& vmax, const JointVector& amax,
                              const JointVector& jmax, const std::string& who) {
  const int n = model.getNumberOfJoints();
  ManipulatorData data(model);
  const Transform start = forwardKinematics(model, data, qStart);
  Line line;
  line.p0 = start.block<3, 1>(0, 3);
  line.dp = goal.block<3, 1>(0, 3) - line.p0;
  line.R0 = start.block<3, 3>(0, 0);
  const Eigen::Matrix3d R1 = goal.block<3, 3>(0, 0);
  const Eigen::AngleAxisd rel(Eigen::Matrix3d(line.R0.transpose() * R1));
  line.angle = std::abs(rel.angle());
  line.axis = rel.angle() < 0 ? Eigen::Vector3d(-rel.axis()) : Eigen::Vector3d(rel.axis());
  line.twist << line.dp, line.R0 * line.axis * line.angle;
  const double L = line.dp.norm();

  SegmentPlan plan;
  plan.kind = SegmentKind::Path;
  plan.length = L;
  if (L < 1e-12 && line.angle < 1e-12) {
    plan.kind = SegmentKind::Dwell;
    plan.hold = qStart;
    plan.end = qStart;
    return plan;
  }
  int intervals = std::clamp(static_cast<int>(std::ceil(std::max(L / 0.005, line.angle / 0.02))), 8, 2000);
  constexpr int kMaxIntervals = 32000;
  for (;;) {
    // A joint may move at most 0.05 rad between nodes; where it must move faster the nodes are
    // refined, and a jump that stays at the finest spacing is a singularity or a branch change.
    if (!sampleNodes(model, data, line, qStart, intervals, plan.path, who, 0.05)) {
      if (intervals < kMaxIntervals) {
        intervals *= 2;
        continue;
      }
      throw std::invalid_argument(who + "the straight line to " + point(goal) +
                                  " passes through a singularity (the configuration changes abruptly)");
    }
    if (deviation(model, data, line, plan.path) < 1e-7 || intervals >= kMaxIntervals) break;
    intervals *= 2;
  }

  // Largest joint derivatives along the path (with a margin for what lies between the nodes).
  const JointPath& p = plan.path;
  const std::size_t nodes = static_cast<std::size_t>(p.intervals) + 1;
  JointVector B1 = JointVector::Zero(n), B2 = JointVector::Zero(n), B3 = JointVector::Zero(n);
  const double h = 1.0 / p.intervals;
  for (std::size_t k = 0; k < nodes; ++k) {
    for (int i = 0; i < n; ++i) {
      B1(i) = std::max(B1(i), std::abs(p.dq[k * n + i]));
      B2(i) = std::max(B2(i), std::abs(p.ddq[k * n + i]));
      if (k + 1 < nodes) B3(i) = std::max(B3(i), std::abs(p.ddq[(k + 1) * n + i] - p.ddq[k * n + i]) / h);
    }
  }
  B1 *= 1.05;
  B2 *= 1.1;
  B3 *= 1.25;
  // Limits of s: |q'| s' <= v; |q''| s'^2 + |q'| |s''| <= a; |q'''| s'^3 + 3 |q''| s' |s''| + |q'| |s'''| <= j.
  double vs = INFINITY, as = INFINITY, js = INFINITY;
  if (L > 0) {
    vs = std::min(vs, limits.linearVelocity / L);
    as = std::min(as, limits.linearAcceleration / L);
    js = std::min(js, limits.linearJerk / L);
  }
  if (line.angle > 0) {
    vs = std::min(vs, limits.angularVelocity / line.angle);
    as = std::min(as, limits.angularAcceleration / line.angle);
    js = std::min(js, limits.angularJerk / line.angle);
  }
  for (int i = 0; i < n; ++i) {
    if (B1(i) > 0) vs = std::min(vs, vmax(i) / B1(i));
    if (B2(i) > 0) vs = std::min(vs, std::sqrt(0.5 * amax(i) / B2(i)));
    if (B3(i) > 0) vs = std::min(vs, std::cbrt(jmax(i) / (3 * B3(i))));
  }
  for (int i = 0; i < n; ++i) {
    if (B1(i) > 0) as = std::min(as, (amax(i) - B2(i) * vs * vs) / B1(i));
    if (B2(i) > 0) as = std::min(as, jmax(i) / (9 * B2(i) * vs));
  }
  for (int i = 0; i < n; ++i) {
    if (B1(i) > 0) js = std::min(js, (jmax(i) - B3(i) * vs * vs * vs - 3 * B2(i) * vs * as) / B1(i));
  }
  if (!(vs > 0 && as > 0 && js > 0) || !std::isfinite(vs + as + js)) {
    throw std::invalid_argument(who + "no speed keeps the joints within their limits along the line to " + point(goal));
  }
  plan.profile = JerkLimitedProfile(1.0, vs, as, js);
  plan.duration = plan.profile.getDuration();
  plan.exitTime = plan.duration;
  plan.entryTime = 0;
  plan.end = JointVector(n);
  for (int i = 0; i < n; ++i) plan.end(i) = p.q[(nodes - 1) * n + i];
  return plan;
}

}  // namespace rp::internal
