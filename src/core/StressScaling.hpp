#pragma once

// Private to src/core: the sweep's stresses (SelfStressBasis.cpp) and the contract-order patches'
// (ContractEchelon.cpp) are kept in one scale, with their rounding noise dropped.

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "mobility_analysis/SparseElimination.hpp"

namespace mobility_analysis {
namespace core_detail {

/// Stress coefficients below this fraction of the stress's largest are rounding noise [-].
constexpr double kStressNoise = 1e-10;

/// Scales @p stress to unit largest coefficient and drops its rounding noise, in place (the order of its
/// entries is kept): a braced lattice has tens of thousands of stresses, each scaled once.
inline void scaleToUnitLargest(SelfStress& stress) {
  double largest = 0.0;
  for (const auto& entry : stress)
    largest = std::max(largest, std::abs(entry.second));
  size_t kept = 0;
  for (const auto& [row, value] : stress) {
    if (std::abs(value) > kStressNoise * largest)
      stress[kept++] = {row, value / largest};
  }
  stress.resize(kept);
}

}  // namespace core_detail
}  // namespace mobility_analysis
