// Fixed-size math never touches the heap: products, inverses, transforms, filters.
#include <gtest/gtest.h>

#include "AllocationCounter.hpp"
#include "rp/math/Math.hpp"

namespace rp {
namespace {

TEST(MathRealtime, CounterSeesAllocations) {
  test::AllocationGuard guard;
  VectorX<> heap(100);  // a dynamic vector must be counted, or the other tests prove nothing
  EXPECT_GE(guard.count(), 1u);
  EXPECT_EQ(heap.size(), 100);
}

TEST(MathRealtime, FixedSizeOperationsDoNotAllocate) {
  Transform a = rpyToTransform(0.1, 0.2, 0.3) * translation(1, 2, 3);
  Matrix<6, 6> m = Matrix<6, 6>::unit() * 3.0;
  Vector<6> v;
  v = 1, 2, 3, 4, 5, 6;
  LowpassFilter<Vector<6>> lp(10, 0.001, 2);
  HighpassFilter<Vector<6>> hp(10, 0.001, 1);
  Differentiator<Vector<6>> d(0.001, 50);
  Integrator<Vector<6>> in(0.001);
  BoundedVector<16> q(6);
  double sink = 0;
  test::AllocationGuard guard;
  for (int i = 0; i < 1000; ++i) {
    Transform b = a * a;
    Transform c = rigidInverse(b) * b.inverse();
    Vector<6> w = m * v + m.inverse() * v;
    Vector<3> e = transformToEuler(c) + transformToRPY(b) + crossProduct(getPosition(b), getPosition(c));
    Vector<6> f = lp.filter(w) + hp.filter(w) + d.differentiate(w) + in.integrate(w);
    q = w;
    sink += e(0) + f(1) + dotProduct(w, v) + q(5) + b.getColumn(4)(0) + length(e);
  }
  EXPECT_EQ(guard.count(), 0u);
  EXPECT_TRUE(std::isfinite(sink));
}

}  // namespace
}  // namespace rp
