#include "EliminationOrders.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <numeric>
#include <vector>

#include "mobility_analysis/EliminationOrder.hpp"
#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

/// An order gives up once it has stored this many times J's entries, plus kBudgetFloor.
constexpr size_t kBudgetFactor = 60;
constexpr size_t kBudgetFloor = 2000000;

/// The rows of J in contract order, the columns by index: the lecture's order.
EliminationOrder contractOrder(const SparseJacobian& J) {
  EliminationOrder order;
  order.rows.resize(J.rows());
  std::iota(order.rows.begin(), order.rows.end(), 0);
  order.columnPriority.resize(J.cols());
  std::iota(order.columnPriority.begin(), order.columnPriority.end(), 0);
  return order;
}

/// @param[in] pivotThreshold SparseElimination's: its default for the sweeps, 1 (the largest entry) for the
/// contract order, as the report's own contract-order fallback takes it (RedundancyAnalysis.hpp).
void eliminate(const char* name, double orderSeconds, const EliminationOrder& order, const SparseJacobian& J,
               const std::string& file, double pivotThreshold = -1.0) {
  const auto start = std::chrono::steady_clock::now();
  SparseElimination elimination(static_cast<int>(J.cols()), order.columnPriority, tolerances::kRank, true,
                                pivotThreshold);
  const size_t budget = kBudgetFactor * static_cast<size_t>(J.nonZeros()) + kBudgetFloor;
  int dependent = 0;
  bool overBudget = false;
  for (int r : order.rows) {
    const double norm = J.row(r).norm();
    if (elimination.addRow(J, r, norm > 0.0 ? 1.0 / norm : 0.0).dependent)
      ++dependent;
    if (elimination.storedEntries() > budget) {
      overBudget = true;
      break;
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "method=orders order=%s file=%s coordinates=%ld equations=%ld nnz=%ld rank=%d dependent=%d stored=%zu "
      "stored_per_nnz=%.2f order_seconds=%.4f seconds=%.4f smallest_kept_pivot=%.3g status=%s\n",
      name, file.c_str(), static_cast<long>(J.cols()), static_cast<long>(J.rows()),
      static_cast<long>(J.nonZeros()), elimination.rank(), dependent, elimination.storedEntries(),
      static_cast<double>(elimination.storedEntries()) /
          static_cast<double>(std::max<Eigen::Index>(1, J.nonZeros())),
      orderSeconds, seconds, elimination.smallestKeptPivot(), overBudget ? "over_budget" : "ok");
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int printEliminationOrders(const Mechanism& mechanism, const CoordinateModel& model, const SparseJacobian& J,
                           const std::string& file) {
  auto start = std::chrono::steady_clock::now();
  const EliminationOrder sweep = computeSweepOrder(mechanism, model);
  eliminate("sweep", secondsSince(start), sweep, J, file);
  start = std::chrono::steady_clock::now();
  const EliminationOrder amd = computeMinimumDegreeOrder(mechanism, model);
  eliminate("amd", secondsSince(start), amd, J, file);
  eliminate("contract", 0.0, contractOrder(J), J, file, 1.0);
  return 0;
}

}  // namespace mobility_analysis
