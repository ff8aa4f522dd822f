#pragma once

// Private to src/core: the sweep (SelfStressBasis.cpp) and the finds it has made ahead (FindsAhead.hpp)
// follow the same rule for a dependent row's stress.

#include <algorithm>
#include <optional>
#include <utility>

#include "LocalStressFinder.hpp"

namespace mobility_analysis {
namespace core_detail {

/// Local searches that may fail in a row before the basis stops searching locally (see futileFinds_).
constexpr int kFutileFinds = 8;

/// Dependent rows in a row whose capped trace failed and whose local find succeeded, after which the rule
/// finds before it traces (see futileTraces_).
constexpr int kFutileTraces = 64;

/**
 * The sweep's rule for a dependent row's stress, whoever finds and traces, and what it carries from row to
 * row.
 * @p find a local stress (LocalStressFinder), @p cappedTrace the dependency traced up to a limit, @p
 * fullTrace traced whatever its length.
 */
class StressRule {
 public:
  size_t traceLimit() const { return traceLimit_; }

  /// Whether the next row is found before it is traced: where the balls in space have taken over, or where
  /// the traces have run past their limit kFutileTraces times in a row and the finds have not failed.
  bool findsFirst(const LocalStressFinder& finder) const {
    return (finder.inSpaceFirst() || futileTraces_ >= kFutileTraces) && futileFinds_ < kFutileFinds;
  }

  template <class Find, class CappedTrace, class FullTrace>
  SelfStress resolve(const LocalStressFinder& finder, Find&& find, CappedTrace&& cappedTrace,
                     FullTrace&& fullTrace, int& locallyResolved) {
    // Where the balls in space have taken over (a grid of continuous bars), the sweep's traces run along
    // whole rows of cells and mostly reach the trace limit before they are dropped: the ball goes first. So
    // it does where the traces have kept running past their limit: on a lattice braced by cables 79 308 of
    // the 79 601 stresses of 200 x 200 cells were found after a trace that had run past it, and those traces
    // were 23% of the sweep's instructions on 100 x 100 cells (callgrind, one thread: 2.61 -> 2.02 10^9).
    std::optional<SelfStress> stress;
    if (findsFirst(finder)) {
      stress = find();
      if (stress) {
        ++locallyResolved;
        futileFinds_ = 0;  // the failures counted are those in a row
      } else {
        ++futileFinds_;
      }
    }
    if (!stress) {
      stress = cappedTrace(traceLimit_);
      if (stress)
        futileTraces_ = 0;
    }
    if (!stress && futileFinds_ < kFutileFinds) {
      stress = find();
      if (stress) {
        ++locallyResolved;
        traceLimit_ = std::max(traceLimit_, 2 * stress->size());
        futileFinds_ = 0;
        ++futileTraces_;
      } else {
        ++futileFinds_;
        futileTraces_ = 0;
      }
    }
    if (!stress)
      stress = fullTrace();
    return std::move(*stress);
  }

 private:
  // A traced stress longer than this is found again locally; it follows the local stresses' size, so a
  // mechanism whose loops are large is not re-solved stress by stress.
  size_t traceLimit_ = kTraceLimit;
  // Local searches that failed in a row. A failed search grows its ball to kLocalLimit equations and costs
  // far more than the full trace it falls back on; where the stresses are really long (a grid of continuous
  // bars: 1 of 19 800 stresses of the 100 x 100 grid was found locally, after 1 500 failed searches that took
  // 80% of the whole report's time) the search stops after kFutileFinds failures in a row. One global stress
  // among local ones (a ring's) fails once and leaves the search on.
  int futileFinds_ = 0;
  // Rows in a row whose capped trace ran past its limit and whose find then succeeded. A failed trace costs
  // its limit's pivots and all their multipliers; once they keep failing, the find goes first (its stress is
  // another local one with the same last row in sweep order, so the stresses stay a basis), until a find
  // fails or a trace succeeds.
  int futileTraces_ = 0;
};

}  // namespace core_detail
}  // namespace mobility_analysis
