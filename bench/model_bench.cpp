// Kinematics and dynamics of the Puma 560 and the WAM 7, ours next to Orocos KDL's solvers
// (ChainFkSolverPos_recursive, ChainJntToJacSolver, ChainIdSolver_RNE, ChainDynParam::JntToMass,
// ChainFdSolver_RNE, ChainIkSolverPos_LMA), on the same 64 seeded random configurations; and ours
// on the same two arms loaded from URDF (Arg 16 and 17: the Placement form next to DH); and, when
// built with Pinocchio (RP_HAVE_PINOCCHIO, see bench/CMakeLists.txt), Pinocchio's CRBA, RNEA and
// ABA on the same arms.
#include <benchmark/benchmark.h>

#include <kdl/chaindynparam.hpp>
#include <kdl/chainfdsolver_recursive_newton_euler.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include "../tests/model/KdlChain.hpp"
#include "rp/model/Model.hpp"

#ifdef RP_HAVE_PINOCCHIO
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody/data.hpp>
#include <pinocchio/multibody/model.hpp>
#endif

namespace {

using namespace rp;

struct Robot {
  std::unique_ptr<ManipulatorModel> model;
  std::unique_ptr<ManipulatorData> data;
  KDL::Chain chain;
  std::vector<JointVector> q, qd, qdd;
  std::vector<KDL::JntArray> kq, kqd, kqdd;
  std::vector<Transform> poses;

  explicit Robot(std::unique_ptr<ManipulatorModel> m) : model(std::move(m)) {
    data = std::make_unique<ManipulatorData>(*model);
    chain = test::kdlChain(*model);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    const int n = model->getNumberOfJoints();
    for (int k = 0; k < 64; ++k) {
      JointVector a(n), b(n), c(n);
      for (int i = 0; i < n; ++i) {
        a(i) = model->getPositionMin()(i) + u(rng) * (model->getPositionMax()(i) - model->getPositionMin()(i));
        b(i) = 2 * u(rng) - 1;
        c(i) = 4 * u(rng) - 2;
      }
      q.push_back(a);
      qd.push_back(b);
      qdd.push_back(c);
      kq.push_back(test::kdlJoints(a));
      kqd.push_back(test::kdlJoints(b));
      kqdd.push_back(test::kdlJoints(c));
      poses.push_back(forwardKinematics(*model, *data, a));
    }
  }
};

Robot& puma() {
  static Robot r(std::make_unique<Puma560Model>());
  return r;
}
Robot& wam7() {
  static Robot r(std::make_unique<WAM7Model>());
  return r;
}
// The same arms written as URDF and loaded back (DHConvention::Placement: each joint's fixed
// placement, then its motion), side by side with their DH models: Arg 16 and 17.
std::unique_ptr<ManipulatorModel> throughUrdf(const ManipulatorModel& model) {
  const std::string file = "/tmp/rp_model_bench_" + model.getName() + ".urdf";
  std::ofstream(file) << toUrdf(model);
  UrdfOptions options;
  options.tip = "tool";
  std::unique_ptr<ManipulatorModel> m = loadUrdf(file, options);
  std::remove(file.c_str());
  return m;
}
Robot& pumaUrdf() {
  static Robot r(throughUrdf(Puma560Model()));
  return r;
}
Robot& wam7Urdf() {
  static Robot r(throughUrdf(WAM7Model()));
  return r;
}
Robot& robot(const benchmark::State& s) {
  switch (s.range(0)) {
    case 6: return puma();
    case 16: return pumaUrdf();
    case 17: return wam7Urdf();
    default: return wam7();
  }
}

void ForwardKinematics_rp(benchmark::State& s) {
  Robot& r = robot(s);
  std::size_t k = 0;
  for (auto _ : s) benchmark::DoNotOptimize(forwardKinematics(*r.model, *r.data, r.q[k++ & 63]));
}
void ForwardKinematics_KDL(benchmark::State& s) {
  Robot& r = robot(s);
  KDL::ChainFkSolverPos_recursive fk(r.chain);
  KDL::Frame f;
  std::size_t k = 0;
  for (auto _ : s) {
    fk.JntToCart(r.kq[k++ & 63], f);
    benchmark::DoNotOptimize(f);
  }
}
void Jacobian_rp(benchmark::State& s) {
  Robot& r = robot(s);
  std::size_t k = 0;
  for (auto _ : s) benchmark::DoNotOptimize(jacobian(*r.model, *r.data, r.q[k++ & 63]).data());
}
void Jacobian_KDL(benchmark::State& s) {
  Robot& r = robot(s);
  KDL::ChainJntToJacSolver jac(r.chain);
  KDL::Jacobian J(r.chain.getNrOfJoints());
  std::size_t k = 0;
  for (auto _ : s) {
    jac.JntToJac(r.kq[k++ & 63], J);
    benchmark::DoNotOptimize(J.data.data());
  }
}
void InverseDynamics_rp(benchmark::State& s) {
  Robot& r = robot(s);
  std::size_t k = 0;
  for (auto _ : s) {
    const std::size_t i = k++ & 63;
    benchmark::DoNotOptimize(inverseDynamics(*r.model, *r.data, r.q[i], r.qd[i], r.qdd[i]).data());
  }
}
void InverseDynamics_KDL(benchmark::State& s) {
  Robot& r = robot(s);
  KDL::ChainIdSolver_RNE id(r.chain, KDL::Vector(0, 0, -9.81));
  KDL::JntArray tau(r.chain.getNrOfJoints());
  KDL::Wrenches w(r.chain.getNrOfSegments(), KDL::Wrench::Zero());
  std::size_t k = 0;
  for (auto _ : s) {
    const std::size_t i = k++ & 63;
    id.CartToJnt(r.kq[i], r.kqd[i], r.kqdd[i], w, tau);
    benchmark::DoNotOptimize(tau.data.data());
  }
}
void MassMatrix_rp(benchmark::State& s) {
  Robot& r = robot(s);
  std::size_t k = 0;
  for (auto _ : s) benchmark::DoNotOptimize(massMatrix(*r.model, *r.data, r.q[k++ & 63]).data());
}
void MassMatrix_KDL(benchmark::State& s) {
  Robot& r = robot(s);
  KDL::ChainDynParam dyn(r.chain, KDL::Vector(0, 0, -9.81));
  KDL::JntSpaceInertiaMatrix M(r.chain.getNrOfJoints());
  std::size_t k = 0;
  for (auto _ : s) {
    dyn.JntToMass(r.kq[k++ & 63], M);
    benchmark::DoNotOptimize(M.data.data());
  }
}
// The gravity torque: ours from forward kinematics and link mass moments, KDL's by Newton-Euler.
void GravityTorque_rp(benchmark::State& s) {
  Robot& r = robot(s);
  JointVector g(r.model->getNumberOfJoints());
  std::size_t k = 0;
  for (auto _ : s) {
    gravityTorque(*r.model, *r.data, r.q[k++ & 63], g);
    benchmark::DoNotOptimize(g.data());
  }
}
void GravityTorque_KDL(benchmark::State& s) {
  Robot& r = robot(s);
  KDL::ChainDynParam dyn(r.chain, KDL::Vector(0, 0, -9.81));
  KDL::JntArray g(r.chain.getNrOfJoints());
  std::size_t k = 0;
  for (auto _ : s) {
    dyn.JntToGravity(r.kq[k++ & 63], g);
    benchmark::DoNotOptimize(g.data.data());
  }
}
void ForwardDynamics_rp(benchmark::State& s) {
  Robot& r = robot(s);
  std::size_t k = 0;
  for (auto _ : s) {
    const std::size_t i = k++ & 63;
    benchmark::DoNotOptimize(forwardDynamics(*r.model, *r.data, r.q[i], r.qd[i], r.qdd[i]).data());
  }
}
// Featherstone's articulated-body algorithm (forwardDynamics() is the mass-matrix route: gravity
// from mass moments, velocity products by a spatial Newton-Euler pass, CRBA, LDL^T).
void ForwardDynamicsArticulatedBody_rp(benchmark::State& s) {
  Robot& r = robot(s);
  std::size_t k = 0;
  for (auto _ : s) {
    const std::size_t i = k++ & 63;
    benchmark::DoNotOptimize(forwardDynamicsArticulatedBody(*r.model, *r.data, r.q[i], r.qd[i], r.qdd[i]).data());
  }
}
BENCHMARK(ForwardDynamicsArticulatedBody_rp)->Arg(6)->Arg(7)->Arg(16)->Arg(17);
void ForwardDynamics_KDL(benchmark::State& s) {
  Robot& r = robot(s);
  KDL::ChainFdSolver_RNE fd(r.chain, KDL::Vector(0, 0, -9.81));
  KDL::JntArray qdd(r.chain.getNrOfJoints());
  KDL::Wrenches w(r.chain.getNrOfSegments(), KDL::Wrench::Zero());
  std::size_t k = 0;
  for (auto _ : s) {
    const std::size_t i = k++ & 63;
    fd.CartToJnt(r.kq[i], r.kqd[i], r.kqdd[i], w, qdd);
    benchmark::DoNotOptimize(qdd.data.data());
  }
}
// Numeric IK from the home position to the random reachable poses.
void InverseKinematics_rp(benchmark::State& s) {
  Robot& r = robot(s);
  JointVector q(r.model->getNumberOfJoints());
  IkOptions o;
  o.positionTolerance = o.orientationTolerance = 1e-5;
  std::size_t k = 0, solved = 0, total = 0;
  for (auto _ : s) {
    solved += inverseKinematics(*r.model, *r.data, r.poses[k++ & 63], r.model->getHomePosition(), q, o) == IkStatus::Solved;
    ++total;
  }
  s.counters["solved"] = static_cast<double>(solved) / static_cast<double>(total);
}
void InverseKinematics_KDL(benchmark::State& s) {
  Robot& r = robot(s);
  KDL::ChainIkSolverPos_LMA ik(r.chain, 1e-5, 500, 1e-15);
  KDL::JntArray q(r.chain.getNrOfJoints());
  const KDL::JntArray seed = test::kdlJoints(r.model->getHomePosition());
  std::size_t k = 0, solved = 0, total = 0;
  for (auto _ : s) {
    const Transform& T = r.poses[k++ & 63];
    KDL::Frame f;
    for (int a = 0; a < 3; ++a) {
      f.p(a) = T(a, 3);
      for (int b = 0; b < 3; ++b) f.M(a, b) = T(a, b);
    }
    solved += ik.CartToJnt(seed, f, q) >= 0;
    ++total;
  }
  s.counters["solved"] = static_cast<double>(solved) / static_cast<double>(total);
}

// The IK protocol: 10,000 seeded random reachable poses (forward kinematics of random
// joint vectors within the limits), each solved from a random seed within the limits. One
// benchmark iteration solves them all; counters: solve rate, mean and median microseconds per
// pose (wall clock of each solve). KDL's LMA solver has no joint limits, so it may count
// solutions outside them as solved.
struct IkSet {
  std::vector<Transform> poses;
  std::vector<JointVector> seeds;
};
const IkSet& ikSet(Robot& r) {
  static std::map<const Robot*, IkSet> sets;
  IkSet& set = sets[&r];
  if (set.poses.empty()) {
    std::mt19937_64 rng(31337);
    const int n = r.model->getNumberOfJoints();
    auto random = [&] {
      JointVector q(n);
      for (int i = 0; i < n; ++i)
        q(i) = std::uniform_real_distribution<double>(r.model->getPositionMin()(i), r.model->getPositionMax()(i))(rng);
      return q;
    };
    for (int k = 0; k < 10000; ++k) {
      set.poses.push_back(forwardKinematics(*r.model, *r.data, random()));
      set.seeds.push_back(random());
    }
  }
  return set;
}
template <typename Solve>
void ikProtocol(benchmark::State& s, Robot& r, Solve solve) {
  const IkSet& set = ikSet(r);
  std::vector<double> us(set.poses.size());
  std::size_t solved = 0;
  for (auto _ : s) {
    solved = 0;
    for (std::size_t k = 0; k < set.poses.size(); ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      solved += solve(set.poses[k], set.seeds[k], k);
      us[k] = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    }
  }
  std::vector<double> sorted = us;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0;
  for (double x : us) sum += x;
  s.counters["solved"] = static_cast<double>(solved) / static_cast<double>(set.poses.size());
  s.counters["mean_us"] = sum / static_cast<double>(us.size());
  s.counters["median_us"] = sorted[sorted.size() / 2];
  s.counters["p99_us"] = sorted[sorted.size() * 99 / 100];
}
void InverseKinematics10k_rp(benchmark::State& s) {
  Robot& r = robot(s);
  JointVector q(r.model->getNumberOfJoints());
  IkOptions o;  // default tolerances 1e-6 m / 1e-6 rad
  if (s.range(1) == 1) o.positionTolerance = o.orientationTolerance = 1e-5;
  ikProtocol(s, r, [&](const Transform& T, const JointVector& seed, std::size_t k) {
    o.randomSeed = k + 1;
    return inverseKinematics(*r.model, *r.data, T, seed, q, o) == IkStatus::Solved;
  });
}
void InverseKinematics10k_KDL(benchmark::State& s) {
  Robot& r = robot(s);
  KDL::ChainIkSolverPos_LMA ik(r.chain, s.range(1) == 1 ? 1e-5 : 1e-6, 500, 1e-15);
  KDL::JntArray q(r.chain.getNrOfJoints());
  ikProtocol(s, r, [&](const Transform& T, const JointVector& seed, std::size_t) {
    return ik.CartToJnt(test::kdlJoints(seed), test::kdlFrame(T), q) >= 0;
  });
}
BENCHMARK(InverseKinematics10k_rp)->Args({7, 0})->Args({7, 1})->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(InverseKinematics10k_KDL)->Args({7, 0})->Args({7, 1})->Iterations(1)->Unit(benchmark::kMillisecond);

// All eight closed-form branches of the Puma 560 (the goal: under 2 us).
void Puma560ClosedFormIk_rp(benchmark::State& s) {
  Robot& r = puma();
  const auto& model = static_cast<const Puma560Model&>(*r.model);
  std::array<Puma560IkSolution, 8> all;
  std::size_t k = 0;
  for (auto _ : s) {
    model.inverseKinematicsAll(r.poses[k++ & 63], all);
    benchmark::DoNotOptimize(all.data());
  }
}
BENCHMARK(Puma560ClosedFormIk_rp);

#ifdef RP_HAVE_PINOCCHIO
// Pinocchio's model of one of our arms (revolute and prismatic joints; no mimic joints), built from
// our frames at q = 0: joint i turns (or slides) about z of its axis frame (frame i-1 in standard
// DH, frame i otherwise), so its placement is the axis frame of joint i-1 to that of joint i, and
// link i hangs on joint i at its link frame. Checked against our mass matrix when built.
struct PinocchioArm {
  pinocchio::Model model;
  std::unique_ptr<pinocchio::Data> data;
  std::vector<Eigen::VectorXd> q, qd, qdd;

  explicit PinocchioArm(Robot& r) {
    const ManipulatorModel& m = *r.model;
    const int n = m.getNumberOfJoints();
    ManipulatorData d(m);
    forwardKinematics(m, d, JointVector::Zero(n));
    auto se3 = [](const Transform& T) {
      return pinocchio::SE3(Eigen::Matrix3d(T.topLeftCorner<3, 3>()), Eigen::Vector3d(T.topRightCorner<3, 1>()));
    };
    auto axis = [&](int i) -> Transform {
      if (m.getConvention() != DHConvention::Standard) return d.linkTransforms[static_cast<std::size_t>(i)];
      return i == 0 ? m.getBaseTransform() : d.linkTransforms[static_cast<std::size_t>(i - 1)];
    };
    pinocchio::JointIndex parent = 0;
    pinocchio::SE3 parentAxis = pinocchio::SE3::Identity();
    for (int i = 0; i < n; ++i) {
      const LinkParameters& l = m.getLink(i);
      const pinocchio::SE3 a = se3(axis(i));
      const pinocchio::SE3 placement = parentAxis.actInv(a);
      std::string name = "j";  // (not "j" + ...: GCC 12's -Wrestrict false positive at -O3)
      name += std::to_string(i);
      parent = m.isPrismatic(i) ? model.addJoint(parent, pinocchio::JointModelPZ(), placement, name)
                                : model.addJoint(parent, pinocchio::JointModelRZ(), placement, name);
      model.appendBodyToJoint(parent, pinocchio::Inertia(l.mass, Eigen::Vector3d(l.com), Eigen::Matrix3d(l.inertia)),
                              a.actInv(se3(d.linkTransforms[static_cast<std::size_t>(i)])));
      parentAxis = a;
    }
    model.gravity.linear(m.getGravity());
    data = std::make_unique<pinocchio::Data>(model);
    for (std::size_t k = 0; k < r.q.size(); ++k) {
      q.emplace_back(r.q[k]);
      qd.emplace_back(r.qd[k]);
      qdd.emplace_back(r.qdd[k]);
    }
    // The same mass matrix as ours (Pinocchio fills the upper triangle).
    double worst = 0;
    for (std::size_t k = 0; k < q.size(); ++k) {
      Eigen::MatrixXd M = pinocchio::crba(model, *data, q[k]);
      M.triangularView<Eigen::StrictlyLower>() = M.transpose().triangularView<Eigen::StrictlyLower>();
      const JointMatrix& ours = massMatrix(m, *r.data, r.q[k]);
      worst = std::max(worst, (M - ours).cwiseAbs().maxCoeff() / ours.cwiseAbs().maxCoeff());
    }
    if (worst > 1e-12) {
      std::fprintf(stderr, "model_bench: Pinocchio's %s differs from ours: mass matrix %.1e relative\n",
                   m.getName().c_str(), worst);
      std::exit(1);
    }
  }
};
PinocchioArm& pinocchioArm(const benchmark::State& s) {
  static PinocchioArm pumaArm(puma()), wamArm(wam7());
  return s.range(0) == 6 ? pumaArm : wamArm;
}
// range(1): 0 Pinocchio's default (Convention::LOCAL), 1 Convention::WORLD.
void MassMatrix_Pinocchio(benchmark::State& s) {
  PinocchioArm& p = pinocchioArm(s);
  const auto convention = s.range(1) == 1 ? pinocchio::Convention::WORLD : pinocchio::Convention::LOCAL;
  std::size_t k = 0;
  for (auto _ : s) benchmark::DoNotOptimize(pinocchio::crba(p.model, *p.data, p.q[k++ & 63], convention).data());
}
// Newton-Euler (rnea) or, with forward, the articulated-body algorithm (aba) on the same states.
template <bool forward>
void pinocchioDynamics(benchmark::State& s) {
  PinocchioArm& p = pinocchioArm(s);
  std::size_t k = 0;
  for (auto _ : s) {
    const std::size_t i = k++ & 63;
    if constexpr (forward) {
      benchmark::DoNotOptimize(pinocchio::aba(p.model, *p.data, p.q[i], p.qd[i], p.qdd[i]).data());
    } else {
      benchmark::DoNotOptimize(pinocchio::rnea(p.model, *p.data, p.q[i], p.qd[i], p.qdd[i]).data());
    }
  }
}
void InverseDynamics_Pinocchio(benchmark::State& s) { pinocchioDynamics<false>(s); }
void ForwardDynamics_Pinocchio(benchmark::State& s) { pinocchioDynamics<true>(s); }
BENCHMARK(MassMatrix_Pinocchio)->Args({6, 0})->Args({6, 1})->Args({7, 0})->Args({7, 1});
BENCHMARK(InverseDynamics_Pinocchio)->Arg(6)->Arg(7);
BENCHMARK(ForwardDynamics_Pinocchio)->Arg(6)->Arg(7);
#endif

#define RP_PAIR(name)                              \
  BENCHMARK(name##_rp)->Arg(6)->Arg(7)->Arg(16)->Arg(17); \
  BENCHMARK(name##_KDL)->Arg(6)->Arg(7)

RP_PAIR(ForwardKinematics);
RP_PAIR(Jacobian);
RP_PAIR(InverseDynamics);
RP_PAIR(MassMatrix);
RP_PAIR(GravityTorque);
RP_PAIR(ForwardDynamics);
RP_PAIR(InverseKinematics);

}  // namespace

BENCHMARK_MAIN();
