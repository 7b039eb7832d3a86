// Checked numpy conversions of the Python module (Arrays.hpp).
#include "Arrays.hpp"

#include "ResultBuffers.hpp"

#include <cmath>
#include <sstream>

namespace rp::python {

namespace {

std::string shapeOf(const py::array& a) {
  std::ostringstream s;
  s << '(';
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s << (i ? ", " : "") << a.shape(i) << (a.ndim() == 1 ? "," : "");
  s << ')';
  return s.str();
}

// The value as a float64 C-contiguous array, refusing what is not an array of real numbers.
py::array_t<double, py::array::c_style> realArray(const py::handle& value, const char* what, const std::string& expected) {
  py::array a = py::array::ensure(value);
  if (!a) throw py::value_error(std::string(what) + ": expected an array of shape " + expected + ", got " +
                                std::string(py::str(py::type::handle_of(value).attr("__name__"))));
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw py::value_error(std::string(what) + ": expected real numbers (float64) of shape " + expected + ", got dtype " +
                          std::string(py::str(a.dtype())));
  }
  return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
}

void checkFinite(const double* v, py::ssize_t size, const char* what) {
  for (py::ssize_t i = 0; i < size; ++i)
    if (!std::isfinite(v[i]))
      throw py::value_error(std::string(what) + ": element " + std::to_string(i) + " is not a finite number");
}

}  // namespace

JointVector toVector(const py::handle& value, int n, const char* what) {
  // Fast path: already a float64 array of the right shape (the common case in a loop).
  if (py::isinstance<py::array_t<double>>(value)) {
    auto a = py::reinterpret_borrow<py::array_t<double>>(value);
    if (a.ndim() == 1 && a.shape(0) == n) {
      JointVector v(n);
      const auto* base = reinterpret_cast<const char*>(a.data());
      for (int i = 0; i < n; ++i) v(i) = *reinterpret_cast<const double*>(base + i * a.strides(0));
      for (int i = 0; i < n; ++i)
        if (!std::isfinite(v(i))) throw py::value_error(std::string(what) + ": element " + std::to_string(i) + " is not a finite number");
      return v;
    }
  }
  const std::string expected = "(" + std::to_string(n) + ",)";
  auto a = realArray(value, what, expected);
  if (a.ndim() != 1 || a.shape(0) != n)
    throw py::value_error(std::string(what) + ": expected shape " + expected + ", got " + shapeOf(a));
  checkFinite(a.data(), a.size(), what);
  JointVector v(n);
  for (int i = 0; i < n; ++i) v(i) = a.data()[i];
  return v;
}

py::array_t<double, py::array::c_style> toMatrix(const py::handle& value, int rows, int cols, const char* what) {
  const std::string expected = "(" + (rows < 0 ? std::string("N") : std::to_string(rows)) + ", " + std::to_string(cols) + ")";
  auto a = realArray(value, what, expected);
  if (a.ndim() != 2 || (rows >= 0 && a.shape(0) != rows) || a.shape(1) != cols)
    throw py::value_error(std::string(what) + ": expected shape " + expected + ", got " + shapeOf(a));
  checkFinite(a.data(), a.size(), what);
  return a;
}

Transform toTransform(const py::handle& value, const char* what) {
  auto a = toMatrix(value, 4, 4, what);
  Transform t;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) t(r, c) = a.data()[r * 4 + c];
  if (const std::string problem = rigidTransformError(t); !problem.empty())
    throw py::value_error(std::string(what) + ": not a rigid transform: it " + problem);
  return t;
}

std::vector<Transform> toTransforms(const py::handle& value, const char* what) {
  const std::string name(what);
  auto a = realArray(value, what, "(N, 4, 4)");
  if (a.ndim() != 3 || a.shape(1) != 4 || a.shape(2) != 4)
    throw py::value_error(name + ": expected an array of shape (N, 4, 4), got " + shapeOf(a));
  std::vector<Transform> poses(static_cast<std::size_t>(a.shape(0)));
  for (py::ssize_t r = 0; r < a.shape(0); ++r) {
    Transform& t = poses[static_cast<std::size_t>(r)];
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) t(i, j) = a.data()[(r * 4 + i) * 4 + j];
    if (const std::string problem = rigidTransformError(t); !problem.empty())
      throw py::value_error(name + "[" + std::to_string(r) + "]: not a rigid transform: it " + problem);
  }
  return poses;
}

py::array_t<double> outputArray(const py::object& out, const std::vector<py::ssize_t>& shape,
                                std::initializer_list<const py::array*> inputs) {
  if (out.is_none()) return newResultArray(shape);
  std::ostringstream want;
  want << '(';
  for (std::size_t i = 0; i < shape.size(); ++i) want << (i ? ", " : "") << shape[i];
  want << ')';
  if (!py::isinstance<py::array>(out))
    throw py::value_error("out: expected a float64 array of shape " + want.str() + ", got " +
                          std::string(py::str(py::type::handle_of(out).attr("__name__"))));
  auto a = py::reinterpret_borrow<py::array>(out);
  if (!a.dtype().is(py::dtype::of<double>()))
    throw py::value_error("out: expected dtype float64, got " + std::string(py::str(a.dtype())));
  bool sameShape = a.ndim() == static_cast<py::ssize_t>(shape.size());
  for (std::size_t i = 0; sameShape && i < shape.size(); ++i) sameShape = a.shape(static_cast<py::ssize_t>(i)) == shape[i];
  if (!sameShape) throw py::value_error("out: expected shape " + want.str() + ", got " + shapeOf(a));
  if (!(a.flags() & py::array::c_style)) throw py::value_error("out: the array must be C-contiguous");
  if (!a.writeable()) throw py::value_error("out: the array is read-only");
  const auto* begin = static_cast<const char*>(a.data());
  const char* end = begin + a.nbytes();
  for (const py::array* in : inputs) {
    const auto* b = static_cast<const char*>(in->data());
    if (b < end && begin < b + in->nbytes()) throw py::value_error("out: the array shares memory with an input");
  }
  return py::reinterpret_borrow<py::array_t<double>>(out);
}

py::array_t<double> fromVector(const Eigen::Ref<const Eigen::VectorXd>& v) {
  py::array_t<double> a(v.size());
  for (Eigen::Index i = 0; i < v.size(); ++i) a.mutable_data()[i] = v(i);
  return a;
}

py::array_t<double> fromMatrix(const Eigen::Ref<const Eigen::MatrixXd>& m) {
  py::array_t<double> a({m.rows(), m.cols()});
  double* out = a.mutable_data();
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) out[r * m.cols() + c] = m(r, c);
  return a;
}

}  // namespace rp::python
