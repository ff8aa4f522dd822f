#pragma once

#include <vector>

#include <Eigen/Core>

#include "mobility_analysis/ConstraintJacobian.hpp"

namespace mobility_analysis {

/**
 * @brief The lecture's ordered rank test: for each equation, whether it depends on the equations before it.
 */
struct OrderedRank {
  int rank = 0;
  int numCoordinates = 0;
  std::vector<bool> redundant;   ///< Per equation.
  std::vector<int> nullityTrace; ///< Nullity after equations 0..k (dim num_constraints).
  /// For each redundant equation (in order): the equations of its dependency (the support of the left null
  /// vector y with y_r = 1 that combines only r and independent equations before it), r included.
  std::vector<std::vector<int>> dependencies;
  double smallestKeptPivot = 0.0;      ///< Smallest relative pivot of an independent equation [-].
  double largestDroppedResidual = 0.0; ///< Largest relative residual of a redundant equation [-].
  double tolerance = 0.0;              ///< Threshold used [-].
  int dof() const { return numCoordinates - rank; }
};

/**
 * @brief Ordered rank by sparse incremental elimination (threshold partial pivoting over coordinates only).
 *
 * Equations are taken in row order and never reordered; each row, scaled to unit norm, is reduced by the
 * pivot rows before it. If what remains is below @p tolerance the equation is redundant (its nullity step is
 * 0), otherwise it becomes a pivot row. Cost is proportional to the fill, not to the cube of the size.
 * @param[in] J row-major Jacobian, rows in contract order.
 * @param[in] tolerance relative threshold (tolerances::kRank by default).
 * @param[in] computeDependencies whether to compute each redundant equation's dependency.
 */
/// @param[in] rowScale when given, row r is scaled by rowScale(r) instead of by 1 / its norm (dim J.rows()).
OrderedRank computeOrderedRank(const SparseJacobian& J, double tolerance, bool computeDependencies = true,
                               const Eigen::VectorXd* rowScale = nullptr);

/**
 * @brief Reference implementation: dense, with a rank-revealing QR of the Gram-Schmidt residual of each row.
 *
 * Same contract as computeOrderedRank (dependencies included); O(m n^2). For tests and benchmarks.
 */
OrderedRank computeOrderedRankDense(const Eigen::MatrixXd& J, double tolerance);

/**
 * @brief The lecture's literal algorithm: after each equation, the nullity of the rows so far by a
 *        rank-revealing decomposition (ColPivHouseholderQR with an explicit threshold). O(m^2 n^2); for benchmarks.
 */
std::vector<int> computeNullityTraceLiteral(const Eigen::MatrixXd& J, double tolerance);

}  // namespace mobility_analysis
