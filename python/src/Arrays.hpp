// numpy <-> Eigen conversions of the Python module, checked: a wrong shape, a dtype that is not a
// real number, or a value that is not finite is a ValueError naming the argument and the shape
// expected, never a crash or a silent copy of the wrong size.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <initializer_list>
#include <string>
#include <vector>

#include "rp/math/Matrix.hpp"
#include "rp/math/Transform.hpp"
#include "rp/model/ManipulatorModel.hpp"

namespace rp::python {

namespace py = pybind11;

/// A 1-D array of `n` finite real numbers (any real dtype) as a JointVector.
/// @throws py::value_error naming `what` and the shape `(n,)` expected
JointVector toVector(const py::handle& value, int n, const char* what);
/// A 2-D array of shape (rows, cols) of finite reals, as a row-major double array (a copy).
/// @param[in] rows  rows expected; -1: any number (the batch size)
/// @throws py::value_error naming `what` and the shape expected
py::array_t<double, py::array::c_style> toMatrix(const py::handle& value, int rows, int cols, const char* what);
/// A 4 x 4 rigid transform.
/// @throws py::value_error naming `what` if it is not 4 x 4, not finite or not rigid
Transform toTransform(const py::handle& value, const char* what);

/// An N x 4 x 4 array of rigid transforms.
/// @throws py::value_error naming `what` (and the row) if it is not N x 4 x 4 real numbers or a
///         row is not a rigid transform
std::vector<Transform> toTransforms(const py::handle& value, const char* what);

/// The array a batched call writes its results into: `out` if the caller gave one (numpy's `out=`
/// convention: a loop that calls again and again reuses its buffer instead of having a new array
/// made and its pages first touched each time), else a new array of `shape` (newResultArray(),
/// whose large buffers are reused once Python frees them).
/// @throws py::value_error if `out` is not a writable, C-contiguous float64 ndarray of exactly
///         `shape`, or shares memory with one of `inputs`
py::array_t<double> outputArray(const py::object& out, const std::vector<py::ssize_t>& shape,
                                std::initializer_list<const py::array*> inputs);

/// A vector as a new 1-D float64 array.
py::array_t<double> fromVector(const Eigen::Ref<const Eigen::VectorXd>& v);
/// A matrix as a new 2-D float64 array.
py::array_t<double> fromMatrix(const Eigen::Ref<const Eigen::MatrixXd>& m);

}  // namespace rp::python
