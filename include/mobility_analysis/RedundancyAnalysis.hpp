#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/SparseElimination.hpp"

namespace mobility_analysis {

/**
 * @brief The ordered rank test: for each equation, whether it depends on the equations taken before it.
 */
struct OrderedRank {
  int rank = 0;
  int numCoordinates = 0;
  std::vector<bool> redundant;    ///< Per equation (indexed by row).
  std::vector<int> nullityTrace;  ///< Nullity after each equation taken, in the order taken (dim rows taken).
  /// For each redundant equation r (in the order found): the self-stress with y_r = 1 that combines only r
  /// and independent equations taken before it.
  std::vector<SelfStress> dependencies;
  double smallestKeptPivot = 0.0;       ///< Smallest relative pivot of an independent equation [-].
  double largestDroppedResidual = 0.0;  ///< Largest relative residual of a redundant equation [-].
  double tolerance = 0.0;               ///< Threshold used [-].
  /// Decisions within tolerances::kNearDecisionFactor of the threshold that no orthogonal re-check settled
  /// (EliminationOptions::recheckNearTolerance): the answer may depend on rounding there.
  int uncheckedNearDecisions = 0;
  /// Pivot rows subtracted over all the reductions (SparseElimination::reductionSteps; 0 from the dense and
  /// stress-based methods): the elimination's work.
  size_t reductionSteps = 0;
  int dof() const { return numCoordinates - rank; }
};

/// How computeSparseElimination takes the rows and picks its pivots.
struct EliminationOptions {
  /// Rows in the order they are taken; empty: 0, 1, …, m − 1. Rows left out are not taken.
  std::vector<int> rowOrder;
  /// Pivot preference of each column, lower first (dim n); empty: the column index.
  std::vector<int> columnPriority;
  /// Row r is scaled by rowScale(r) instead of 1 / |J_r| when given (dim m).
  Eigen::VectorXd rowScale;
  /// Whether to compute each redundant row's dependency (SelfStress).
  bool computeDependencies = false;
  /// Once every column holds a pivot, the remaining rows are dependent: mark them without reducing them
  /// (their dependencies are then not computed).
  bool stopAtFullRank = false;
  /// Pivot acceptance (SparseElimination); 0: tolerances::kPivotThreshold.
  double pivotThreshold = 0.0;
  /**
   * Whether a row whose reduced norm lies within tolerances::kNearDecisionFactor of the tolerance (either
   * side) is decided by its distance from the span of the rows kept before it instead
   * (SparseElimination::distanceFromPivotRows: the dense method's own residual), when no more than
   * maxRecheckNullity columns are free then; otherwise it counts in OrderedRank::uncheckedNearDecisions.
   */
  bool recheckNearTolerance = false;
  size_t maxRecheckNullity = 64;
};

/**
 * @brief The ordered rank test of the rows of @p J taken in @p options.rowOrder, by one SparseElimination.
 *
 * Each row is scaled to unit norm (or by options.rowScale), so the threshold is relative to the equation
 * itself.
 * @param[in] J row-major matrix.
 * @param[in] tolerance relative threshold (tolerances::kRank by default).
 * @param[in] options row order, column priorities, scaling.
 */
OrderedRank computeSparseElimination(const SparseJacobian& J, double tolerance,
                                     const EliminationOptions& options);

/**
 * @brief The lecture's ordered rank test in contract order, by computeSparseElimination over the rows as
 * given, with strict partial pivoting and near-tolerance decisions re-checked.
 *
 * The report's fallback when the self-stress basis is numerically ambiguous, and the sparse reference of the
 * tests. Why strict partial pivoting (pivot on the largest entry): threshold pivoting (kPivotThreshold 0.1)
 * lets elements grow along long eliminations, measured at 5e26 on the 1 000-unit ring pantograph net; on the
 * 100 x 100 continuous-bar grid the rounding of dependent rows then reached 1e-8 and one was kept (DOF 0
 * instead of 1). With the largest entry as pivot that grid's dependent rows reduce to 1e-14 and its smallest
 * kept pivot is 0.01, and the contract order fills less (the ring: 1.1e5 entries instead of 2.1e6, linear in
 * its length). Rows still decided within kNearDecisionFactor of the tolerance are re-checked by their
 * orthogonal distance from the rows kept before them (EliminationOptions::recheckNearTolerance), which is
 * what the dense method compares: on the deployed ring pantograph net from 500 units the reduced rows of
 * dependent equations carried 1e-8 to 2e-8 of amplified rounding (one was kept); their distances are at most
 * 2.3e-9 (1 000 units), which the report flags as near the tolerance.
 * @param[in] J row-major Jacobian, rows in contract order.
 * @param[in] tolerance relative threshold.
 * @param[in] computeDependencies whether to compute each redundant equation's dependency.
 */
OrderedRank computeOrderedRank(const SparseJacobian& J, double tolerance, bool computeDependencies = true);

/**
 * @brief Reference implementation: dense, with Gram–Schmidt of each row against the rows kept before it.
 *
 * Same contract as computeOrderedRank (dependencies included); O(m n^2). For tests and benchmarks.
 */
OrderedRank computeOrderedRankDense(const Eigen::MatrixXd& J, double tolerance);

/**
 * @brief The lecture's literal algorithm: after each equation, the nullity of the rows so far by a
 *        rank-revealing decomposition (ColPivHouseholderQR with an explicit threshold). O(m^2 n^2); for
 * benchmarks.
 */
std::vector<int> computeNullityTraceLiteral(const Eigen::MatrixXd& J, double tolerance);

}  // namespace mobility_analysis
