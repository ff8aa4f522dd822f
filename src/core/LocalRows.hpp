#pragma once

// Private to src/core: the local stress searches (SelfStressBasis.cpp, ContractEchelon.cpp,
// analysis/Prestress.cpp, RedundantLinks.cpp) copy a few rows of J into a small matrix through it; row norms
// as J.row(r).norm() sums them.

#include <cassert>
#include <cmath>
#include <utility>
#include <vector>

#include "mobility_analysis/ConstraintJacobian.hpp"

namespace mobility_analysis {
namespace core_detail {

/// The norm of row @p r of @p J: the same sum, in the same order, as J.row(r).norm(), without building the
/// row's block expression (a local search takes it for every row of every ball, the passive-freedom search
/// for every row of J).
inline double rowNorm(const SparseJacobian& J, Eigen::Index r) {
  double squared = 0.0;
  for (SparseJacobian::InnerIterator it(J, r); it; ++it)
    squared += it.value() * it.value();
  return std::sqrt(squared);
}

/**
 * Rows @p rows of @p J, in that order, over their columns renumbered by @p localOf (global column -> local
 * index below @p numColumns), written into @p local: the matrix setFromTriplets would give (each row's
 * entries by increasing local index, values as in J), but straight into @p local's storage, which keeps its
 * capacity from call to call. Why: a local search builds thousands of such matrices of a few hundred rows
 * (one per cable of a braced lattice, one per redundant row of the sweep); their triplet lists, the sort
 * and the allocations cost about half as much as eliminating them. Each entry is sorted into place as it is
 * written (insertion: a row has a handful of entries, and their local order is nearly J's).
 */
template <class LocalOf>
void copyRows(const SparseJacobian& J, const std::vector<int>& rows, LocalOf&& localOf, int numColumns,
              SparseJacobian& local) {
  assert(J.isCompressed());
  const int* rowStart = J.outerIndexPtr();
  const int* column = J.innerIndexPtr();
  const double* value = J.valuePtr();
  Eigen::Index entries = 0;
  for (int r : rows)
    entries += rowStart[r + 1] - rowStart[r];
  local.resize(static_cast<Eigen::Index>(rows.size()), numColumns);
  local.resizeNonZeros(entries);
  int* outer = local.outerIndexPtr();
  int* inner = local.innerIndexPtr();
  double* localValue = local.valuePtr();
  int written = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    const int begin = written;
    outer[i] = begin;
    for (int p = rowStart[rows[i]]; p < rowStart[rows[i] + 1]; ++p) {
      const int c = localOf(column[p]);
      int b = written;
      for (; b > begin && inner[b - 1] > c; --b) {
        inner[b] = inner[b - 1];
        localValue[b] = localValue[b - 1];
      }
      inner[b] = c;
      localValue[b] = value[p];
      ++written;
    }
  }
  outer[rows.size()] = written;
}

/// copyRows over @p columns, numbered 0, 1, ... in the order given. @p map (one entry per column of @p J, all
/// -1) holds their numbers while the rows are copied and is all -1 again afterwards.
inline void copyRowsOver(const SparseJacobian& J, const std::vector<int>& rows,
                         const std::vector<int>& columns, std::vector<int>& map, SparseJacobian& local) {
  for (size_t c = 0; c < columns.size(); ++c)
    map[static_cast<size_t>(columns[c])] = static_cast<int>(c);
  copyRows(
      J, rows, [&](int column) { return map[static_cast<size_t>(column)]; }, static_cast<int>(columns.size()),
      local);
  for (int c : columns)
    map[static_cast<size_t>(c)] = -1;
}

}  // namespace core_detail
}  // namespace mobility_analysis
