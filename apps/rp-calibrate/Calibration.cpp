// The identification behind rp-calibrate (see Calibration.hpp).
#include "Calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

namespace rp::calibration {

namespace {

using V3 = Eigen::Vector3d;

// The world frame whose z axis is joint i's axis and whose origin lies on it, from the last
// forward kinematics (as the library's gravityTorque() takes it).
const Transform& axisFrame(const ManipulatorModel& model, const ManipulatorData& data, int i) {
  if (model.getConvention() != DHConvention::Standard) return data.linkTransforms[static_cast<std::size_t>(i)];
  return i == 0 ? model.getBaseTransform() : data.linkTransforms[static_cast<std::size_t>(i - 1)];
}

void requireChain(const ManipulatorModel& model) {
  if (model.hasMimicJoints())
    throw std::invalid_argument("calibration: models with mimic joints are not supported ('" + model.getName() + "')");
}

// A joint's range for planning: its limits, a revolute joint's cut to [-pi, pi].
void planningRange(const ManipulatorModel& model, int j, double& lo, double& hi) {
  lo = model.getPositionMin()(j);
  hi = model.getPositionMax()(j);
  if (!model.isPrismatic(j)) {
    lo = std::max(lo, -M_PI);
    hi = std::min(hi, M_PI);
  }
}

// Least squares A x = y with the columns scaled to unit norm: the solution, the standard errors
// from the residual variance and the rank (relative tolerance 1e-9).
struct LeastSquares {
  Eigen::VectorXd x, se, residual;
  Eigen::Index rank = 0;
};

LeastSquares solve(const Eigen::MatrixXd& A, const Eigen::VectorXd& y) {
  LeastSquares r;
  Eigen::VectorXd scale = A.colwise().norm().transpose();
  for (Eigen::Index c = 0; c < scale.size(); ++c)
    if (!(scale(c) > 0)) scale(c) = 1;
  const Eigen::MatrixXd As = A * scale.cwiseInverse().asDiagonal();
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(As);
  qr.setThreshold(1e-9);
  r.rank = qr.rank();
  r.x = qr.solve(y).cwiseQuotient(scale);
  r.residual = y - A * r.x;
  const double dof = static_cast<double>(std::max<Eigen::Index>(1, A.rows() - A.cols()));
  const double variance = r.residual.squaredNorm() / dof;
  const Eigen::MatrixXd info = As.transpose() * As;
  const Eigen::MatrixXd cov = info.ldlt().solve(Eigen::MatrixXd::Identity(A.cols(), A.cols()));
  r.se = (variance * cov.diagonal()).cwiseMax(0).cwiseSqrt().cwiseQuotient(scale);
  return r;
}

// One row of the fit: joint `joint` of sample `sample`, moving.
struct Row {
  std::size_t sample;
  int joint;
  double y;  // logged torque less the model's Coriolis and centrifugal torque
};

// The friction columns (3 per joint: viscous, Coulomb, asymmetry) of the rows.
Eigen::MatrixXd frictionColumns(const std::vector<Row>& rows, const std::vector<Sample>& samples, int n) {
  Eigen::MatrixXd F = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rows.size()), 3 * n);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const int i = rows[r].joint;
    const double v = samples[rows[r].sample].qd(i);
    const auto row = static_cast<Eigen::Index>(r);
    F(row, 3 * i) = v;
    F(row, 3 * i + 1) = v > 0 ? 1.0 : -1.0;
    F(row, 3 * i + 2) = 1.0;
  }
  return F;
}

// The nominal gravity torque at the readings less the offsets, per row, and (with J) its
// derivative by each offset (central differences, step 1e-6).
void gravityRows(const ManipulatorModel& model, const std::vector<Row>& rows, const std::vector<Sample>& samples,
                 const JointVector& delta, Eigen::VectorXd& g, Eigen::MatrixXd* J) {
  const int n = model.getNumberOfJoints();
  ManipulatorData data(model);
  JointVector tau(n), plus(n), minus(n), q(n);
  g.resize(static_cast<Eigen::Index>(rows.size()));
  if (J) J->setZero(static_cast<Eigen::Index>(rows.size()), n);
  constexpr double h = 1e-6;
  std::size_t last = samples.size();
  std::vector<JointVector> columns(static_cast<std::size_t>(n), JointVector(n));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    if (rows[r].sample != last) {
      last = rows[r].sample;
      q = samples[last].q - delta;
      gravityTorque(model, data, q, tau);
      if (J) {
        for (int j = 0; j < n; ++j) {
          q(j) -= h;
          gravityTorque(model, data, q, plus);  // g(q - delta - h e_j): the offset grows
          q(j) += 2 * h;
          gravityTorque(model, data, q, minus);
          q(j) -= h;
          columns[static_cast<std::size_t>(j)] = (plus - minus) / (2 * h);
        }
      }
    }
    const auto row = static_cast<Eigen::Index>(r);
    g(row) = tau(rows[r].joint);
    if (J)
      for (int j = 0; j < n; ++j) (*J)(row, j) = columns[static_cast<std::size_t>(j)](rows[r].joint);
  }
}

Eigen::MatrixXd baseRegressorRows(const ManipulatorModel& model, const std::vector<Row>& rows,
                                  const std::vector<Sample>& samples, const JointVector& delta,
                                  const BaseParameters& base) {
  ManipulatorData data(model);
  Eigen::MatrixXd Y;
  Eigen::MatrixXd out(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(base.base.size()));
  std::size_t last = samples.size();
  for (std::size_t r = 0; r < rows.size(); ++r) {
    if (rows[r].sample != last) {
      last = rows[r].sample;
      gravityRegressor(model, data, samples[last].q - delta, Y);
    }
    for (std::size_t b = 0; b < base.base.size(); ++b)
      out(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(b)) = Y(rows[r].joint, base.base[b]);
  }
  return out;
}

Estimate estimate(const LeastSquares& ls, Eigen::Index k, double nominal) {
  Estimate e;
  e.value = ls.x(k);
  e.stdError = ls.se(k);
  e.nominal = nominal;
  e.resolution = e.stdError * std::sqrt(static_cast<double>(ls.residual.size()));
  return e;
}

}  // namespace

int gravityParameterCount(const ManipulatorModel& model) { return 4 * model.getNumberOfJoints(); }

std::string gravityParameterName(int k) {
  static const char* kinds[] = {"m", "mcx", "mcy", "mcz"};
  return std::string(kinds[k % 4]) + std::to_string(k / 4 + 1);
}

Eigen::VectorXd gravityParameters(const ManipulatorModel& model) {
  requireChain(model);
  const int n = model.getNumberOfJoints();
  Eigen::VectorXd theta(4 * n);
  for (int k = 0; k < n; ++k) {
    const LinkParameters& l = model.getLink(k);
    theta(4 * k) = l.mass;
    theta.segment<3>(4 * k + 1) = l.mass * V3(l.com);
  }
  return theta;
}

void gravityRegressor(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q, Eigen::MatrixXd& Y) {
  requireChain(model);
  const int n = model.getNumberOfJoints();
  forwardKinematics(model, data, q);
  Y.setZero(n, 4 * n);
  const V3 g = model.getGravity();
  for (int i = 0; i < n; ++i) {
    const Transform& axis = axisFrame(model, data, i);
    const V3 z = axis.block<3, 1>(0, 2);
    const V3 o = axis.topRightCorner<3, 1>();
    const V3 gz = g.cross(z);
    for (int k = i; k < n; ++k) {
      if (model.isPrismatic(i)) {
        Y(i, 4 * k) = -z.dot(g);
        continue;
      }
      const Transform& T = data.linkTransforms[static_cast<std::size_t>(k)];
      const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
      const V3 p = T.topRightCorner<3, 1>();
      Y(i, 4 * k) = -(p - o).dot(gz);
      Y.block<1, 3>(i, 4 * k + 1) = -(R.transpose() * gz).transpose();
    }
  }
}

std::string BaseParameters::expression(int b) const {
  const auto bi = static_cast<std::size_t>(b);
  std::string s = gravityParameterName(base[bi]);
  for (std::size_t d = 0; d < dependent.size(); ++d) {
    const double k = K(static_cast<Eigen::Index>(bi), static_cast<Eigen::Index>(d));
    if (std::abs(k) < 1e-9) continue;
    char buf[64];
    std::snprintf(buf, sizeof buf, " %c %.6g %s", k < 0 ? '-' : '+', std::abs(k), gravityParameterName(dependent[d]).c_str());
    s += buf;
  }
  return s;
}

Eigen::VectorXd BaseParameters::project(const Eigen::VectorXd& theta) const {
  Eigen::VectorXd b(static_cast<Eigen::Index>(base.size())), d(static_cast<Eigen::Index>(dependent.size()));
  for (std::size_t i = 0; i < base.size(); ++i) b(static_cast<Eigen::Index>(i)) = theta(base[i]);
  for (std::size_t i = 0; i < dependent.size(); ++i) d(static_cast<Eigen::Index>(i)) = theta(dependent[i]);
  return dependent.empty() ? b : Eigen::VectorXd(b + K * d);
}

BaseParameters findBaseParameters(const ManipulatorModel& model, int poses) {
  requireChain(model);
  if (poses < 1) throw std::invalid_argument("findBaseParameters: poses must be positive");
  const int n = model.getNumberOfJoints(), p = 4 * n;
  ManipulatorData data(model);
  std::mt19937 rng(12345);
  Eigen::MatrixXd W(static_cast<Eigen::Index>(n) * poses, p), Y;
  JointVector q(n);
  for (int s = 0; s < poses; ++s) {
    for (int j = 0; j < n; ++j) {
      double lo = 0, hi = 0;
      planningRange(model, j, lo, hi);
      q(j) = std::uniform_real_distribution<double>(lo, hi)(rng);
    }
    gravityRegressor(model, data, q, Y);
    W.middleRows(static_cast<Eigen::Index>(s) * n, n) = Y;
  }
  BaseParameters bp;
  const Eigen::VectorXd norms = W.colwise().norm().transpose();
  const double largest = norms.maxCoeff();
  std::vector<int> kept;
  for (int c = 0; c < p; ++c) (norms(c) <= 1e-9 * largest ? bp.unidentifiable : kept).push_back(c);
  Eigen::MatrixXd Wk(W.rows(), static_cast<Eigen::Index>(kept.size()));
  for (std::size_t c = 0; c < kept.size(); ++c) Wk.col(static_cast<Eigen::Index>(c)) = W.col(kept[c]);
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Wk);
  qr.setThreshold(1e-8);
  const Eigen::Index r = qr.rank(), m = Wk.cols();
  const auto& perm = qr.colsPermutation().indices();
  for (Eigen::Index c = 0; c < m; ++c)
    (c < r ? bp.base : bp.dependent).push_back(kept[static_cast<std::size_t>(perm(c))]);
  const Eigen::MatrixXd R = qr.matrixR().topRows(r).template triangularView<Eigen::Upper>();
  const Eigen::MatrixXd K = R.leftCols(r).triangularView<Eigen::Upper>().solve(R.rightCols(m - r));
  // In the order of the links (base and dependent parameters alike), small entries of K dropped.
  std::vector<Eigen::Index> rowOrder(bp.base.size()), colOrder(bp.dependent.size());
  for (std::size_t i = 0; i < rowOrder.size(); ++i) rowOrder[i] = static_cast<Eigen::Index>(i);
  for (std::size_t i = 0; i < colOrder.size(); ++i) colOrder[i] = static_cast<Eigen::Index>(i);
  std::sort(rowOrder.begin(), rowOrder.end(), [&](auto a, auto b) { return bp.base[static_cast<std::size_t>(a)] < bp.base[static_cast<std::size_t>(b)]; });
  std::sort(colOrder.begin(), colOrder.end(), [&](auto a, auto b) { return bp.dependent[static_cast<std::size_t>(a)] < bp.dependent[static_cast<std::size_t>(b)]; });
  bp.K.resize(r, m - r);
  std::vector<int> base, dependent;
  for (Eigen::Index i = 0; i < r; ++i) {
    base.push_back(bp.base[static_cast<std::size_t>(rowOrder[static_cast<std::size_t>(i)])]);
    for (Eigen::Index j = 0; j < m - r; ++j) {
      const double k = K(rowOrder[static_cast<std::size_t>(i)], colOrder[static_cast<std::size_t>(j)]);
      bp.K(i, j) = std::abs(k) < 1e-10 ? 0.0 : k;
    }
  }
  for (Eigen::Index j = 0; j < m - r; ++j) dependent.push_back(bp.dependent[static_cast<std::size_t>(colOrder[static_cast<std::size_t>(j)])]);
  bp.base = base;
  bp.dependent = dependent;
  return bp;
}

std::vector<PlanSegment> makePlan(const ManipulatorModel& model, const PlanOptions& options) {
  if (options.poses < 1 || !(options.passAmplitude > 0) || !(options.passSpeed > 0) || options.sweepSpeeds.empty() ||
      !(options.sweepRange > 0))
    throw std::invalid_argument("makePlan: sizes and speeds must be positive");
  for (double v : options.sweepSpeeds)
    if (!(v > 0)) throw std::invalid_argument("makePlan: sweep speeds must be positive");
  const int n = model.getNumberOfJoints();
  const JointVector fast = 0.3 * model.getVelocityLimit();  // moves between the logged motions
  JointVector lo(n), hi(n), middle(n);
  for (int j = 0; j < n; ++j) {
    planningRange(model, j, lo(j), hi(j));
    middle(j) = 0.5 * (lo(j) + hi(j));
  }
  // The servo holds the arm only where gravity leaves it torque to move: every point of every
  // motion keeps the gravity torque within 60 % of each joint's torque limit (checked at 21
  // points along the straight joint-space path each synchronised motion follows).
  ManipulatorData data(model);
  JointVector g(n);
  auto holdable = [&](const JointVector& q) {
    gravityTorque(model, data, q, g);
    for (int j = 0; j < n; ++j)
      if (std::abs(g(j)) > 0.6 * model.getTorqueLimit()(j)) return false;
    return true;
  };
  bool started = false;  // the first motion starts where the arm is, held already: only its end is checked
  auto pathHoldable = [&](const JointVector& a, const JointVector& b) {
    for (int k = started ? 0 : 20; k <= 20; ++k)
      if (!holdable(a + (b - a) * (k / 20.0))) return false;
    return true;
  };
  std::vector<PlanSegment> plan;
  JointVector at = model.getHomePosition();
  auto add = [&](const JointVector& target, const JointVector& vmax, bool log, const std::string& what) {
    PlanSegment s;
    s.target = target;
    s.vmax = vmax;
    s.log = log;
    s.what = what;
    plan.push_back(std::move(s));
    at = target;
    started = true;
  };
  const JointVector cap = 0.5 * model.getVelocityLimit();  // logged motions
  std::mt19937 rng(options.seed);
  JointVector passSpeed(n);
  for (int j = 0; j < n; ++j) passSpeed(j) = std::min(options.passSpeed, cap(j));
  const JointVector a = JointVector::Constant(n, options.passAmplitude);
  for (int k = 1; k <= options.poses; ++k) {
    JointVector pose(n);
    for (int attempt = 0;; ++attempt) {
      if (attempt == 10000)
        throw std::runtime_error("no pose found that the arm can hold within 60 % of its torque limits");
      for (int j = 0; j < n; ++j) {
        const double margin = 0.15 * (hi(j) - lo(j));
        pose(j) = std::uniform_real_distribution<double>(lo(j) + margin, hi(j) - margin)(rng);
      }
      if (pathHoldable(at, pose - a) && pathHoldable(pose - a, pose + a)) break;
    }
    add(pose - a, fast, false, "to pose " + std::to_string(k));
    add(pose + a, passSpeed, true, "pose " + std::to_string(k) + " +");
    add(pose - a, passSpeed, true, "pose " + std::to_string(k) + " -");
  }
  for (int j = 0; j < n; ++j) {
    // Each joint sweeps about the middle of its range, the others in the middle of theirs, or
    // else at the home position; the range shrinks until the arm can hold every point.
    const double margin = 0.1 * (hi(j) - lo(j));
    JointVector from, to;
    bool found = false;
    for (const JointVector* base : {static_cast<const JointVector*>(&middle), &model.getHomePosition()}) {
      for (double range = options.sweepRange; range > 0.05 && !found; range *= 0.8) {
        from = to = *base;
        from(j) = std::max(lo(j) + margin, middle(j) - range);
        to(j) = std::min(hi(j) - margin, middle(j) + range);
        found = pathHoldable(at, from) && pathHoldable(from, to);
      }
      if (found) break;
    }
    if (!found)
      throw std::runtime_error("joint " + std::to_string(j + 1) + ": no sweep the arm can hold within 60 % of its torque limits");
    add(from, fast, false, "to joint " + std::to_string(j + 1) + " sweeps");
    for (double v : options.sweepSpeeds) {
      JointVector vmax = fast;
      vmax(j) = std::min(v, cap(j));
      char speed[32];
      std::snprintf(speed, sizeof speed, "%.3g", vmax(j));
      add(to, vmax, true, "joint " + std::to_string(j + 1) + " sweep " + speed + " +");
      add(from, vmax, true, "joint " + std::to_string(j + 1) + " sweep " + speed + " -");
    }
  }
  return plan;
}

void modelFriction(const ManipulatorModel& model, int joint, double& viscous, double& coulomb, double& asymmetry) {
  const LinkParameters& l = model.getLink(joint);
  const double G = std::abs(l.gearRatio);
  viscous = l.viscousFriction * G * G;
  const double up = G * std::abs(l.coulombFrictionPositive), down = G * std::abs(l.coulombFrictionNegative);
  coulomb = 0.5 * (up + down);
  asymmetry = 0.5 * (up - down);
}

Result fit(const ManipulatorModel& model, const std::vector<Sample>& samples, const BaseParameters& base,
           bool fitOffsets) {
  requireChain(model);
  const int n = model.getNumberOfJoints();
  Result result;
  result.baseParameters = base;
  // Rows: moving, unsaturated joints; the logged torque less the model's inertial, Coriolis and
  // centrifugal torque.
  ManipulatorData data(model);
  DynamicsOptions noGravity;
  noGravity.gravity = false;
  noGravity.motorInertia = true;
  std::vector<Row> rows;
  result.rowsPerJoint.assign(static_cast<std::size_t>(n), 0);
  for (std::size_t s = 0; s < samples.size(); ++s) {
    const Sample& x = samples[s];
    const JointVector& c = inverseDynamics(model, data, x.q, x.qd, x.qdd, noGravity);
    for (int i = 0; i < n; ++i) {
      if (std::abs(x.qd(i)) < 0.01 || std::abs(x.tau(i)) >= 0.999 * model.getTorqueLimit()(i)) continue;
      rows.push_back(Row{s, i, x.tau(i) - c(i)});
      ++result.rowsPerJoint[static_cast<std::size_t>(i)];
    }
  }
  for (int i = 0; i < n; ++i)
    if (result.rowsPerJoint[static_cast<std::size_t>(i)] < 20)
      throw std::runtime_error("joint " + std::to_string(i + 1) + ": only " +
                               std::to_string(result.rowsPerJoint[static_cast<std::size_t>(i)]) +
                               " logged samples in motion (need 20)");
  Eigen::VectorXd y(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) y(static_cast<Eigen::Index>(r)) = rows[r].y;
  const Eigen::MatrixXd F = frictionColumns(rows, samples, n);

  // Step 1: the offsets, Gauss-Newton on the model's gravity.
  JointVector delta = JointVector::Zero(n);
  result.offset.assign(static_cast<std::size_t>(n), Estimate());
  result.offsetObservable.assign(static_cast<std::size_t>(n), false);
  result.offsetSeparable.assign(static_cast<std::size_t>(n), false);
  result.offsetSensitivity.assign(static_cast<std::size_t>(n), 0.0);
  Eigen::VectorXd g;
  Eigen::MatrixXd J;
  if (fitOffsets) {
    gravityRows(model, rows, samples, delta, g, &J);
    // Observable: the offset's column, with the friction columns projected out, is not
    // (numerically) zero or a combination of the other offsets' columns.
    Eigen::MatrixXd proj(J.rows(), n);
    for (int j = 0; j < n; ++j) proj.col(j) = solve(F, J.col(j)).residual;
    const double largest = proj.colwise().norm().maxCoeff();
    std::vector<int> observable;
    if (largest > 0) {
      Eigen::MatrixXd scaled = proj / largest;
      Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(scaled);
      qr.setThreshold(1e-6);
      for (Eigen::Index c = 0; c < qr.rank(); ++c) observable.push_back(static_cast<int>(qr.colsPermutation().indices()(c)));
      std::sort(observable.begin(), observable.end());
    }
    for (int j : observable) result.offsetObservable[static_cast<std::size_t>(j)] = true;
    const auto m = static_cast<Eigen::Index>(observable.size());
    LeastSquares last;
    for (int it = 0; it < 30 && m > 0; ++it) {
      Eigen::MatrixXd A(y.size(), F.cols() + m);
      A.leftCols(F.cols()) = F;
      for (Eigen::Index c = 0; c < m; ++c) A.col(F.cols() + c) = J.col(observable[static_cast<std::size_t>(c)]);
      last = solve(A, y - g);
      // Converged when every step is below 1e-10 rad or a thousandth of its standard error (a
      // poorly observable offset keeps moving by rounding in its finite differences otherwise).
      bool converged = true;
      for (Eigen::Index c = 0; c < m; ++c) {
        const double d = last.x(F.cols() + c);
        delta(observable[static_cast<std::size_t>(c)]) += d;
        if (std::abs(d) > std::max(1e-10, 1e-3 * last.se(F.cols() + c))) converged = false;
      }
      result.offsetIterations = it + 1;
      gravityRows(model, rows, samples, delta, g, &J);
      if (converged) break;
    }
    const double count = static_cast<double>(y.size());
    if (m > 0) result.offsetResidualRms = std::sqrt(last.residual.squaredNorm() / count);
    for (Eigen::Index c = 0; c < m; ++c) {
      const auto j = static_cast<std::size_t>(observable[static_cast<std::size_t>(c)]);
      result.offset[j] = estimate(last, F.cols() + c, 0);
      result.offset[j].value = delta(static_cast<Eigen::Index>(j));
      result.offsetSensitivity[j] = proj.col(static_cast<Eigen::Index>(j)).norm() / std::sqrt(count);
    }
    // Separable from the gravity parameters: the offset's column is not in the span of the base
    // regressor and the friction columns.
    const Eigen::MatrixXd Yb = baseRegressorRows(model, rows, samples, delta, base);
    Eigen::MatrixXd B(y.size(), Yb.cols() + F.cols());
    B << Yb, F;
    for (int j : observable) {
      const double rel = solve(B, J.col(j)).residual.norm() / J.col(j).norm();
      result.offsetSeparable[static_cast<std::size_t>(j)] = rel > 1e-4;
    }
  }

  // Step 2: gravity base parameters and friction at the corrected angles.
  const Eigen::MatrixXd Yb = baseRegressorRows(model, rows, samples, delta, base);
  Eigen::MatrixXd A(y.size(), Yb.cols() + F.cols());
  A << Yb, F;
  const LeastSquares ls = solve(A, y);
  if (ls.rank < A.cols())
    throw std::runtime_error("the plan does not excite every parameter (rank " + std::to_string(ls.rank) + " of " +
                             std::to_string(A.cols()) + "): add poses");
  result.residualRms = std::sqrt(ls.residual.squaredNorm() / static_cast<double>(ls.residual.size()));
  const Eigen::VectorXd nominal = base.project(gravityParameters(model));
  for (Eigen::Index b = 0; b < Yb.cols(); ++b) result.gravity.push_back(estimate(ls, b, nominal(b)));
  for (int i = 0; i < n; ++i) {
    double fv = 0, fc = 0, fa = 0;
    modelFriction(model, i, fv, fc, fa);
    const Eigen::Index c = Yb.cols() + 3 * i;
    result.viscous.push_back(estimate(ls, c, fv));
    result.coulomb.push_back(estimate(ls, c + 1, fc));
    result.asymmetry.push_back(estimate(ls, c + 2, fa));
  }
  return result;
}

}  // namespace rp::calibration
