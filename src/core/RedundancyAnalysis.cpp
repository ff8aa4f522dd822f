#include "mobility_analysis/RedundancyAnalysis.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <queue>

#include <Eigen/Dense>

#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

/// Entries below this fraction of a reduced row's largest entry are rounding noise and are not stored [-].
constexpr double kDropTolerance = 1e-15;

/// An entry of a unit-norm row this small at a pivot column is cancellation noise: it is zeroed instead of
/// eliminated. Without it, noise of 1e-17 would walk the elimination down a whole chain of links (a loop row's
/// entries cancel exactly at the first common link, but only up to rounding). Six orders below kRank, so no rank
/// decision can change [-].
constexpr double kCancellationNoise = 1e-14;

/// Coefficients of a dependency below this are not part of it [-] (rows are scaled to unit norm).
constexpr double kDependencyCoefficient = 1e-9;

/// One pivot row of the incremental elimination: P_k = J_origin - sum_j m_kj P_j (all rows scaled to unit norm).
struct PivotRow {
  int origin = -1;                                  ///< Equation it came from.
  int column = -1;                                  ///< Its pivot coordinate.
  double pivot = 0.0;                               ///< Its entry at that coordinate.
  std::vector<std::pair<int, double>> entries;      ///< (column, value).
  std::vector<std::pair<int, double>> multipliers;  ///< (pivot index j, m_kj).
};

/// Dense scatter of one row being reduced, with the list of columns it touches.
class SparseAccumulator {
 public:
  explicit SparseAccumulator(int size) : values_(size, 0.0), present_(size, false) {}

  void add(int column, double value) {
    if (!present_[column]) {
      present_[column] = true;
      touched_.push_back(column);
    }
    values_[column] += value;
  }
  double get(int column) const { return values_[column]; }
  void zero(int column) { values_[column] = 0.0; }
  const std::vector<int>& touched() const { return touched_; }
  void clear() {
    for (int c : touched_) {
      values_[c] = 0.0;
      present_[c] = false;
    }
    touched_.clear();
  }

 private:
  std::vector<double> values_;
  std::vector<bool> present_;
  std::vector<int> touched_;
};

/// Resolves y with y_r = 1 and y^T J = 0 from the multipliers of row r (J_r = sum_k c_k P_k).
std::vector<int> traceDependency(int row, const std::vector<std::pair<int, double>>& multipliers,
                                 const std::vector<PivotRow>& pivots) {
  std::vector<int> support = {row};
  std::map<int, double, std::greater<int>> coefficients;  // pivot index -> c_k, largest first
  for (const auto& [k, m] : multipliers) coefficients[k] += m;
  while (!coefficients.empty()) {
    const auto [k, c] = *coefficients.begin();
    coefficients.erase(coefficients.begin());
    if (std::abs(c) < kDependencyCoefficient) continue;
    support.push_back(pivots[k].origin);
    for (const auto& [j, m] : pivots[k].multipliers) coefficients[j] -= c * m;
  }
  std::sort(support.begin(), support.end());
  return support;
}

/// An answer for m equations in n coordinates with nothing decided yet.
OrderedRank makeEmptyOrderedRank(int m, int n, double tolerance) {
  OrderedRank result;
  result.numCoordinates = n;
  result.tolerance = tolerance;
  result.redundant.assign(m, false);
  result.nullityTrace.resize(m);
  return result;
}

}  // namespace

OrderedRank computeOrderedRank(const SparseJacobian& J, double tolerance, bool computeDependencies,
                               const Eigen::VectorXd* rowScale) {
  const int m = static_cast<int>(J.rows());
  const int n = static_cast<int>(J.cols());
  OrderedRank result = makeEmptyOrderedRank(m, n, tolerance);
  std::vector<PivotRow> pivots;
  std::vector<int> pivotOfColumn(n, -1);
  SparseAccumulator row(n);
  double smallestKept = std::numeric_limits<double>::infinity();
  double largestDropped = 0.0;
  std::priority_queue<int, std::vector<int>, std::greater<int>> pending;  // pivot indices, oldest first
  std::vector<bool> queued;
  std::vector<std::pair<int, double>> multipliers;
  std::vector<int> visited;

  for (int r = 0; r < m; ++r) {
    // Each equation scaled to unit norm, so the threshold is relative to the equation itself.
    double norm = 0.0;
    for (SparseJacobian::InnerIterator it(J, r); it; ++it) norm += it.value() * it.value();
    norm = rowScale != nullptr ? ((*rowScale)(r) > 0.0 ? 1.0 / (*rowScale)(r) : 0.0) : std::sqrt(norm);
    row.clear();
    multipliers.clear();
    if (norm > 0.0) {
      for (SparseJacobian::InnerIterator it(J, r); it; ++it) {
        row.add(static_cast<int>(it.col()), it.value() / norm);
        const int k = pivotOfColumn[it.col()];
        if (k >= 0 && !queued[k]) {
          queued[k] = true;
          pending.push(k);
        }
      }
    }
    // Reduce by the pivot rows in the order they were made: P_k is zero at the pivot columns of earlier pivots,
    // so fill only ever reaches later ones.
    visited.clear();
    while (!pending.empty()) {
      const int k = pending.top();
      pending.pop();
      visited.push_back(k);
      const PivotRow& pivot = pivots[k];
      const double value = row.get(pivot.column);
      if (std::abs(value) <= kCancellationNoise) {
        row.zero(pivot.column);
        continue;
      }
      const double multiplier = value / pivot.pivot;
      multipliers.emplace_back(k, multiplier);
      for (const auto& [column, entry] : pivot.entries) {
        row.add(column, -multiplier * entry);
        const int later = pivotOfColumn[column];
        if (later > k && !queued[later]) {
          queued[later] = true;
          pending.push(later);
        }
      }
      row.zero(pivot.column);
    }
    for (int k : visited) queued[k] = false;

    double residual = 0.0, largest = 0.0;
    for (int c : row.touched()) {
      residual += row.get(c) * row.get(c);
      largest = std::max(largest, std::abs(row.get(c)));
    }
    residual = std::sqrt(residual);
    if (residual <= tolerance) {
      result.redundant[r] = true;
      largestDropped = std::max(largestDropped, residual);
      if (computeDependencies) result.dependencies.push_back(traceDependency(r, multipliers, pivots));
    } else {
      smallestKept = std::min(smallestKept, residual);
      // Threshold partial pivoting: among entries within kPivotThreshold of the largest, the lowest coordinate,
      // which keeps the fill local when coordinates follow the tree from the ground.
      PivotRow pivot;
      pivot.origin = r;
      for (int c : row.touched()) {
        const double v = row.get(c);
        if (std::abs(v) >= tolerances::kPivotThreshold * largest && (pivot.column < 0 || c < pivot.column)) {
          pivot.column = c;
        }
      }
      pivot.pivot = row.get(pivot.column);
      for (int c : row.touched()) {
        const double v = row.get(c);
        if (std::abs(v) > kDropTolerance * largest) pivot.entries.emplace_back(c, v);
      }
      if (computeDependencies) pivot.multipliers = multipliers;
      pivotOfColumn[pivot.column] = static_cast<int>(pivots.size());
      pivots.push_back(std::move(pivot));
      queued.push_back(false);
    }
    result.nullityTrace[r] = n - static_cast<int>(pivots.size());
  }
  result.rank = static_cast<int>(pivots.size());
  result.smallestKeptPivot = std::isinf(smallestKept) ? 0.0 : smallestKept;
  result.largestDroppedResidual = largestDropped;
  return result;
}

OrderedRank computeOrderedRankDense(const Eigen::MatrixXd& J, double tolerance) {
  const int m = static_cast<int>(J.rows());
  const int n = static_cast<int>(J.cols());
  OrderedRank result = makeEmptyOrderedRank(m, n, tolerance);
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
      std::vector<int> support;
      for (int i = 0; i < m; ++i) {
        if (i == r || std::abs(combination(i)) > kDependencyCoefficient) support.push_back(i);
      }
      result.dependencies.push_back(support);
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
    if (norm > 0.0) scaled.row(r) /= norm;
  }
  for (int r = 0; r < J.rows(); ++r) {
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(scaled.topRows(r + 1));
    qr.setThreshold(tolerance);
    trace[r] = static_cast<int>(J.cols()) - static_cast<int>(qr.rank());
  }
  return trace;
}

}  // namespace mobility_analysis
