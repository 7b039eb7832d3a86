// Trajectory generation next to Orocos KDL's trajectory classes, in one binary.
//
// Joint space, 6 joints (Puma 560 limits) and 7 joints (WAM 7 limits), over 1,024 seeded random
// start/target pairs within the joint limits:
// - plan: our time-optimal, jerk-limited (S-curve), synchronised rest-to-rest line
//   (JointLineSegment) next to KDL's per-joint VelocityProfile_Trap (SetProfile for every joint,
//   then SetProfileDuration to the slowest joint's duration, which is how KDL synchronises). KDL's
//   profile is trapezoidal (no jerk limit), so it does less work than ours.
// - evaluate: position, velocity and acceleration of every joint at one instant (one servo cycle).
// - the queue: QueueTrajectoryGenerator::getCurrentSetpoint, what the servo loop calls every
//   cycle (a queued motion with blends, read at 1 kHz).
// Cartesian space, Puma 560: a straight line of 0.3 m with a rotation: our plan (IK nodes along
// the line, refined until the joint path stays within 1e-7 m of it; the output is a joint path)
// next to KDL's Path_RoundedComposite + Trajectory_Segment with a trapezoidal profile (a Cartesian
// path only, no inverse kinematics). Evaluation: ours gives joint position, velocity and
// acceleration; KDL's gives the frame, twist and acceleration twist.
#include <benchmark/benchmark.h>

#include <kdl/path_roundedcomposite.hpp>
#include <kdl/rotational_interpolation_sa.hpp>
#include <kdl/trajectory_segment.hpp>
#include <kdl/velocityprofile_trap.hpp>

#include <chrono>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <random>
#include <thread>
#include <vector>

#include "CartesianPath.hpp"
#include "Segment.hpp"
#include "rp/RoboticPlatform.hpp"
#include "rp/trajectory/JointLineSegment.hpp"

namespace {

using namespace rp;

constexpr int kPairs = 1024;

const ManipulatorModel& modelFor(int joints) {
  static const Puma560Model puma;
  static const WAM7Model wam;
  return joints == 6 ? static_cast<const ManipulatorModel&>(puma) : wam;
}

struct Pairs {
  std::vector<JointVector> start, target;
};

const Pairs& pairsFor(int joints) {
  static Pairs cache[2];
  Pairs& p = cache[joints - 6];
  if (p.start.empty()) {
    const ManipulatorModel& model = modelFor(joints);
    std::mt19937_64 rng(20261123 + joints);
    std::uniform_real_distribution<double> unit(0.05, 0.95);
    for (int k = 0; k < kPairs; ++k) {
      JointVector a(joints), b(joints);
      for (int i = 0; i < joints; ++i) {
        const double lo = model.getPositionMin()(i), range = model.getPositionMax()(i) - lo;
        a(i) = lo + unit(rng) * range;
        b(i) = lo + unit(rng) * range;
      }
      p.start.push_back(a);
      p.target.push_back(b);
    }
  }
  return p;
}

void BM_JointPlan_Ours(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const ManipulatorModel& model = modelFor(n);
  const Pairs& p = pairsFor(n);
  int k = 0;
  for (auto _ : state) {
    JointLineSegment segment(p.start[k], p.target[k], model.getVelocityLimit(), model.getAccelerationLimit(),
                             model.getJerkLimit());
    benchmark::DoNotOptimize(segment.getDuration());
    k = (k + 1) % kPairs;
  }
}

// KDL: one trapezoidal profile per joint, synchronised to the slowest joint.
void planKdl(const JointVector& a, const JointVector& b, const ManipulatorModel& model,
             std::vector<KDL::VelocityProfile_Trap>& profiles) {
  const Eigen::Index n = a.size();
  double slowest = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    profiles[i].SetMax(model.getVelocityLimit()(i), model.getAccelerationLimit()(i));
    profiles[i].SetProfile(a(i), b(i));
    slowest = std::max(slowest, profiles[i].Duration());
  }
  for (Eigen::Index i = 0; i < n; ++i) profiles[i].SetProfileDuration(a(i), b(i), slowest);
}

void BM_JointPlan_KdlTrap(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const ManipulatorModel& model = modelFor(n);
  const Pairs& p = pairsFor(n);
  std::vector<KDL::VelocityProfile_Trap> profiles(n, KDL::VelocityProfile_Trap(1, 1));
  int k = 0;
  for (auto _ : state) {
    planKdl(p.start[k], p.target[k], model, profiles);
    benchmark::DoNotOptimize(profiles.back().Duration());
    k = (k + 1) % kPairs;
  }
}

void BM_JointEval_Ours(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const ManipulatorModel& model = modelFor(n);
  const Pairs& p = pairsFor(n);
  std::vector<JointLineSegment> segments;
  for (int k = 0; k < kPairs; ++k) {
    segments.emplace_back(p.start[k], p.target[k], model.getVelocityLimit(), model.getAccelerationLimit(),
                          model.getJerkLimit());
  }
  Setpoint sp;
  sp.position = sp.velocity = sp.acceleration = JointVector(n);
  int k = 0;
  double fraction = 0;
  for (auto _ : state) {
    segments[k].evaluate(fraction * segments[k].getDuration(), sp);
    benchmark::DoNotOptimize(sp.acceleration.data());
    k = (k + 1) % kPairs;
    fraction += 0.0137;
    if (fraction > 1) fraction -= 1;
  }
}

void BM_JointEval_KdlTrap(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const ManipulatorModel& model = modelFor(n);
  const Pairs& p = pairsFor(n);
  std::vector<std::vector<KDL::VelocityProfile_Trap>> plans(kPairs, std::vector<KDL::VelocityProfile_Trap>(
                                                                       n, KDL::VelocityProfile_Trap(1, 1)));
  for (int k = 0; k < kPairs; ++k) planKdl(p.start[k], p.target[k], model, plans[k]);
  JointVector q(n), qd(n), qdd(n);
  int k = 0;
  double fraction = 0;
  for (auto _ : state) {
    const double t = fraction * plans[k][0].Duration();
    for (int i = 0; i < n; ++i) {
      q(i) = plans[k][i].Pos(t);
      qd(i) = plans[k][i].Vel(t);
      qdd(i) = plans[k][i].Acc(t);
    }
    benchmark::DoNotOptimize(qdd.data());
    k = (k + 1) % kPairs;
    fraction += 0.0137;
    if (fraction > 1) fraction -= 1;
  }
}

// The queue as the servo loop reads it: a simulated arm whose loop is paused (the simulated clock
// does not advance), 16 queued motions through random via points with blends, read at 1 kHz.
void BM_QueueSetpoint_Ours(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  RoboticPlatform::setConfiguration(Configuration());
  RoboticPlatform::setSimulationModeOn();
  RoboticPlatform::useSimulatedClock();
  auto& clock = dynamic_cast<SimulatedClock&>(RoboticPlatform::getDefaultClock());
  std::unique_ptr<DefaultManipulator> arm;
  if (n == 6) arm = std::make_unique<Puma560>();
  else arm = std::make_unique<WAM>("", 7);
  clock.pause();
  while (arm->getCycleCount() < 1) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const Pairs& p = pairsFor(n);
  double cycles = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto tragen = std::make_unique<DefaultTrajectoryGenerator<>>();
    tragen->setJointBlendRadius(0.2);
    arm->setTrajectoryGenerator(*tragen);
    for (int k = 0; k < 16; ++k) tragen->moveRadians(p.target[k]);
    Setpoint sp;
    sp.position = sp.velocity = sp.acceleration = JointVector(n);
    const double t0 = 1.0;
    long count = 0;
    state.ResumeTiming();
    while (tragen->getCurrentSetpoint(t0 + 1e-3 * static_cast<double>(count), sp) && !tragen->isDone()) ++count;
    state.PauseTiming();
    cycles += static_cast<double>(count);
    arm->clearTrajectoryGenerator();
    tragen.reset();
    state.ResumeTiming();
  }
  state.counters["ns_per_cycle"] =
      benchmark::Counter(cycles, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  clock.resume();
}

// Cartesian: a 0.3 m line with a 0.4 rad rotation from a Puma pose in the middle of the work space.
struct CartesianCase {
  Puma560Model model;
  JointVector qStart = JointVector(6);
  Transform start, goal;
  CartesianLimits limits;
  CartesianCase() {
    // The pose of the Cartesian-motion tests (gripper pointing down, as in Figure 21), elbow up.
    start = translation(0.5, 0.2, 0.3) * xRotation(std::numbers::pi);
    JointVector near(6);
    near << 0.3, 0.5, -2.5, 0, -0.6, 0;
    if (model.inverseKinematicsClosest(start, near, qStart) != IkStatus::Solved) throw std::runtime_error("IK");
    goal = translation(-0.1, -0.2, -0.2) * start * zRotation(0.4);
  }
  internal::SegmentPlan plan() const {
    return internal::planCartesianLine(model, qStart, goal, limits, model.getVelocityLimit(),
                                       model.getAccelerationLimit(), model.getJerkLimit(), "bench");
  }
};

KDL::Frame toKdl(const Transform& T) {
  return KDL::Frame(KDL::Rotation(T(0, 0), T(0, 1), T(0, 2), T(1, 0), T(1, 1), T(1, 2), T(2, 0), T(2, 1), T(2, 2)),
                    KDL::Vector(T(0, 3), T(1, 3), T(2, 3)));
}

std::unique_ptr<KDL::Trajectory_Segment> kdlLine(const CartesianCase& c) {
  auto* path = new KDL::Path_RoundedComposite(0.02, 0.1, new KDL::RotationalInterpolation_SingleAxis());
  path->Add(toKdl(c.start));
  path->Add(toKdl(c.goal));
  path->Finish();
  auto* profile = new KDL::VelocityProfile_Trap(c.limits.linearVelocity, c.limits.linearAcceleration);
  profile->SetProfile(0, path->PathLength());
  return std::make_unique<KDL::Trajectory_Segment>(path, profile);  // owns both
}

void BM_CartesianPlan_Ours(benchmark::State& state) {
  const CartesianCase c;
  for (auto _ : state) {
    internal::SegmentPlan plan = c.plan();
    benchmark::DoNotOptimize(plan.duration);
  }
  state.counters["nodes"] = c.plan().path.intervals + 1;
}

void BM_CartesianPlan_Kdl(benchmark::State& state) {
  const CartesianCase c;
  for (auto _ : state) {
    auto segment = kdlLine(c);
    benchmark::DoNotOptimize(segment->Duration());
  }
}

void BM_CartesianEval_Ours(benchmark::State& state) {
  const CartesianCase c;
  const internal::SegmentPlan plan = c.plan();
  Setpoint sp;
  sp.position = sp.velocity = sp.acceleration = JointVector(6);
  double fraction = 0;
  for (auto _ : state) {
    plan.evaluate(fraction * plan.duration, sp);
    benchmark::DoNotOptimize(sp.acceleration.data());
    fraction += 0.0137;
    if (fraction > 1) fraction -= 1;
  }
}

void BM_CartesianEval_Kdl(benchmark::State& state) {
  const CartesianCase c;
  auto segment = kdlLine(c);
  double fraction = 0;
  for (auto _ : state) {
    const double t = fraction * segment->Duration();
    KDL::Frame f = segment->Pos(t);
    KDL::Twist v = segment->Vel(t), a = segment->Acc(t);
    benchmark::DoNotOptimize(f);
    benchmark::DoNotOptimize(v);
    benchmark::DoNotOptimize(a);
    fraction += 0.0137;
    if (fraction > 1) fraction -= 1;
  }
}

BENCHMARK(BM_JointPlan_Ours)->Arg(6)->Arg(7);
BENCHMARK(BM_JointPlan_KdlTrap)->Arg(6)->Arg(7);
BENCHMARK(BM_JointEval_Ours)->Arg(6)->Arg(7);
BENCHMARK(BM_JointEval_KdlTrap)->Arg(6)->Arg(7);
BENCHMARK(BM_QueueSetpoint_Ours)->Arg(6)->Arg(7)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CartesianPlan_Ours)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CartesianPlan_Kdl)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CartesianEval_Ours);
BENCHMARK(BM_CartesianEval_Kdl);

}  // namespace

BENCHMARK_MAIN();
