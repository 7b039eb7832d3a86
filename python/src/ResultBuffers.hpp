// Memory for the large result arrays of the batched calls, kept for the next call once Python has
// freed an array (ResultBuffers.cpp).
#pragma once

#include <pybind11/numpy.h>

#include <cstddef>
#include <vector>

namespace rp::python {

namespace py = pybind11;

/// A new, uninitialised C-contiguous float64 array of `shape` for a batched call to fill.
///
/// Results of 1 MiB or more live in buffers that are kept when Python frees the array (up to
/// `kKeptResultBytes` in all, the oldest given back to the system first) and handed to the next
/// result of about the same size. Without this, each call of a loop of large batched calls had its
/// result's pages zeroed and mapped afresh by the kernel (glibc maps allocations above 32 MiB at
/// most on their own and unmaps them when freed): about 0.04 us per row of a WAM 7 Jacobian, a
/// quarter of the computation. Smaller results come from numpy's allocator as usual.
///
/// Each array owns its buffer until Python frees it (the array's base is a capsule that gives it
/// back); two live arrays never share one. Call with the GIL held.
py::array_t<double> newResultArray(const std::vector<py::ssize_t>& shape);

/// Bytes kept at most, in all, in freed result buffers waiting for the next large result.
inline constexpr std::size_t kKeptResultBytes = std::size_t{256} << 20;

/// Bytes now kept in freed result buffers (for the tests and the benchmark).
std::size_t keptResultBytes();

}  // namespace rp::python
