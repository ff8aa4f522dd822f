#pragma once

// Private to src/core: the self-stresses as one sparse matrix Y, a row per equation and a column per stress,
// for the reductions that read them by equation (SelfStressBasis.cpp, RedundantLinks.cpp).

#include <algorithm>
#include <vector>

#include <Eigen/SparseCore>

#include "mobility_analysis/SparseElimination.hpp"

namespace mobility_analysis {
namespace core_detail {

/**
 * Y(r, s) = stress s at equation r, for the equations @p keep accepts, over @p numRows equations: the matrix
 * setFromTriplets gives from one triplet per entry, written straight into compressed row storage by counting
 * where every stress lists its equations in increasing order (each row's entries then come by increasing
 * stress, as setFromTriplets sorts them); a stress that does not (an equation twice: setFromTriplets sums)
 * takes setFromTriplets itself. Why: the contract-order echelon of a 200 x 200 braced lattice has 5.9 10^6
 * entries; their triplets (94 MB), setFromTriplets' column-major pass and its transpose took 0.23 s.
 */
template <class Keep>
SparseJacobian stressMatrix(const std::vector<SelfStress>& stresses, int numRows, Keep&& keep) {
  SparseJacobian Y(numRows, static_cast<int>(stresses.size()));
  std::vector<int> start(static_cast<size_t>(numRows) + 1, 0);
  bool increasing = true;
  for (const SelfStress& stress : stresses) {
    for (size_t i = 0; i < stress.size(); ++i) {
      increasing = increasing && (i == 0 || stress[i - 1].first < stress[i].first);
      if (keep(stress[i].first))
        ++start[static_cast<size_t>(stress[i].first) + 1];
    }
  }
  if (!increasing) {
    std::vector<Eigen::Triplet<double>> triplets;
    for (int s = 0; s < static_cast<int>(stresses.size()); ++s) {
      for (const auto& [row, value] : stresses[static_cast<size_t>(s)]) {
        if (keep(row))
          triplets.emplace_back(row, s, value);
      }
    }
    Y.setFromTriplets(triplets.begin(), triplets.end());
    return Y;
  }
  for (size_t r = 1; r < start.size(); ++r)
    start[r] += start[r - 1];
  Y.resizeNonZeros(start.back());
  std::copy(start.begin(), start.end(), Y.outerIndexPtr());
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int s = 0; s < static_cast<int>(stresses.size()); ++s) {
    for (const auto& [row, value] : stresses[static_cast<size_t>(s)]) {
      if (!keep(row))
        continue;
      const int at = fill[static_cast<size_t>(row)]++;
      Y.innerIndexPtr()[at] = s;
      Y.valuePtr()[at] = value;
    }
  }
  return Y;
}

}  // namespace core_detail
}  // namespace mobility_analysis
