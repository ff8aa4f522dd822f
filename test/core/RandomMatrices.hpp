#pragma once

#include <random>

#include <Eigen/Core>

namespace mobility_analysis {

/**
 * @brief A sparse m x n matrix with exact row dependencies: rows of three random entries, and from row
 *        @p firstCombination on, about half of the rows a random combination of two earlier rows.
 */
inline Eigen::MatrixXd makeRankDeficientMatrix(std::mt19937& random, int m, int n, int firstCombination) {
  std::uniform_int_distribution<int> pick(0, 9);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(m, n);
  for (int r = 0; r < m; ++r) {
    if (r >= firstCombination && pick(random) < 5) {
      // A combination of two earlier rows: structurally sparse, numerically exact dependency.
      const int a = pick(random) % r, b = (pick(random) + 3) % r;
      J.row(r) = normal(random) * J.row(a) + normal(random) * J.row(b);
    } else {
      for (int k = 0; k < 3; ++k) J(r, (r + 4 * k + pick(random)) % n) = normal(random);
    }
  }
  return J;
}

}  // namespace mobility_analysis
