// Time synchronisation of joint moves (issue 17): durations and planning time of 10,000 seeded
// random 7-joint rest-to-rest problems with per-joint limits, for each Synchronization mode.
//
// Problems: start and target uniform in the middle 90 % of the WAM 7's joint ranges; per joint a
// velocity limit uniform in [0.5, 3] rad/s, an acceleration limit in [2, 20] rad/s^2 and a jerk
// limit in [20, 400] rad/s^3, drawn independently (so the joints' limits differ).
// - BM_SyncPlan/{0,1,2} (Time, Phase, None): SynchronizedJointMotion's constructor, one problem
//   per iteration, cycling through the 10,000. Counters: the mean duration over all problems
//   [s], and for Time the share of problems where Phase is more than 1 % longer ("phase_longer")
//   and Phase's mean and largest excess over Time ("phase_excess_mean", "phase_excess_max").
// - BM_SyncEval/{0,1,2}: one setpoint of all 7 joints (what a servo cycle reads).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>
#include <vector>

#include "rp/RoboticPlatform.hpp"

namespace {

using namespace rp;

constexpr int kProblems = 10000;

struct Problem {
  JointVector start, target, v, a, j;
};

const std::vector<Problem>& problems() {
  static const std::vector<Problem> all = [] {
    const WAM7Model wam;
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> unit(0, 1);
    std::vector<Problem> p(kProblems);
    for (Problem& q : p) {
      q.start = q.target = q.v = q.a = q.j = JointVector(7);
      for (int i = 0; i < 7; ++i) {
        const double lo = wam.getPositionMin()(i), range = wam.getPositionMax()(i) - lo;
        q.start(i) = lo + (0.05 + 0.9 * unit(rng)) * range;
        q.target(i) = lo + (0.05 + 0.9 * unit(rng)) * range;
        q.v(i) = 0.5 + 2.5 * unit(rng);
        q.a(i) = 2 + 18 * unit(rng);
        q.j(i) = 20 + 380 * unit(rng);
      }
    }
    return p;
  }();
  return all;
}

Synchronization modeOf(const benchmark::State& state) { return static_cast<Synchronization>(state.range(0)); }

void BM_SyncPlan(benchmark::State& state) {
  const std::vector<Problem>& p = problems();
  const Synchronization mode = modeOf(state);
  std::size_t k = 0;
  for (auto _ : state) {
    const Problem& q = p[k];
    SynchronizedJointMotion m(q.start, q.target, q.v, q.a, q.j, mode);
    benchmark::DoNotOptimize(m);
    k = (k + 1) % p.size();
  }
  state.SetLabel(toString(mode));
  double sum = 0, excessSum = 0, excessMax = 0;
  int longer = 0;
  for (const Problem& q : p) {
    const double T = SynchronizedJointMotion(q.start, q.target, q.v, q.a, q.j, mode).getDuration();
    sum += T;
    if (mode == Synchronization::Time) {
      const double line = SynchronizedJointMotion(q.start, q.target, q.v, q.a, q.j, Synchronization::Phase).getDuration();
      const double excess = line / T - 1;
      excessSum += excess;
      excessMax = std::max(excessMax, excess);
      if (excess > 0.01) ++longer;
    }
  }
  state.counters["mean_duration_s"] = sum / kProblems;
  if (mode == Synchronization::Time) {
    state.counters["phase_longer"] = static_cast<double>(longer) / kProblems;
    state.counters["phase_excess_mean"] = excessSum / kProblems;
    state.counters["phase_excess_max"] = excessMax;
  }
}

void BM_SyncEval(benchmark::State& state) {
  const std::vector<Problem>& p = problems();
  const Synchronization mode = modeOf(state);
  std::vector<SynchronizedJointMotion> motions;
  motions.reserve(256);
  for (int k = 0; k < 256; ++k) {
    const Problem& q = p[static_cast<std::size_t>(k)];
    motions.emplace_back(q.start, q.target, q.v, q.a, q.j, mode);
  }
  Setpoint s;
  s.position = s.velocity = s.acceleration = JointVector(7);
  std::size_t k = 0;
  double t = 0;
  for (auto _ : state) {
    const SynchronizedJointMotion& m = motions[k];
    m.evaluate(t * m.getDuration(), s);
    benchmark::DoNotOptimize(s);
    k = (k + 1) % motions.size();
    t += 0.618034;
    if (t > 1) t -= 1;
  }
  state.SetLabel(toString(mode));
}

}  // namespace

BENCHMARK(BM_SyncPlan)->Arg(0)->Arg(1)->Arg(2);
BENCHMARK(BM_SyncEval)->Arg(0)->Arg(1)->Arg(2);

BENCHMARK_MAIN();
