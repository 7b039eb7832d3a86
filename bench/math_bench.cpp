// The paper claims its matrix templates are "as fast as direct programming" (section 3.9). Each
// computation here is measured twice in the same binary: through the math library, and written
// out by hand in scalar code on plain arrays of the same layout (column-major, as the library
// stores matrices). Inputs come from memory and results go back to memory in both versions.
//
// Report: library time / hand-written time for each pair (goal: at most 1.05).
#include <benchmark/benchmark.h>

#include <array>
#include <random>

#include "rp/math/Math.hpp"

namespace {

using rp::Matrix;
using rp::Transform;
using rp::Vector;

constexpr int kBatch = 64;  // independent problems per iteration, so the loop is throughput-bound

template <typename T>
std::array<T, kBatch> randomBatch(unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> d(-1, 1);
  std::array<T, kBatch> a;
  for (auto& m : a)
    for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = d(rng);
  return a;
}

// The same values as plain arrays in the library's storage order.
template <typename M>
auto asArrays(const std::array<M, kBatch>& in) {
  constexpr int n = M::SizeAtCompileTime;
  std::array<std::array<double, n>, kBatch> out;
  for (int k = 0; k < kBatch; ++k)
    for (int i = 0; i < n; ++i) out[k][i] = in[k].data()[i];
  return out;
}

// ---- Transform * Transform ------------------------------------------------------------------

void TransformProduct_Library(benchmark::State& state) {
  auto a = randomBatch<Transform>(1), b = randomBatch<Transform>(2);
  std::array<Transform, kBatch> c;
  for (auto _ : state) {
    for (int k = 0; k < kBatch; ++k) c[k] = a[k] * b[k];
    benchmark::DoNotOptimize(c.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}

void TransformProduct_Hand(benchmark::State& state) {
  auto a = asArrays(randomBatch<Transform>(1)), b = asArrays(randomBatch<Transform>(2));
  std::array<std::array<double, 16>, kBatch> c;
  for (auto _ : state) {
    for (int k = 0; k < kBatch; ++k) {
      const double* A = a[k].data();
      const double* B = b[k].data();
      double* C = c[k].data();
      // Column-major: element (i, j) at [i + 4 j].
      for (int j = 0; j < 4; ++j) {
        const double b0 = B[0 + 4 * j], b1 = B[1 + 4 * j], b2 = B[2 + 4 * j], b3 = B[3 + 4 * j];
        C[0 + 4 * j] = A[0] * b0 + A[4] * b1 + A[8] * b2 + A[12] * b3;
        C[1 + 4 * j] = A[1] * b0 + A[5] * b1 + A[9] * b2 + A[13] * b3;
        C[2 + 4 * j] = A[2] * b0 + A[6] * b1 + A[10] * b2 + A[14] * b3;
        C[3 + 4 * j] = A[3] * b0 + A[7] * b1 + A[11] * b2 + A[15] * b3;
      }
    }
    benchmark::DoNotOptimize(c.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}

// ---- Transform * point (homogeneous 4-vector) -------------------------------------------------

void TransformPoint_Library(benchmark::State& state) {
  auto t = randomBatch<Transform>(3);
  auto p = randomBatch<Vector<4>>(4);
  std::array<Vector<4>, kBatch> q;
  for (auto _ : state) {
    for (int k = 0; k < kBatch; ++k) q[k] = t[k] * p[k];
    benchmark::DoNotOptimize(q.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}

void TransformPoint_Hand(benchmark::State& state) {
  auto t = asArrays(randomBatch<Transform>(3));
  auto p = asArrays(randomBatch<Vector<4>>(4));
  std::array<std::array<double, 4>, kBatch> q;
  for (auto _ : state) {
    for (int k = 0; k < kBatch; ++k) {
      const double* T = t[k].data();
      const double* P = p[k].data();
      double* Q = q[k].data();
      Q[0] = T[0] * P[0] + T[4] * P[1] + T[8] * P[2] + T[12] * P[3];
      Q[1] = T[1] * P[0] + T[5] * P[1] + T[9] * P[2] + T[13] * P[3];
      Q[2] = T[2] * P[0] + T[6] * P[1] + T[10] * P[2] + T[14] * P[3];
      Q[3] = T[3] * P[0] + T[7] * P[1] + T[11] * P[2] + T[15] * P[3];
    }
    benchmark::DoNotOptimize(q.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}

// ---- Transform applied to a 3-D point (rotation and translation) ------------------------------

void TransformPoint3_Library(benchmark::State& state) {
  auto t = randomBatch<Transform>(5);
  auto p = randomBatch<Vector<3>>(6);
  std::array<Vector<3>, kBatch> q;
  for (auto _ : state) {
    for (int k = 0; k < kBatch; ++k) q[k] = rp::transformPoint(t[k], p[k]);
    benchmark::DoNotOptimize(q.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}

void TransformPoint3_Hand(benchmark::State& state) {
  auto t = asArrays(randomBatch<Transform>(5));
  auto p = asArrays(randomBatch<Vector<3>>(6));
  std::array<std::array<double, 3>, kBatch> q;
  for (auto _ : state) {
    for (int k = 0; k < kBatch; ++k) {
      const double* T = t[k].data();
      const double* P = p[k].data();
      double* Q = q[k].data();
      Q[0] = T[0] * P[0] + T[4] * P[1] + T[8] * P[2] + T[12];
      Q[1] = T[1] * P[0] + T[5] * P[1] + T[9] * P[2] + T[13];
      Q[2] = T[2] * P[0] + T[6] * P[1] + T[10] * P[2] + T[14];
    }
    benchmark::DoNotOptimize(q.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}

// ---- 6x6 matrix * 6-vector ----------------------------------------------------------------------

void Matrix6Vector6_Library(benchmark::State& state) {
  auto m = randomBatch<Matrix<6, 6>>(7);
  auto v = randomBatch<Vector<6>>(8);
  std::array<Vector<6>, kBatch> r;
  for (auto _ : state) {
    for (int k = 0; k < kBatch; ++k) r[k] = m[k] * v[k];
    benchmark::DoNotOptimize(r.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}

void Matrix6Vector6_Hand(benchmark::State& state) {
  auto m = asArrays(randomBatch<Matrix<6, 6>>(7));
  auto v = asArrays(randomBatch<Vector<6>>(8));
  std::array<std::array<double, 6>, kBatch> r;
  for (auto _ : state) {
    for (int k = 0; k < kBatch; ++k) {
      const double* M = m[k].data();
      const double* V = v[k].data();
      double* R = r[k].data();
      for (int i = 0; i < 6; ++i) {
        R[i] = M[i] * V[0] + M[i + 6] * V[1] + M[i + 12] * V[2] + M[i + 18] * V[3] + M[i + 24] * V[4] +
               M[i + 30] * V[5];
      }
    }
    benchmark::DoNotOptimize(r.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}

BENCHMARK(TransformProduct_Library);
BENCHMARK(TransformProduct_Hand);
BENCHMARK(TransformPoint_Library);
BENCHMARK(TransformPoint_Hand);
BENCHMARK(TransformPoint3_Library);
BENCHMARK(TransformPoint3_Hand);
BENCHMARK(Matrix6Vector6_Library);
BENCHMARK(Matrix6Vector6_Hand);

}  // namespace

BENCHMARK_MAIN();
