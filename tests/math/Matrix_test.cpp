// Tests of rp::Matrix and the Table 2 matrix/vector functions against independent references:
// products and inverses checked element by element with scalar loops, stream round trips checked
// bit for bit, cross products against their defining formula.
#include "rp/math/Matrix.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>

namespace rp {
namespace {

template <typename M>
void fillRandom(M& m, std::mt19937_64& rng, double lo = -1.0, double hi = 1.0) {
  std::uniform_real_distribution<double> d(lo, hi);
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) m(i, j) = d(rng);
}

TEST(Matrix, DefaultConstructedFixedSizeIsZero) {
  Matrix<3, 4> m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_EQ(m(i, j), 0.0);
  Vector<6> v;
  EXPECT_EQ(v.squaredNorm(), 0.0);
}

TEST(Matrix, CommaAssignmentFillsRowByRowAsInFigure23) {
  Vector<6> target;
  target = 0, 45, -90, 0, 0, 0;
  EXPECT_EQ(target(1), 45.0);
  EXPECT_EQ(target(2), -90.0);
  Matrix<2, 3> m;
  m = 1, 2, 3, 4, 5, 6;
  EXPECT_EQ(m(0, 2), 3.0);
  EXPECT_EQ(m(1, 0), 4.0);
  Vector<4> wall;
  wall = 0, 0, -1, 3;  // Figure 22
  EXPECT_EQ(wall(3), 3.0);
}

TEST(Matrix, CommaAssignmentWithWrongCountThrows) {
  Vector<3> v;
  EXPECT_THROW((v = 1, 2), MathException);
  EXPECT_THROW((v = 1, 2, 3, 4), MathException);
  try {
    v = 1, 2;
    FAIL() << "no exception";
  } catch (const MathException& e) {
    EXPECT_NE(std::string(e.what()).find("2 value(s) given for a 3x1 matrix"), std::string::npos) << e.what();
  }
}

TEST(Matrix, ProductMatchesScalarLoops) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 100; ++trial) {
    Matrix<3, 5> a;
    Matrix<5, 2> b;
    fillRandom(a, rng);
    fillRandom(b, rng);
    Matrix<3, 2> c = a * b;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 2; ++j) {
        double s = 0;
        for (int k = 0; k < 5; ++k) s += a(i, k) * b(k, j);
        EXPECT_NEAR(c(i, j), s, 1e-15);
      }
  }
}

TEST(Matrix, ProductAssignedToOneOfItsFactorsIsStillCorrect) {
  // Assignment writes products straight into the target unless the target is a factor.
  std::mt19937_64 rng(8);
  Matrix<4, 4> a, b;
  fillRandom(a, rng);
  fillRandom(b, rng);
  const Eigen::Matrix4d ea = a, eb = b;
  Matrix<4, 4> c;
  c = a * b;
  EXPECT_TRUE(c.isApprox(ea * eb, 1e-15));
  a = a * b;
  EXPECT_TRUE(a.isApprox(ea * eb, 1e-15));
  b = a * b;
  EXPECT_TRUE(b.isApprox(ea * eb * eb, 1e-15));
  Matrix<4, 4> d = b;
  d = d.transpose() * d;  // a factor that is an expression of the target
  EXPECT_TRUE(d.isApprox(Eigen::Matrix4d(b.transpose()) * Eigen::Matrix4d(b), 1e-15));
  MatrixX<> x(9, 9), y(9, 9);
  fillRandom(x, rng);
  fillRandom(y, rng);
  const Eigen::MatrixXd ex = x, ey = y;
  x = x * y;  // dynamic sizes take Eigen's general product
  EXPECT_TRUE(x.isApprox(ex * ey, 1e-14));
}

TEST(Matrix, SumDifferenceScalarMultiplicationAndDivision) {
  Matrix<2, 2> a{{1, 2}, {3, 4}};
  Matrix<2, 2> b{{5, 6}, {7, 8}};
  Matrix<2, 2> sum = a + b, diff = b - a, scaled = 2.0 * a, divided = b / 2.0;
  EXPECT_EQ(sum, (Matrix<2, 2>{{6, 8}, {10, 12}}));
  EXPECT_EQ(diff, (Matrix<2, 2>{{4, 4}, {4, 4}}));
  EXPECT_EQ(scaled, (Matrix<2, 2>{{2, 4}, {6, 8}}));
  EXPECT_EQ(divided, (Matrix<2, 2>{{2.5, 3}, {3.5, 4}}));
}

TEST(Matrix, Transpose) {
  Matrix<2, 3> a{{1, 2, 3}, {4, 5, 6}};
  Matrix<3, 2> t = transpose(a);
  Matrix<3, 2> t2 = a.transpose();
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 3; ++j) {
      EXPECT_EQ(t(j, i), a(i, j));
      EXPECT_EQ(t2(j, i), a(i, j));
    }
}

TEST(Matrix, OneBasedAccessorsAsInThePaper) {
  Matrix<3, 4> m;
  m = 1, 2, 3, 4,  //
      5, 6, 7, 8,  //
      9, 10, 11, 12;
  EXPECT_EQ(m.getElement(1, 1), 1.0);
  EXPECT_EQ(m.getElement(3, 4), 12.0);
  m.setElement(2, 3, -7);
  EXPECT_EQ(m(1, 2), -7.0);
  Vector<3> c4 = m.getColumn(4);
  EXPECT_EQ(c4, (Vector<3>{{4}, {8}, {12}}));
  RowVector<4> r2 = m.getRow(2);
  EXPECT_EQ(r2, (RowVector<4>{{5, 6, -7, 8}}));
  Matrix<2, 2> s = m.getSubMatrix<2, 2>(2, 3);
  EXPECT_EQ(s, (Matrix<2, 2>{{-7, 8}, {11, 12}}));
  m.setSubMatrix(1, 1, Matrix<2, 2>{{0, 0}, {0, 0}});
  EXPECT_EQ(m(1, 1), 0.0);
  EXPECT_EQ(m(2, 2), 11.0);
  m.setColumn(1, Vector<3>{{-1}, {-2}, {-3}});
  EXPECT_EQ(m(2, 0), -3.0);
  m.setRow(3, RowVector<4>{{1, 1, 1, 1}});
  EXPECT_EQ(m(2, 3), 1.0);
  Vector<3> v;
  v = 7, 8, 9;
  EXPECT_EQ(v.getElement(3), 9.0);
  v.setElement(1, 0.5);
  EXPECT_EQ(v(0), 0.5);
  EXPECT_EQ(m.getNumberOfRows(), 3);
  EXPECT_EQ(m.getNumberOfColumns(), 4);
}

TEST(Matrix, OneBasedAccessorsRejectOutOfRangeIndices) {
  Matrix<3, 4> m;
  EXPECT_THROW(m.getElement(0, 1), MathException);
  EXPECT_THROW(m.getElement(4, 1), MathException);
  EXPECT_THROW(m.getColumn(5), MathException);
  EXPECT_THROW(m.getRow(0), MathException);
  EXPECT_THROW((m.getSubMatrix<2, 2>(3, 1)), MathException);
  EXPECT_THROW(m.setSubMatrix(3, 4, Matrix<1, 2>()), MathException);
  Vector<3> v;
  EXPECT_THROW(v.getElement(4), MathException);
}

template <int n>
void checkInverse(std::mt19937_64& rng) {
  for (int trial = 0; trial < 50; ++trial) {
    Matrix<n, n> a;
    fillRandom(a, rng);
    a += 2.0 * n * Matrix<n, n>::unit();  // diagonally dominant: well conditioned
    Matrix<n, n> inv = a.inverse();
    Matrix<n, n> i1 = a * inv, i2 = inv * a;
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) {
        EXPECT_NEAR(i1(r, c), r == c ? 1.0 : 0.0, 1e-13);
        EXPECT_NEAR(i2(r, c), r == c ? 1.0 : 0.0, 1e-13);
      }
  }
}

TEST(Matrix, InverseTimesMatrixIsUnit) {
  std::mt19937_64 rng(7);
  checkInverse<2>(rng);
  checkInverse<3>(rng);
  checkInverse<4>(rng);
  checkInverse<6>(rng);
  checkInverse<7>(rng);
  MatrixX<> d(5, 5);
  fillRandom(d, rng);
  d += 10.0 * MatrixX<>(Eigen::MatrixXd::Identity(5, 5));
  MatrixX<> prod = d * inverse(d);
  EXPECT_TRUE(prod.isIdentity(1e-13));
}

TEST(Matrix, InverseOfSingularMatrixThrows) {
  Matrix<3, 3> s{{1, 2, 3}, {2, 4, 6}, {0, 1, 1}};
  try {
    (void)s.inverse();
    FAIL() << "no exception";
  } catch (const MathException& e) {
    EXPECT_NE(std::string(e.what()).find("singular (rank 2)"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)(Matrix<4, 4>().inverse()), MathException);
  MatrixX<> nonSquare(2, 3);
  EXPECT_THROW((void)nonSquare.inverse(), MathException);
}

TEST(Matrix, UnitAndZero) {
  const auto u = Matrix<4, 4>::unit();
  const auto z = Matrix<4, 4>::zero();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      EXPECT_EQ(u(i, j), i == j ? 1.0 : 0.0);
      EXPECT_EQ(z(i, j), 0.0);
    }
  Matrix<3, 3> m{{1, 2, 3}, {4, 5, 6}, {7, 8, 9}};
  m.setUnit();
  EXPECT_TRUE(m.isIdentity(0.0));
}

TEST(Matrix, StreamRoundTripIsBitExact) {
  std::mt19937_64 rng(3);
  Matrix<3, 4> m;
  fillRandom(m, rng, -1e6, 1e6);
  m(0, 0) = 1.0 / 3.0;
  m(0, 1) = std::numeric_limits<double>::denorm_min();
  m(0, 2) = -0.0;
  m(0, 3) = std::numeric_limits<double>::max();
  m(1, 0) = std::numeric_limits<double>::infinity();
  m(1, 1) = -std::numeric_limits<double>::infinity();
  m(1, 2) = 0.1;
  std::stringstream ss;
  ss << m;
  Matrix<3, 4> back;
  ss >> back;
  ASSERT_FALSE(ss.fail()) << ss.str();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j)
      EXPECT_EQ(std::bit_cast<std::uint64_t>(back(i, j)), std::bit_cast<std::uint64_t>(m(i, j)))
          << "element " << i << "," << j << " written as " << ss.str();
  // The text is readable: rows on lines, numbers in their shortest form.
  std::stringstream s2;
  s2 << Matrix<2, 2>{{1, 0.5}, {-2, 0.1}};
  EXPECT_EQ(s2.str(), "1 0.5\n-2 0.1");
}

TEST(Matrix, StreamInputRejectsMalformedText) {
  Vector<3> v;
  v = 1, 2, 3;
  std::istringstream bad("4 five 6");
  bad >> v;
  EXPECT_TRUE(bad.fail());
  EXPECT_EQ(v(1), 2.0) << "a failed read leaves the matrix unchanged";
  std::istringstream shortInput("4 5");
  shortInput >> v;
  EXPECT_TRUE(shortInput.fail());
  EXPECT_EQ(v(0), 1.0);
}

TEST(Matrix, LengthDotCrossAndElementProduct) {
  Vector<3> a, b;
  a = 1, 2, 2;
  b = -3, 0.5, 4;
  EXPECT_DOUBLE_EQ(a.length(), 3.0);
  EXPECT_DOUBLE_EQ(length(a), 3.0);
  EXPECT_DOUBLE_EQ(dotProduct(a, b), -3 + 1 + 8);
  Vector<3> c = crossProduct(a, b);
  // Defining formula of the cross product.
  EXPECT_DOUBLE_EQ(c(0), a(1) * b(2) - a(2) * b(1));
  EXPECT_DOUBLE_EQ(c(1), a(2) * b(0) - a(0) * b(2));
  EXPECT_DOUBLE_EQ(c(2), a(0) * b(1) - a(1) * b(0));
  EXPECT_NEAR(dotProduct(c, a), 0.0, 1e-14);
  Vector<3> e = elementMultiply(a, b);
  EXPECT_EQ(e, (Vector<3>{{-3}, {1}, {8}}));
  RowVector<3> r{{1, 1, 1}};
  EXPECT_DOUBLE_EQ(dotProduct(r, a), 5.0);
}

TEST(Matrix, RunTimeSizesAreChecked) {
  VectorX<> five(5);
  EXPECT_THROW((Vector<6>(five)), MathException);
  Vector<5> ok = five;
  EXPECT_EQ(ok.size(), 5);
  EXPECT_THROW(BoundedVector<6>(7), MathException);
  BoundedVector<6> q(6);
  EXPECT_EQ(q.size(), 6);
  VectorX<> seven(7);
  EXPECT_THROW(q = seven, MathException);
  Vector<3> x, y;
  EXPECT_THROW((dotProduct(VectorX<>(2), VectorX<>(3))), MathException);
  (void)x;
  (void)y;
}

TEST(Matrix, BoundedVectorsLiveInsideTheObject) {
  static_assert(sizeof(BoundedVector<16>) >= 16 * sizeof(double));
  BoundedVector<16> q(7);
  q.setConstant(2.0);
  EXPECT_DOUBLE_EQ(q.sum(), 14.0);
}

}  // namespace
}  // namespace rp
