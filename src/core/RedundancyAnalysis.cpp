#include "mobility_analysis/RedundancyAnalysis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>

#include <Eigen/Dense>

#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

/// Coefficients of a dependency below this are not part of it [-] (rows are scaled to unit norm).
constexpr double kDependencyCoefficient = 1e-9;

/// An answer for m equations in n coordinates with nothing decided yet.
OrderedRank makeEmptyOrderedRank(int m, int n, double tolerance) {
  OrderedRank result;
  result.numCoordinates = n;
  result.tolerance = tolerance;
  result.redundant.assign(m, false);
  return result;
}

}  // namespace

OrderedRank computeSparseElimination(const SparseJacobian& J, double tolerance,
                                     const EliminationOptions& options) {
  const int m = static_cast<int>(J.rows());
  const int n = static_cast<int>(J.cols());
  OrderedRank result = makeEmptyOrderedRank(m, n, tolerance);
  std::vector<int> identityOrder;
  if (options.rowOrder.empty()) {
    identityOrder.resize(m);
    std::iota(identityOrder.begin(), identityOrder.end(), 0);
  }
  const std::vector<int>& rowOrder = options.rowOrder.empty() ? identityOrder : options.rowOrder;
  const bool scaled = options.rowScale.size() == m;
  result.nullityTrace.resize(rowOrder.size());

  SparseElimination elimination(n, options.columnPriority, tolerance, options.computeDependencies,
                                options.pivotThreshold);
  double smallestKept = -1.0, largestDropped = 0.0;
  for (size_t position = 0; position < rowOrder.size(); ++position) {
    const int r = rowOrder[position];
    if (options.stopAtFullRank && elimination.rank() == n) {
      result.redundant[r] = true;
      result.nullityTrace[position] = 0;
      continue;
    }
    double scale = 0.0;
    if (scaled) {
      scale = options.rowScale(r);
    } else {
      const double norm = J.row(r).norm();
      scale = norm > 0.0 ? 1.0 / norm : 0.0;
    }
    const SparseElimination::Step step = elimination.reduce(J, r, scale);
    bool dependent = step.dependent;
    double residual = step.residual;
    const bool near = residual > tolerance / tolerances::kNearDecisionFactor &&
                      residual < tolerance * tolerances::kNearDecisionFactor;
    if (near && options.recheckNearTolerance) {
      const std::optional<double> distance =
          elimination.distanceFromPivotRows(J, r, scale, options.maxRecheckNullity);
      if (distance) {
        // The distance is never above the reduced norm but for rounding: a row found dependent stays so.
        residual = dependent ? std::min(residual, *distance) : *distance;
        dependent = residual <= tolerance;
      } else {
        ++result.uncheckedNearDecisions;
      }
    }
    if (dependent) {
      largestDropped = std::max(largestDropped, residual);
      result.redundant[r] = true;
      if (options.computeDependencies) {
        result.dependencies.push_back(*elimination.traceDependency(r, elimination.multipliers()));
      }
    } else {
      smallestKept = smallestKept < 0.0 ? residual : std::min(smallestKept, residual);
      elimination.keep();
    }
    result.nullityTrace[position] = n - elimination.rank();
  }
  result.rank = elimination.rank();
  result.reductionSteps = elimination.reductionSteps();
  result.smallestKeptPivot = smallestKept < 0.0 ? 0.0 : smallestKept;
  result.largestDroppedResidual = largestDropped;
  return result;
}

OrderedRank computeOrderedRank(const SparseJacobian& J, double tolerance, bool computeDependencies) {
  EliminationOptions options;
  options.computeDependencies = computeDependencies;
  options.pivotThreshold = 1.0;
  options.recheckNearTolerance = true;
  // Between entries of equal magnitude (exact ties are common where the equations are axis-aligned) the later
  // coordinate: a child link's come after its parent's, so a joint's equations pivot on the child and leave
  // the parent's free for its other joints (as ContractEchelon's patches take their columns). Which of equal
  // entries is taken leaves the pivots' bound (|multiplier| <= 1) as it is. Measured on a strip of the
  // continuous-bar grid in space (2 x 5 000 cells): with the earlier coordinate every third-row pin's reduced
  // row pivoted on a long bar's basis, each pivot row led to the previous pin's, and each later row was
  // reduced along the whole strip: 4.7 s, quadratic; now 0.04 s. The answers and margins of the families and
  // bundled mechanisms measured are otherwise the same or within rounding.
  options.columnPriority.resize(static_cast<size_t>(J.cols()));
  for (Eigen::Index c = 0; c < J.cols(); ++c)
    options.columnPriority[static_cast<size_t>(c)] = static_cast<int>(J.cols() - 1 - c);
  return computeSparseElimination(J, tolerance, options);
}

OrderedRank computeOrderedRankDense(const Eigen::MatrixXd& J, double tolerance) {
  const int m = static_cast<int>(J.rows());
  const int n = static_cast<int>(J.cols());
  OrderedRank result = makeEmptyOrderedRank(m, n, tolerance);
  result.nullityTrace.resize(m);
  // Orthonormal basis Q of the rows kept so far, and T with q_k = sum_i T(k, i) J_i / |J_i|.
  Eigen::MatrixXd Q(n, 0);
  Eigen::MatrixXd T(0, m);
  double smallestKept = std::numeric_limits<double>::infinity();
  double largestDropped = 0.0;
  for (int r = 0; r < m; ++r) {
    const double norm = J.row(r).norm();
    const Eigen::VectorXd row = norm > 0.0 ? (J.row(r).transpose() / norm).eval() : Eigen::VectorXd::Zero(n);
    // Classical Gram-Schmidt, twice (enough for orthogonality to working precision).
    Eigen::VectorXd c = Q.transpose() * row;
    Eigen::VectorXd v = row - Q * c;
    const Eigen::VectorXd c2 = Q.transpose() * v;
    v -= Q * c2;
    c += c2;
    const double residual = v.norm();
    Eigen::RowVectorXd combination = c.transpose() * T;  // row = sum_i combination_i J_i/|J_i| + v
    if (residual <= tolerance) {
      result.redundant[r] = true;
      largestDropped = std::max(largestDropped, residual);
      SelfStress stress;
      for (int i = 0; i < m; ++i) {
        if (i == r) {
          stress.emplace_back(i, 1.0);
        } else if (std::abs(combination(i)) > kDependencyCoefficient) {
          stress.emplace_back(i, -combination(i));
        }
      }
      result.dependencies.push_back(stress);
    } else {
      smallestKept = std::min(smallestKept, residual);
      Q.conservativeResize(n, Q.cols() + 1);
      Q.col(Q.cols() - 1) = v / residual;
      Eigen::RowVectorXd t = -combination;
      t(r) += 1.0;
      T.conservativeResize(T.rows() + 1, m);
      T.row(T.rows() - 1) = t / residual;
    }
    result.nullityTrace[r] = n - static_cast<int>(Q.cols());
  }
  result.rank = static_cast<int>(Q.cols());
  result.smallestKeptPivot = std::isinf(smallestKept) ? 0.0 : smallestKept;
  result.largestDroppedResidual = largestDropped;
  return result;
}

std::vector<int> computeNullityTraceLiteral(const Eigen::MatrixXd& J, double tolerance) {
  std::vector<int> trace(J.rows());
  Eigen::MatrixXd scaled = J;
  for (int r = 0; r < scaled.rows(); ++r) {
    const double norm = scaled.row(r).norm();
    if (norm > 0.0)
      scaled.row(r) /= norm;
  }
  for (int r = 0; r < J.rows(); ++r) {
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(scaled.topRows(r + 1));
    qr.setThreshold(tolerance);
    trace[r] = static_cast<int>(J.cols()) - static_cast<int>(qr.rank());
  }
  return trace;
}

}  // namespace mobility_analysis
