#pragma once

// Private to src/core: the local stress searches (SelfStressBasis.cpp, ContractEchelon.cpp,
// analysis/Prestress.cpp) copy a few rows of J into a small matrix through it.

#include <cassert>
#include <cmath>
#include <utility>
#include <vector>

#include "mobility_analysis/ConstraintJacobian.hpp"

namespace mobility_analysis {
namespace core_detail {

/// The norm of row @p r of @p J: the same sum, in the same order, as J.row(r).norm(), without building the
/// row's block expression (a local search takes it for every row of every ball).
inline double rowNorm(const SparseJacobian& J, int r) {
  assert(J.isCompressed());
  const double* value = J.valuePtr();
  double squared = 0.0;
  for (int i = J.outerIndexPtr()[r]; i < J.outerIndexPtr()[r + 1]; ++i)
    squared += value[i] * value[i];
  return std::sqrt(squared);
}

/**
 * Rows @p rows of @p J, in that order, over their columns renumbered by @p localOf (global column -> local
 * index below @p numColumns), written into @p local: the matrix setFromTriplets would give (each row's
 * entries by increasing local index, values as in J), but straight into @p local's storage, which keeps its
 * capacity from call to call. Why: a local search builds thousands of such matrices of a few hundred rows
 * (one per cable of a braced lattice, one per redundant row of the sweep); their triplet lists, the sort
 * and the allocations cost about half as much as eliminating them.
 * @param[in,out] scratch one row's entries, reused.
 */
template <class LocalOf>
void copyRows(const SparseJacobian& J, const std::vector<int>& rows, LocalOf&& localOf, int numColumns,
              SparseJacobian& local, std::vector<std::pair<int, double>>& scratch) {
  Eigen::Index entries = 0;
  for (int r : rows)
    entries += J.row(r).nonZeros();
  local.resize(static_cast<Eigen::Index>(rows.size()), numColumns);
  local.resizeNonZeros(entries);
  int* outer = local.outerIndexPtr();
  int* inner = local.innerIndexPtr();
  double* value = local.valuePtr();
  int written = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    outer[i] = written;
    scratch.clear();
    for (SparseJacobian::InnerIterator it(J, rows[i]); it; ++it)
      scratch.emplace_back(localOf(static_cast<int>(it.col())), it.value());
    // Insertion sort: a row has a handful of entries, and their local order is nearly J's.
    for (size_t a = 1; a < scratch.size(); ++a) {
      const std::pair<int, double> entry = scratch[a];
      size_t b = a;
      for (; b > 0 && scratch[b - 1].first > entry.first; --b)
        scratch[b] = scratch[b - 1];
      scratch[b] = entry;
    }
    for (const auto& [column, v] : scratch) {
      inner[written] = column;
      value[written] = v;
      ++written;
    }
  }
  outer[rows.size()] = written;
}

}  // namespace core_detail
}  // namespace mobility_analysis
