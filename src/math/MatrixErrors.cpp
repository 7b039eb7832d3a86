// Error messages of rp::Matrix (rp/math/Matrix.hpp), kept out of line so the checks stay small.
#include "rp/math/Matrix.hpp"

namespace rp::internal {

namespace {
std::string size(Eigen::Index r, Eigen::Index c) { return std::to_string(r) + "x" + std::to_string(c); }
std::string bound(int fixed, Eigen::Index max) {
  return fixed == Dynamic ? "up to " + std::to_string(max) : std::to_string(fixed);
}
}  // namespace

void throwIndexError(const char* where, Eigen::Index row, Eigen::Index col, Eigen::Index rows, Eigen::Index cols) {
  throw MathException(std::string("Matrix::") + where + ": element (" + std::to_string(row) + ", " +
                      std::to_string(col) + ") is outside a " + size(rows, cols) +
                      " matrix (indices count from 1)");
}

void throwVectorIndexError(const char* where, Eigen::Index i, Eigen::Index n) {
  throw MathException(std::string("Matrix::") + where + ": element " + std::to_string(i) + " is outside a vector of " +
                      std::to_string(n) + " elements (indices count from 1)");
}

void throwBlockError(const char* where, Eigen::Index row, Eigen::Index col, Eigen::Index r, Eigen::Index c,
                     Eigen::Index rows, Eigen::Index cols) {
  throw MathException(std::string("Matrix::") + where + ": a " + size(r, c) + " block at (" + std::to_string(row) +
                      ", " + std::to_string(col) + ") is outside a " + size(rows, cols) +
                      " matrix (indices count from 1)");
}

void throwSizeError(const char* where, Eigen::Index rows, Eigen::Index cols, int fixedRows, int fixedCols,
                    Eigen::Index maxRows, Eigen::Index maxCols) {
  throw MathException(std::string(where) + ": a " + size(rows, cols) + " value does not fit a matrix of " +
                      bound(fixedRows, maxRows) + "x" + bound(fixedCols, maxCols));
}

}  // namespace rp::internal
