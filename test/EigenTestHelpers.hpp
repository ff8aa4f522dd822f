#pragma once

#include <sstream>

#include <Eigen/Core>
#include <gtest/gtest.h>

namespace mobility_analysis {

/// Compares two matrices entry by entry; on failure prints both and the first differing entry.
inline ::testing::AssertionResult matricesNear(const Eigen::MatrixXd& expected, const Eigen::MatrixXd& actual,
                                               double tolerance) {
  if (expected.rows() != actual.rows() || expected.cols() != actual.cols()) {
    return ::testing::AssertionFailure() << "sizes differ: expected " << expected.rows() << "x" << expected.cols()
                                         << ", got " << actual.rows() << "x" << actual.cols();
  }
  for (Eigen::Index i = 0; i < expected.rows(); ++i) {
    for (Eigen::Index j = 0; j < expected.cols(); ++j) {
      if (!(std::abs(expected(i, j) - actual(i, j)) <= tolerance)) {
        std::ostringstream out;
        if (expected.size() <= 400) out << "\nexpected:\n" << expected << "\nactual:\n" << actual;
        return ::testing::AssertionFailure() << "first difference at (" << i << ", " << j << "): expected "
                                             << expected(i, j) << ", got " << actual(i, j) << " (tolerance "
                                             << tolerance << ")" << out.str();
      }
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace mobility_analysis
