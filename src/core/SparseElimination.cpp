#include "mobility_analysis/SparseElimination.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <Eigen/QR>

#include "Buckets.hpp"
#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

/// Entries below this fraction of a reduced row's largest entry are rounding noise and are not stored [-].
constexpr double kDropTolerance = 1e-15;

/// An entry of a unit-norm row this small at a pivot column is cancellation noise: it is zeroed instead of
/// eliminated. Without it, noise of 1e-17 would walk the elimination down a whole chain of links (a loop
/// row's entries cancel exactly at the first common link, but only up to rounding). Six orders below kRank,
/// so no rank decision can change [-].
constexpr double kCancellationNoise = 1e-14;

/// Coefficients of a dependency below this are not part of it [-] (rows are scaled to unit norm).
constexpr double kDependencyCoefficient = 1e-9;

}  // namespace

std::vector<int> supportOf(const SelfStress& stress) {
  std::vector<int> support;
  support.reserve(stress.size());
  for (const auto& entry : stress)
    support.push_back(entry.first);
  return support;
}

SparseElimination::SparseElimination(int numColumns, std::vector<int> columnPriority, double tolerance,
                                     bool keepMultipliers, double pivotThreshold)
    : columnPriority_(std::move(columnPriority)),
      tolerance_(tolerance),
      pivotThreshold_(pivotThreshold > 0.0 ? pivotThreshold : tolerances::kPivotThreshold),
      keepMultipliers_(keepMultipliers),
      pivotOfColumn_(numColumns, -1),
      values_(numColumns, 0.0),
      present_(numColumns, 0) {}

double SparseElimination::smallestKeptPivot() const {
  return smallestKept_ < 0.0 ? 0.0 : smallestKept_;
}

SparseElimination::Step SparseElimination::addRow(const SparseJacobian& J, int r, double scale) {
  const Step step = reduce(J, r, scale);
  if (step.dependent) {
    largestDropped_ = std::max(largestDropped_, step.residual);
  } else {
    smallestKept_ = smallestKept_ < 0.0 ? step.residual : std::min(smallestKept_, step.residual);
    keep();
  }
  return step;
}

SparseElimination::Step SparseElimination::reduceOver(const SparseJacobian& J, int r, double scale,
                                                      int numPivots) {
  reducedRow_ = r;
  for (int c : touched_) {
    values_[c] = 0.0;
    present_[c] = 0;
  }
  touched_.clear();
  multipliers_.clear();
  // A column's pivot is queued when the column first enters the row, if it is one still to come: pivots are
  // taken in increasing order, so one that is not queued then never is, and one that is stays queued until
  // it is taken; later additions to the column need not look.
  auto add = [&](int column, double value, int after) {
    values_[column] += value;
    if (present_[column] != 0)
      return;
    present_[column] = 1;
    touched_.push_back(column);
    const int pivot = pivotOfColumn_[column];
    if (pivot > after && pivot < numPivots)
      pending_.push(pivot);
  };
  if (scale > 0.0) {
    for (SparseJacobian::InnerIterator it(J, r); it; ++it)
      add(static_cast<int>(it.col()), it.value() * scale, -1);
  }
  while (!pending_.empty()) {
    const int k = pending_.pop();
    const int pivotColumn = column_[k];
    const double value = values_[pivotColumn];
    if (std::abs(value) <= kCancellationNoise) {
      values_[pivotColumn] = 0.0;
      continue;
    }
    const double multiplier = value / pivot_[k];
    multipliers_.emplace_back(k, multiplier);
    ++reductionSteps_;
    for (size_t i = entryStart_[k]; i < entryStart_[k + 1]; ++i) {
      const auto [column, entry] = entries_[i];
      add(column, -multiplier * entry, k);
    }
    values_[pivotColumn] = 0.0;
  }

  // The largest entry too, for keep: one pass over the reduced row instead of two.
  double squared = 0.0;
  reducedLargest_ = 0.0;
  for (int c : touched_) {
    squared += values_[c] * values_[c];
    reducedLargest_ = std::max(reducedLargest_, std::abs(values_[c]));
  }
  Step step;
  step.residual = std::sqrt(squared);
  step.dependent = step.residual <= tolerance_;
  return step;
}

void SparseElimination::keep() {
  const double largest = reducedLargest_;
  if (!(largest > 0.0))
    return;  // nothing to pivot on: a zero row is dependent whatever the tolerance
  // Threshold partial pivoting: among entries within pivotThreshold_ of the largest, the column of lowest
  // priority. The entries are stored in the same pass.
  const double pivotFloor = pivotThreshold_ * largest;
  const double dropFloor = kDropTolerance * largest;
  int pivotColumn = -1;
  int pivotPriority = 0;
  for (int c : touched_) {
    const double value = values_[c];
    const double magnitude = std::abs(value);
    if (magnitude >= pivotFloor) {
      const int p = priority(c);
      if (pivotColumn < 0 || p < pivotPriority) {
        pivotColumn = c;
        pivotPriority = p;
      }
    }
    if (magnitude > dropFloor)
      entries_.emplace_back(c, value);
  }
  origin_.push_back(reducedRow_);
  column_.push_back(pivotColumn);
  pivot_.push_back(values_[pivotColumn]);
  entryStart_.push_back(entries_.size());
  if (keepMultipliers_)
    pivotMultipliers_.insert(pivotMultipliers_.end(), multipliers_.begin(), multipliers_.end());
  multiplierStart_.push_back(pivotMultipliers_.size());
  pivotOfColumn_[pivotColumn] = rank() - 1;
  pending_.resize(origin_.size());
}

void SparseElimination::reserve(size_t rows, size_t entries) {
  origin_.reserve(rows);
  column_.reserve(rows);
  pivot_.reserve(rows);
  entryStart_.reserve(rows + 1);
  multiplierStart_.reserve(rows + 1);
  entries_.reserve(entries);
}

void SparseElimination::reset(int numColumns) {
  assert(columnPriority_.empty());
  origin_.clear();
  column_.clear();
  pivot_.clear();
  entryStart_.assign(1, 0);
  multiplierStart_.assign(1, 0);
  entries_.clear();
  pivotMultipliers_.clear();
  pivotOfColumn_.assign(static_cast<size_t>(numColumns), -1);
  values_.assign(static_cast<size_t>(numColumns), 0.0);
  present_.assign(static_cast<size_t>(numColumns), 0);
  touched_.clear();
  multipliers_.clear();
  smallestKept_ = -1.0;
  reductionSteps_ = 0;
  largestDropped_ = 0.0;
  reducedRow_ = -1;
}

std::optional<double> SparseElimination::distanceFromPivotRows(const SparseJacobian& J, int r, double scale,
                                                               size_t maxNullity) const {
  const std::optional<std::vector<Eigen::VectorXd>> basis = nullSpace(maxNullity);
  if (!basis)
    return std::nullopt;
  if (basis->empty())
    return 0.0;
  Eigen::MatrixXd N(numColumns(), static_cast<Eigen::Index>(basis->size()));
  for (size_t k = 0; k < basis->size(); ++k)
    N.col(static_cast<Eigen::Index>(k)) = (*basis)[k];
  // Column-pivoted QR: the computed basis vectors can be far from orthogonal (they share pivot columns).
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(N);
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(N.rows(), qr.rank());
  Eigen::VectorXd projection = Eigen::VectorXd::Zero(Q.cols());
  for (SparseJacobian::InnerIterator it(J, r); it; ++it)
    projection += (it.value() * scale) * Q.row(it.col()).transpose();
  return projection.norm();
}

std::optional<SelfStress> SparseElimination::traceDependency(
    int row, const std::vector<std::pair<int, double>>& multipliers, size_t maxSupport) {
  // J_row = sum_k c_k P_k, and each P_k expands into J_origin(k) and earlier pivots: push the coefficients
  // down from the latest pivot to the first.
  // The pivots to expand, latest first: a PivotQueue of (latest - k), as a pivot's multipliers only refer to
  // earlier pivots.
  const int latest = rank() - 1;
  coefficient_.resize(origin_.size(), 0.0);
  traced_.resize(origin_.size(), 0);
  traceQueue_.resize(origin_.size());
  std::vector<int>& seen = traceSeen_;
  seen.clear();
  auto add = [&](int k, double value) {
    if (traced_[k] == 0) {
      traced_[k] = 1;
      traceQueue_.push(latest - k);
      seen.push_back(k);
    }
    coefficient_[k] += value;
  };
  for (const auto& [k, m] : multipliers)
    add(k, m);
  SelfStress stress = {{row, 1.0}};
  bool complete = true;
  while (!traceQueue_.empty()) {
    const int k = latest - traceQueue_.pop();
    const double c = coefficient_[k];
    if (std::abs(c) < kDependencyCoefficient)
      continue;
    stress.emplace_back(origin_[k], -c);
    if (maxSupport > 0 && stress.size() > maxSupport) {
      complete = false;
      break;
    }
    for (size_t i = multiplierStart_[k]; i < multiplierStart_[k + 1]; ++i) {
      add(pivotMultipliers_[i].first, -c * pivotMultipliers_[i].second);
    }
  }
  traceQueue_.clear();  // not empty when the support grew past maxSupport
  for (int k : seen) {
    coefficient_[k] = 0.0;
    traced_[k] = 0;
  }
  if (!complete)
    return std::nullopt;
  std::sort(stress.begin(), stress.end());
  return stress;
}

std::optional<std::vector<Eigen::VectorXd>> SparseElimination::nullSpace(size_t maxVectors) const {
  std::vector<int> freeColumns;
  for (size_t c = 0; c < pivotOfColumn_.size(); ++c) {
    if (pivotOfColumn_[c] < 0)
      freeColumns.push_back(static_cast<int>(c));
  }
  if (freeColumns.size() > maxVectors)
    return std::nullopt;
  std::vector<Eigen::VectorXd> basis;
  if (freeColumns.empty())
    return basis;
  // x is 0 at every pivot column no non-zero reaches from the free column: back-substitution visits only the
  // pivot rows holding a column where x is not 0, latest first (each reads pivot columns of later rows
  // only). Why: visiting every row cost the whole fill per vector; on a pin-jointed bar lattice of 100 x 100
  // cells, whose 199 motions each move a few rows of cells, that was 59% of the main thread's instructions.
  // The transpose of the pivot rows: the pivot rows holding each column outside their own pivot column.
  core_detail::Buckets rowsOfColumn(numColumns());
  auto forEachOffPivotEntry = [&](auto&& use) {
    for (int k = 0; k < rank(); ++k) {
      for (size_t i = entryStart_[k]; i < entryStart_[k + 1]; ++i) {
        if (entries_[i].first != column_[k])
          use(entries_[i].first, k);
      }
    }
  };
  forEachOffPivotEntry([&](int column, int) { rowsOfColumn.count(column); });
  rowsOfColumn.allocate();
  forEachOffPivotEntry([&](int column, int k) { rowsOfColumn.add(column, k); });
  // The pivots to visit, latest first: the queue takes the smallest, so pivot k is queued as rank - 1 - k.
  PivotQueue pending;
  pending.resize(static_cast<size_t>(rank()));
  auto queueRowsHolding = [&](int column) {
    for (int k : rowsOfColumn[column])
      pending.push(rank() - 1 - k);
  };
  for (int f : freeColumns) {
    // Where no non-zero reaches, the full back-substitution wrote -0 / pivot: the same zeros, to the sign.
    Eigen::VectorXd x = Eigen::VectorXd::Zero(numColumns());
    for (int k = 0; k < rank(); ++k)
      x(column_[k]) = -0.0 / pivot_[k];
    x(f) = 1.0;
    queueRowsHolding(f);
    while (!pending.empty()) {
      const int k = rank() - 1 - pending.pop();
      double sum = 0.0;
      for (size_t i = entryStart_[k]; i < entryStart_[k + 1]; ++i) {
        if (entries_[i].first != column_[k])
          sum += entries_[i].second * x(entries_[i].first);
      }
      x(column_[k]) = -sum / pivot_[k];
      if (x(column_[k]) != 0.0)
        queueRowsHolding(column_[k]);
    }
    basis.push_back(std::move(x));
  }
  return basis;
}

}  // namespace mobility_analysis
