#pragma once
/// @file
/// The matrix and vector classes of the math library (paper section 3.9, Figure 14, Table 2),
/// with Eigen 3.4 as the engine.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include <charconv>
#include <cmath>
#include <exception>
#include <istream>
#include <ostream>
#include <string>
#include <type_traits>

#include "rp/math/MathException.hpp"

namespace rp {

/// Marks a number of rows or columns that is known only at run time (Eigen's `Eigen::Dynamic`).
inline constexpr int Dynamic = Eigen::Dynamic;

template <int Rows, int Cols, typename T, int MaxRows, int MaxCols>
class Matrix;

namespace internal {

// Eigen's storage option for a Rows x Cols matrix: row vectors must be row-major.
constexpr int storageOptions(int rows, int cols) {
  return Eigen::AutoAlign |
         ((rows == 1 && cols != 1) ? Eigen::RowMajor : Eigen::ColMajor);
}

// Out-of-line throwers for the paper's 1-based accessors (src/math/MatrixErrors.cpp).
[[noreturn]] void throwIndexError(const char* where, Eigen::Index row, Eigen::Index col, Eigen::Index rows,
                                  Eigen::Index cols);
[[noreturn]] void throwVectorIndexError(const char* where, Eigen::Index i, Eigen::Index size);
[[noreturn]] void throwBlockError(const char* where, Eigen::Index row, Eigen::Index col, Eigen::Index r,
                                  Eigen::Index c, Eigen::Index rows, Eigen::Index cols);
[[noreturn]] void throwSizeError(const char* where, Eigen::Index rows, Eigen::Index cols, int fixedRows,
                                 int fixedCols, Eigen::Index maxRows, Eigen::Index maxCols);

// Throws unless a run-time size fits a compile-time size.
inline void checkSize(const char* where, Eigen::Index rows, Eigen::Index cols, int fixedRows, int fixedCols,
                      Eigen::Index maxRows, Eigen::Index maxCols) {
  const bool rowsOk = fixedRows == Dynamic ? (maxRows == Dynamic || rows <= maxRows) : rows == fixedRows;
  const bool colsOk = fixedCols == Dynamic ? (maxCols == Dynamic || cols <= maxCols) : cols == fixedCols;
  if (!rowsOk || !colsOk) [[unlikely]] {
    throwSizeError(where, rows, cols, fixedRows, fixedCols, maxRows, maxCols);
  }
}

// Helper returned by `matrix = a` so that `matrix = a, b, c, ...;` fills the matrix row by row,
// as the paper's programs write it (Figures 22 and 23).
template <typename M>
class CommaAssigner {
 public:
  using Scalar = typename M::Scalar;
  CommaAssigner(M& m, const Scalar& first) : m_(m), exceptions_(std::uncaught_exceptions()) { push(first); }
  CommaAssigner(const CommaAssigner&) = delete;
  CommaAssigner& operator=(const CommaAssigner&) = delete;
  CommaAssigner& operator,(const Scalar& value) {
    push(value);
    return *this;
  }
  // Too few values is reported when the statement ends; never while another exception unwinds.
  ~CommaAssigner() noexcept(false) {
    if (count_ != m_.size() && std::uncaught_exceptions() == exceptions_) {
      throw MathException("comma assignment: " + std::to_string(count_) + " value(s) given for a " +
                          std::to_string(m_.rows()) + "x" + std::to_string(m_.cols()) +
                          " matrix; give all " + std::to_string(m_.size()) +
                          " (use setZero() or Matrix::zero() to clear it)");
    }
  }

 private:
  void push(const Scalar& value) {
    if (count_ >= m_.size()) {
      throw MathException("comma assignment: more than " + std::to_string(m_.size()) + " values for a " +
                          std::to_string(m_.rows()) + "x" + std::to_string(m_.cols()) + " matrix");
    }
    m_(count_ / m_.cols(), count_ % m_.cols()) = value;
    ++count_;
  }
  M& m_;
  Eigen::Index count_ = 0;
  int exceptions_;
};

}  // namespace internal

/// A matrix of `Rows` x `Cols` elements of type `T` (the paper's `Matrix`), built on `Eigen::Matrix`.
///
/// Sizes known at compile time are checked at compile time: multiplying a 3x3 matrix by a
/// 4-vector, adding a 3-vector to a 4-vector or assigning a 4x4 matrix to a 3x3 one does not
/// compile. Fixed-size matrices never allocate memory. `Rows` or `Cols` may be `rp::Dynamic` for
/// code that is generic over sizes (the role of the paper's `MatrixBase` and `VectorBase`);
/// `MaxRows`/`MaxCols` then give an optional upper bound that keeps the storage inside the object
/// (no heap), as `BoundedVector` does for joint vectors.
///
/// Every Eigen operation works on it (`*`, `+`, `-`, `transpose()`, `norm()`, blocks, ...), and
/// Eigen's accessors count from 0: `m(0, 0)` is the top-left element. The paper's accessors
/// (`getElement`, `getColumn`, ...) count rows and columns **from 1**, as the paper does:
/// `t.getColumn(4)` is the translation column of a `Transform`.
///
/// A default-constructed fixed-size matrix is zero. `m = a, b, c, ...;` assigns all elements row
/// by row; giving fewer or more values than the matrix has throws `MathException`.
template <int Rows, int Cols, typename T = double, int MaxRows = Rows, int MaxCols = Cols>
class Matrix : public Eigen::Matrix<T, Rows, Cols, internal::storageOptions(Rows, Cols), MaxRows, MaxCols> {
 public:
  /// The Eigen matrix type this class extends.
  using Base = Eigen::Matrix<T, Rows, Cols, internal::storageOptions(Rows, Cols), MaxRows, MaxCols>;
  /// The element type.
  using Scalar = T;
  /// True when the size is fixed at compile time.
  static constexpr bool kFixedSize = Rows != Dynamic && Cols != Dynamic;
  /// True for a row or column vector.
  static constexpr bool kIsVector = Rows == 1 || Cols == 1;

  /// A fixed-size matrix full of zeros, or an empty dynamic-size matrix.
  /// Real-time safe: yes.
  Matrix() : Base() {
    if constexpr (kFixedSize) Base::setZero();
  }

  /// A dynamic-size vector of `size` zeros.
  /// @param[in] size  number of elements
  /// @throws MathException if the size exceeds `MaxRows`/`MaxCols`.
  /// Real-time safe: only with a bounded size (no heap).
  explicit Matrix(Eigen::Index size)
    requires(kIsVector && !kFixedSize)
  {
    if constexpr (Rows == 1) internal::checkSize("Matrix(size)", 1, size, Rows, Cols, MaxRows, MaxCols);
    else internal::checkSize("Matrix(size)", size, 1, Rows, Cols, MaxRows, MaxCols);
    Base::setZero(size);
  }

  /// A dynamic-size matrix of `rows` x `cols` zeros.
  /// @throws MathException if the size does not fit the compile-time or maximum size.
  /// Real-time safe: only with a bounded size (no heap).
  Matrix(Eigen::Index rows, Eigen::Index cols)
    requires(!kFixedSize && !kIsVector)
  {
    internal::checkSize("Matrix(rows, cols)", rows, cols, Rows, Cols, MaxRows, MaxCols);
    Base::setZero(rows, cols);
  }

  /// A matrix from nested lists of rows: `Matrix<2, 2> m{{1, 2}, {3, 4}};`.
  Matrix(const std::initializer_list<std::initializer_list<T>>& rows) : Base(rows) {}

  /// A matrix from any Eigen expression (a product, a sum, a block, ...).
  /// Sizes fixed on both sides are checked at compile time; others at run time.
  /// @throws MathException if a run-time size does not fit.
  template <typename Other>
  Matrix(const Eigen::EigenBase<Other>& other) : Base(checked(other)) {}  // NOLINT: implicit by design

  /// Copy construction. Real-time safe: yes for fixed and bounded sizes.
  Matrix(const Matrix&) = default;
  /// Move construction. Real-time safe: yes.
  Matrix(Matrix&&) noexcept = default;
  /// Copy assignment. Real-time safe: yes for fixed and bounded sizes.
  Matrix& operator=(const Matrix&) = default;
  /// Move assignment. Real-time safe: yes.
  Matrix& operator=(Matrix&&) noexcept = default;
  ~Matrix() = default;

  /// Assigns any Eigen expression; sizes are checked as for construction.
  template <typename Other>
  Matrix& operator=(const Eigen::DenseBase<Other>& other) {
    Base::operator=(checked(other));
    return *this;
  }

  /// Assigns a matrix product. When both factors are plain matrices other than this one, the
  /// product is written straight into this matrix; otherwise (`a = a * b`) through a temporary, as
  /// Eigen does by default. Real-time safe: yes for fixed and bounded sizes.
  template <typename Lhs, typename Rhs, int Option>
  Matrix& operator=(const Eigen::Product<Lhs, Rhs, Option>& product) {
    checked(product);
    if constexpr (isPlain<Lhs>() && isPlain<Rhs>()) {
      if (product.lhs().data() != Base::data() && product.rhs().data() != Base::data()) {
        if constexpr (isSmallFixed<Lhs>() && isSmallFixed<Rhs>()) {
          Base::noalias() = product.lhs().lazyProduct(product.rhs());  // coefficient-wise, unrolled
        } else {
          Base::noalias() = product;
        }
        return *this;
      }
    }
    Base::operator=(product);
    return *this;
  }

  /// Starts a comma assignment: `v = 0, 45, -90, 0, 0, 0;` sets all elements, row by row.
  /// @throws MathException when the statement gives fewer or more values than the matrix has.
  internal::CommaAssigner<Matrix> operator=(const T& first) { return internal::CommaAssigner<Matrix>(*this, first); }

  /// The unit (identity) matrix. Real-time safe: yes.
  static Matrix unit()
    requires kFixedSize
  {
    return Matrix(Base::Identity());
  }
  /// The zero matrix. Real-time safe: yes.
  static Matrix zero()
    requires kFixedSize
  {
    return Matrix();
  }
  /// Makes this a unit (identity) matrix, keeping its size. Real-time safe: yes.
  void setUnit() { Base::setIdentity(); }

  /// Number of rows. Real-time safe: yes.
  int getNumberOfRows() const { return static_cast<int>(Base::rows()); }
  /// Number of columns. Real-time safe: yes.
  int getNumberOfColumns() const { return static_cast<int>(Base::cols()); }

  /// Element at `row`, `col`, counted **from 1** as in the paper.
  /// @throws MathException if out of range. Real-time safe: yes (throws only on a programming error).
  T getElement(int row, int col) const {
    checkIndex("getElement", row, col);
    return (*this)(row - 1, col - 1);
  }
  /// Element `i` of a vector, counted **from 1**.
  T getElement(int i) const
    requires kIsVector
  {
    checkVectorIndex("getElement", i);
    return Base::coeff(i - 1);
  }
  /// Sets the element at `row`, `col`, counted **from 1**.
  void setElement(int row, int col, const T& value) {
    checkIndex("setElement", row, col);
    (*this)(row - 1, col - 1) = value;
  }
  /// Sets element `i` of a vector, counted **from 1**.
  void setElement(int i, const T& value)
    requires kIsVector
  {
    checkVectorIndex("setElement", i);
    Base::coeffRef(i - 1) = value;
  }

  /// Column `col` (counted **from 1**) as a column vector: `t.getColumn(4)` is a Transform's
  /// homogeneous position. Real-time safe: yes for fixed and bounded sizes.
  Matrix<Rows, 1, T, MaxRows, 1> getColumn(int col) const {
    checkIndex("getColumn", 1, col);
    return Matrix<Rows, 1, T, MaxRows, 1>(Base::col(col - 1));
  }
  /// Row `row` (counted **from 1**) as a row vector.
  Matrix<1, Cols, T, 1, MaxCols> getRow(int row) const {
    checkIndex("getRow", row, 1);
    return Matrix<1, Cols, T, 1, MaxCols>(Base::row(row - 1));
  }
  /// Sets column `col` (counted **from 1**).
  template <typename Other>
  void setColumn(int col, const Eigen::MatrixBase<Other>& v) {
    checkIndex("setColumn", 1, col);
    Base::col(col - 1) = v;
  }
  /// Sets row `row` (counted **from 1**).
  template <typename Other>
  void setRow(int row, const Eigen::MatrixBase<Other>& v) {
    checkIndex("setRow", row, 1);
    Base::row(row - 1) = v;
  }

  /// The `R` x `C` sub-matrix whose top-left element is at `row`, `col` (counted **from 1**).
  /// @throws MathException if it does not lie inside this matrix.
  template <int R, int C>
  Matrix<R, C, T> getSubMatrix(int row, int col) const {
    checkBlock("getSubMatrix", row, col, R, C);
    return Matrix<R, C, T>(Base::template block<R, C>(row - 1, col - 1));
  }
  /// Writes `m` into this matrix with its top-left element at `row`, `col` (counted **from 1**).
  /// @throws MathException if it does not fit.
  template <typename Other>
  void setSubMatrix(int row, int col, const Eigen::MatrixBase<Other>& m) {
    checkBlock("setSubMatrix", row, col, m.rows(), m.cols());
    Base::block(row - 1, col - 1, m.rows(), m.cols()) = m;
  }

  /// The inverse of a square matrix, computed by LU decomposition with full pivoting.
  /// @throws MathException if the matrix is singular (numerically: rank below its size).
  /// Real-time safe: yes for fixed sizes (no heap); throws on a singular matrix.
  Matrix inverse() const {
    static_assert(Rows == Cols, "rp::Matrix::inverse: the matrix must be square");
    if (Base::rows() != Base::cols()) {
      throw MathException("Matrix::inverse: a " + std::to_string(Base::rows()) + "x" +
                          std::to_string(Base::cols()) + " matrix is not square");
    }
    Eigen::FullPivLU<Base> lu(Base::rows(), Base::cols());
    // Eigen's default rank threshold, set explicitly (it also keeps GCC's maybe-uninitialized quiet).
    lu.setThreshold(Eigen::NumTraits<T>::epsilon() * T(Base::rows()));
    lu.compute(*this);
    if (!lu.isInvertible()) {
      throw MathException("Matrix::inverse: matrix (" + std::to_string(Base::rows()) + "x" +
                          std::to_string(Base::cols()) + ") is singular (rank " + std::to_string(lu.rank()) + ")");
    }
    return Matrix(lu.inverse());
  }

  /// The 2-norm of a vector (the paper's "length"). Real-time safe: yes.
  T length() const
    requires kIsVector
  {
    return Base::norm();
  }

 private:
  template <typename X>
  static constexpr bool isPlain() {
    using D = std::remove_cv_t<std::remove_reference_t<X>>;
    return std::is_base_of_v<Eigen::PlainObjectBase<D>, D>;
  }
  template <typename X>
  static constexpr bool isSmallFixed() {
    using D = std::remove_cv_t<std::remove_reference_t<X>>;
    return D::RowsAtCompileTime != Dynamic && D::ColsAtCompileTime != Dynamic && D::RowsAtCompileTime <= 8 &&
           D::ColsAtCompileTime <= 8;
  }
  template <typename Other>
  static const Other& checked(const Eigen::EigenBase<Other>& other) {
    static_assert(Rows == Dynamic || Other::RowsAtCompileTime == Dynamic || Rows == int(Other::RowsAtCompileTime),
                  "rp::Matrix: the number of rows does not match");
    static_assert(Cols == Dynamic || Other::ColsAtCompileTime == Dynamic || Cols == int(Other::ColsAtCompileTime),
                  "rp::Matrix: the number of columns does not match");
    if constexpr (Rows == Dynamic || Cols == Dynamic || Other::RowsAtCompileTime == Dynamic ||
                  Other::ColsAtCompileTime == Dynamic) {
      internal::checkSize("rp::Matrix", other.rows(), other.cols(), Rows, Cols, MaxRows, MaxCols);
    }
    return other.derived();
  }
  void checkIndex(const char* where, int row, int col) const {
    if (row < 1 || row > Base::rows() || col < 1 || col > Base::cols()) [[unlikely]] {
      internal::throwIndexError(where, row, col, Base::rows(), Base::cols());
    }
  }
  void checkVectorIndex(const char* where, int i) const {
    if (i < 1 || i > Base::size()) [[unlikely]] {
      internal::throwVectorIndexError(where, i, Base::size());
    }
  }
  void checkBlock(const char* where, int row, int col, Eigen::Index r, Eigen::Index c) const {
    if (row < 1 || col < 1 || row - 1 + r > Base::rows() || col - 1 + c > Base::cols()) [[unlikely]] {
      internal::throwBlockError(where, row, col, r, c, Base::rows(), Base::cols());
    }
  }
};

/// A column vector of `n` elements (the paper's `ColumnVector`).
template <int n, typename T = double>
using ColumnVector = Matrix<n, 1, T>;
/// A row vector of `n` elements (the paper's `RowVector`).
template <int n, typename T = double>
using RowVector = Matrix<1, n, T>;
/// A vector of `n` elements; vectors are column vectors (the paper's `Vector`).
template <int n, typename T = double>
using Vector = ColumnVector<n, T>;
/// A matrix whose size is known only at run time (stored on the heap).
template <typename T = double>
using MatrixX = Matrix<Dynamic, Dynamic, T>;
/// A column vector whose size is known only at run time (stored on the heap).
template <typename T = double>
using VectorX = Matrix<Dynamic, 1, T>;
/// A column vector of at most `maxSize` elements whose size is set at run time; its storage is
/// inside the object, so it never allocates (used for joint vectors of generic manipulator code).
template <int maxSize, typename T = double>
using BoundedVector = Matrix<Dynamic, 1, T, maxSize, 1>;
/// A matrix of at most `maxRows` x `maxCols` elements whose size is set at run time; never allocates.
template <int maxRows, int maxCols, typename T = double>
using BoundedMatrix = Matrix<Dynamic, Dynamic, T, maxRows, maxCols>;

// ---- Table 2: functions on matrices and vectors ------------------------------------------------

/// The transpose of `m` (an Eigen expression; assign it to a Matrix). Real-time safe: yes.
template <typename Derived>
auto transpose(const Eigen::MatrixBase<Derived>& m) {
  return m.transpose();
}

/// The inverse of a square matrix. @throws MathException if it is singular.
template <int R, int C, typename T, int MR, int MC>
Matrix<R, C, T, MR, MC> inverse(const Matrix<R, C, T, MR, MC>& m) {
  return m.inverse();
}

/// The 2-norm (length) of a vector. Real-time safe: yes.
template <typename Derived>
typename Derived::Scalar length(const Eigen::MatrixBase<Derived>& v) {
  static_assert(Derived::IsVectorAtCompileTime, "rp::length: the argument must be a vector");
  return v.norm();
}

/// The dot product of two vectors of the same size. Real-time safe: yes.
template <typename A, typename B>
typename A::Scalar dotProduct(const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b) {
  static_assert(A::IsVectorAtCompileTime && B::IsVectorAtCompileTime, "rp::dotProduct: arguments must be vectors");
  static_assert(A::SizeAtCompileTime == Dynamic || B::SizeAtCompileTime == Dynamic ||
                    int(A::SizeAtCompileTime) == int(B::SizeAtCompileTime),
                "rp::dotProduct: the vectors must have the same size");
  if (a.size() != b.size()) {
    throw MathException("dotProduct: vectors of " + std::to_string(a.size()) + " and " + std::to_string(b.size()) +
                        " elements");
  }
  if constexpr (int(A::RowsAtCompileTime) == int(B::RowsAtCompileTime)) {
    return a.dot(b);
  } else {
    return a.transpose().dot(b);  // a row vector with a column vector
  }
}

/// The cross product of two 3-vectors. Real-time safe: yes.
template <typename A, typename B>
Matrix<3, 1, typename A::Scalar> crossProduct(const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b) {
  static_assert(A::SizeAtCompileTime == 3 && B::SizeAtCompileTime == 3 && A::ColsAtCompileTime == 1 &&
                    B::ColsAtCompileTime == 1,
                "rp::crossProduct: both arguments must be 3-element column vectors");
  return Matrix<3, 1, typename A::Scalar>(a.cross(b));
}

/// Element-by-element product of two matrices of the same size. Real-time safe: yes.
template <typename A, typename B>
auto elementMultiply(const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b) {
  return a.cwiseProduct(b);
}

// ---- Input/output ------------------------------------------------------------------------------

/// Writes a matrix as rows of numbers separated by spaces, one row per line, each number in the
/// shortest form that reads back to the same value, so that `operator>>` restores it exactly.
/// Real-time safe: no.
template <int R, int C, typename T, int MR, int MC>
std::ostream& operator<<(std::ostream& os, const Matrix<R, C, T, MR, MC>& m) {
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    for (Eigen::Index j = 0; j < m.cols(); ++j) {
      if (j > 0) os << ' ';
      if constexpr (std::is_floating_point_v<T>) {
        char buf[64];
        const auto res = std::to_chars(buf, buf + sizeof buf, m(i, j));
        os.write(buf, res.ptr - buf);
      } else {
        os << m(i, j);
      }
    }
    if (i + 1 < m.rows()) os << '\n';
  }
  return os;
}

/// Reads the elements of a matrix of known size, row by row, as written by `operator<<`
/// (any white space between numbers; `inf`, `-inf` and `nan` accepted).
/// On a malformed or missing number the stream's failbit is set and the matrix is unchanged.
/// Real-time safe: no.
template <int R, int C, typename T, int MR, int MC>
std::istream& operator>>(std::istream& is, Matrix<R, C, T, MR, MC>& m) {
  Matrix<R, C, T, MR, MC> tmp = m;
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    for (Eigen::Index j = 0; j < m.cols(); ++j) {
      std::string token;
      if (!(is >> token)) return is;
      T value{};
      const auto res = std::from_chars(token.data(), token.data() + token.size(), value);
      if (res.ec != std::errc() || res.ptr != token.data() + token.size()) {
        is.setstate(std::ios::failbit);
        return is;
      }
      tmp(i, j) = value;
    }
  }
  m = tmp;
  return is;
}

}  // namespace rp
