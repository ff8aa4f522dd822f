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

/**
 * The sweep's rule for a dependent row's stress, whoever finds and traces, and what it carries from row to
 * row.
 * @p find a local stress (LocalStressFinder), @p cappedTrace the dependency traced up to a limit, @p
 * fullTrace traced whatever its length.
 */
class StressRule {
 public:
  size_t traceLimit() const { return traceLimit_; }

  template <class Find, class CappedTrace, class FullTrace>
  SelfStress resolve(const LocalStressFinder& finder, Find&& find, CappedTrace&& cappedTrace,
                     FullTrace&& fullTrace, int& locallyResolved) {
    // Where the balls in space have taken over (a grid of continuous bars), the sweep's traces run along
    // whole rows of cells and mostly reach the trace limit before they are dropped: the ball goes first.
    std::optional<SelfStress> stress;
    if (finder.inSpaceFirst() && futileFinds_ < kFutileFinds) {
      stress = find();
      if (stress)
        ++locallyResolved;
      else
        ++futileFinds_;
    }
    if (!stress)
      stress = cappedTrace(traceLimit_);
    if (!stress && futileFinds_ < kFutileFinds) {
      stress = find();
      if (stress) {
        ++locallyResolved;
        traceLimit_ = std::max(traceLimit_, 2 * stress->size());
        futileFinds_ = 0;
      } else {
        ++futileFinds_;
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
};

}  // namespace core_detail
}  // namespace mobility_analysis
