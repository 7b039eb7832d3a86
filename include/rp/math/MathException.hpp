#pragma once
/// @file
/// The exception thrown by every error condition of the math library.

#include <stdexcept>
#include <string>

namespace rp {

/// Error in the math library: a singular matrix inverted, a size that does not fit at run time,
/// an index out of range, a filter set up with an impossible cutoff, and so on.
///
/// The message says what was wrong, for example
/// `Matrix::inverse: matrix (4x4) is singular (rank 3)`.
class MathException : public std::runtime_error {
 public:
  /// Creates the exception with a message that says what was wrong.
  /// @param[in] what  human-readable description of the error
  explicit MathException(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace rp
