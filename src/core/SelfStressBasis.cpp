#include "mobility_analysis/SelfStressBasis.hpp"

#include "mobility_analysis/ContractEchelon.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "FindsAhead.hpp"
#include "LocalStressFinder.hpp"
#include "SideTask.hpp"
#include "StressMatrix.hpp"
#include "StressRule.hpp"
#include "StressScaling.hpp"

namespace mobility_analysis {

namespace {

using core_detail::LocalStressFinder;
using core_detail::StressRule;

/// The sweep from the ground is abandoned once it has stored this many times the entries of the rows it has
/// taken so far, plus kFillFloor; the leaves-first sweep after it, this many times all of J's entries, plus
/// kFillFloor.
constexpr size_t kFillFactor = 8;
constexpr size_t kFillFloor = 1000000;

/// The sweep's stresses are reduced to contract-order echelon form directly while the reduction stores at
/// most this many times their entries, plus kEchelonFillFloor, and at most kEchelonRunningFactor times the
/// entries of the rows it has taken so far, plus the same floor; past either, local stresses are found
/// (findContractEchelon).
constexpr size_t kEchelonFillFactor = 2;
constexpr size_t kEchelonRunningFactor = 8;
constexpr size_t kEchelonFillFloor = 100000;

/// When an elimination gives up: past a fixed number of stored entries, or past a multiple of the entries of
/// the rows it has taken so far plus a floor (either 0: not that limit; both: never).
struct FillBudget {
  size_t entries = 0;
  size_t perRowEntry = 0;
  size_t floor = kFillFloor;  ///< Added to the multiple.
  static FillBudget none() { return {}; }
  static FillBudget total(size_t entries) { return {entries, 0}; }
  static FillBudget proportional(size_t factor) { return {0, factor}; }
  bool unlimited() const { return entries == 0 && perRowEntry == 0; }
  bool exceeded(size_t stored, size_t rowEntries) const {
    return (entries > 0 && stored > entries) ||
           (perRowEntry > 0 && stored > perRowEntry * rowEntries + floor);
  }
};

/// What the rule needs of a dependent row once the elimination has gone past it (finds made ahead): how many
/// pivot rows it met, and the capped trace made at once.
struct PassedRow {
  int row;
  int pivots;
  size_t limit;  ///< of the trace made at once; 0: none made
  std::optional<SelfStress> trace;
};

/**
 * The rule row by row over the rows passed, as on one thread: a find made ahead from the state @p finder is
 * in, else the finder's own; the trace made at once if its limit is the rule's, else traced again from the
 * reduction the row had when it was added (SparseElimination::reduceOver).
 */
void resolvePassedRows(const SparseJacobian& J, SparseElimination& elimination,
                       core_detail::FindsAhead& ahead, std::vector<PassedRow>& passed,
                       LocalStressFinder& finder, StressRule& rule, SelfStressBasis& basis) {
  finder.setState(LocalStressFinder::State{});
  for (size_t k = 0; k < passed.size(); ++k) {
    PassedRow& row = passed[k];
    core_detail::FindsAhead::Find* made = ahead.finds(k);
    auto find = [&]() -> std::optional<SelfStress> {
      for (int f = 0; f < 2; ++f) {
        if (made[f].made && made[f].from == finder.state()) {
          made[f].made = false;
          finder.setState(made[f].after);
          return std::move(made[f].stress);
        }
      }
      return finder.find(row.row);
    };
    bool reduced = false;
    auto reduceAgain = [&] {
      if (reduced)
        return;
      const double norm = J.row(row.row).norm();
      elimination.reduceOver(J, row.row, norm > 0.0 ? 1.0 / norm : 0.0, row.pivots);
      reduced = true;
    };
    auto cappedTrace = [&](size_t limit) {
      if (row.limit == limit)
        return std::move(row.trace);
      reduceAgain();
      return elimination.traceDependency(row.row, elimination.multipliers(), limit);
    };
    auto fullTrace = [&] {
      reduceAgain();
      return elimination.traceDependency(row.row, elimination.multipliers());
    };
    basis.stresses.push_back(rule.resolve(finder, find, cappedTrace, fullTrace, basis.locallyResolved));
  }
}

/**
 * One elimination of J in @p order, tracing each dependent row's stress (locally where the trace runs long).
 * @param[in] fillBudget give up (return nothing) once the elimination has stored more entries than it allows.
 */
std::optional<SelfStressBasis> sweepBasis(const Mechanism& mechanism, const CoordinateModel& model,
                                          const SparseJacobian& J, const EliminationOrder& order,
                                          double tolerance, FillBudget fillBudget, bool findAhead,
                                          const ProgressCallback& progress) {
  const int m = static_cast<int>(J.rows());
  const int n = static_cast<int>(J.cols());
  std::vector<int> position(m, 0);
  for (size_t i = 0; i < order.rows.size(); ++i)
    position[order.rows[i]] = static_cast<int>(i);

  SelfStressBasis basis;
  basis.numConstraints = m;
  basis.numCoordinates = n;
  SparseElimination elimination(n, order.columnPriority, tolerance, true);
  // A sweep that runs to the end (a tree's) stores at least J's entries: room for them at once. One that may
  // be abandoned at its fill budget grows as it goes (reserved, it raised a ring's peak by 50 MB).
  if (fillBudget.unlimited())
    elimination.reserve(std::min<size_t>(order.rows.size(), static_cast<size_t>(n)),
                        static_cast<size_t>(J.nonZeros()));
  // Built at the first dependent row: a tree has none, and its graph costs a vector per link and joint.
  std::optional<LocalStressFinder> lazyFinder;
  auto finder = [&]() -> LocalStressFinder& {
    if (!lazyFinder)
      lazyFinder.emplace(mechanism, model, J, order, position, tolerance);
    return *lazyFinder;
  };
  StressRule rule;
  // Finds made ahead on a second thread (FindsAhead.hpp), and what the rule needs of each dependent row once
  // the elimination has gone past it.
  std::optional<core_detail::FindsAhead> ahead;
  std::vector<PassedRow> passed;
  const size_t progressStep = std::max<size_t>(1, order.rows.size() / 20);
  size_t rowEntries = 0;  // of the rows taken so far
  for (size_t i = 0; i < order.rows.size(); ++i) {
    if (progress && i % progressStep == 0) {
      progress(static_cast<double>(i) / static_cast<double>(m));
    }
    if (fillBudget.exceeded(elimination.storedEntries(), rowEntries))
      return std::nullopt;
    const int r = order.rows[i];
    rowEntries += static_cast<size_t>(J.outerIndexPtr()[r + 1] - J.outerIndexPtr()[r]);
    const double norm = J.row(r).norm();
    if (!elimination.addRow(J, r, norm > 0.0 ? 1.0 / norm : 0.0).dependent) {
      continue;
    }
    if (findAhead) {
      if (!ahead)
        ahead.emplace(LocalStressFinder::Inputs{mechanism, model, J, order, position, tolerance},
                      static_cast<size_t>(m));
      PassedRow row{r, elimination.rank(), 0, std::nullopt};
      if (!ahead->predictsFindsFirst()) {
        row.limit = ahead->traceLimitHint();
        row.trace = elimination.traceDependency(r, elimination.multipliers(), row.limit);
      }
      ahead->publish(r, row.trace.has_value());
      passed.push_back(std::move(row));
      continue;
    }
    auto find = [&] { return finder().find(r); };
    auto cappedTrace = [&](size_t limit) {
      return elimination.traceDependency(r, elimination.multipliers(), limit);
    };
    auto fullTrace = [&] { return elimination.traceDependency(r, elimination.multipliers()); };
    basis.stresses.push_back(rule.resolve(finder(), find, cappedTrace, fullTrace, basis.locallyResolved));
  }
  if (ahead) {
    ahead->finish(finder());
    resolvePassedRows(J, elimination, *ahead, passed, finder(), rule, basis);
  }
  basis.rank = elimination.rank();
  basis.storedEntries = elimination.storedEntries();
  basis.smallestKeptPivot = elimination.smallestKeptPivot();
  basis.largestDroppedResidual = elimination.largestDroppedResidual();
  if (std::optional<std::vector<Eigen::VectorXd>> motions =
          elimination.nullSpace(SelfStressBasis::kMaxMotions)) {
    basis.motions = std::move(*motions);
    basis.motionsComputed = true;
  }
  return basis;
}

/**
 * The rows of Y (one column per stress) from the last equation up, each kept when it is independent of the
 * rows after it: the kept ones are the stresses' last equations once reduced to echelon form.
 * @param[in] limited give up (return nothing) once the reduction has stored more entries than
 * kEchelonFillFactor times the stresses' entries, or than kEchelonRunningFactor times the entries of the rows
 * taken so far (each plus kEchelonFillFloor); false: no limit.
 */
std::optional<StressEchelon> reduceStresses(const std::vector<SelfStress>& stresses, int m, double tolerance,
                                            bool limited) {
  const int numStresses = static_cast<int>(stresses.size());
  std::vector<int> enters(numStresses, -1);  // the stress's last row: where the upward sweep meets it
  size_t entries = 0;
  for (int s = 0; s < numStresses; ++s) {
    entries += stresses[s].size();
    for (const auto& entry : stresses[s])
      enters[s] = std::max(enters[s], entry.first);
  }
  // The upward reduction cannot end above the lowest last row of a stress (that stress has no entry higher
  // up to pivot on), and mostly ends there: Y is built from that row up, and whole only if the reduction goes
  // further down. Rows of Y are the same either way, so is the answer. Why: the contract-order echelon of a
  // 200 x 200 braced lattice has 5.9 10^6 entries, 0.86 10^6 of them from its lowest last row up (the
  // cables'); the whole Y took 0.07-0.2 s of fresh memory for a reduction of 0.014 s.
  const int lowestLast = numStresses == 0 ? 0 : *std::min_element(enters.begin(), enters.end());
  SparseJacobian Y = core_detail::stressMatrix(stresses, m, [&](int r) { return r >= lowestLast; });

  // Rows from the last equation up, unscaled (the stresses are scaled instead, so a row of rounding noise
  // stays noise); the stress that the upward sweep met last is the preferred pivot. Once every stress has
  // its pivot the earlier rows are all independent and are not looked at: the rigid-link and tree-joint
  // rows come first and the redundancy almost always lies after them.
  // Why the stress met last: measured on the 100 x 100 grid of continuous bars (19 800 local stresses),
  // against the stress the sweep leaves first (its first row, the rule before), it took 0.72 s instead of
  // 2.0 s and dropped residuals of 8e-12 instead of 3.5e-10 (which flagged the rank decision as near the
  // tolerance); on every bundled mechanism and the chain, ring, bar-lattice, spatial-mast and truss-mast
  // families the report is the same to the byte with either rule.
  std::vector<int> byEntering(numStresses);
  std::iota(byEntering.begin(), byEntering.end(), 0);
  std::stable_sort(byEntering.begin(), byEntering.end(), [&](int a, int b) { return enters[a] < enters[b]; });
  std::vector<int> columnPriority(numStresses, 0);
  for (int k = 0; k < numStresses; ++k)
    columnPriority[byEntering[k]] = k;
  SparseElimination elimination(numStresses, std::move(columnPriority), tolerance, false);
  StressEchelon reduction;
  reduction.tolerance = tolerance;
  reduction.pivot.assign(m, 0);
  // Why a running budget beside the total: where the reduction fills (a braced lattice) its fill grows as
  // the square of the rows taken, and the total budget is passed only after most of that square has been
  // paid: at 50 x 50 it stored 20 times the entries of the rows taken after 4 000 of them, and passed the
  // total 1 850 rows later. Where it does not (grids of continuous bars) it stays within 3.3 times.
  const FillBudget budget = limited ? FillBudget{kEchelonFillFactor * entries + kEchelonFillFloor,
                                                 kEchelonRunningFactor, kEchelonFillFloor}
                                    : FillBudget::none();
  size_t taken = 0;
  for (int r = m - 1; r >= 0 && elimination.rank() < numStresses; --r) {
    if (budget.exceeded(elimination.storedEntries(), taken))
      return std::nullopt;
    if (r == lowestLast - 1)
      Y = core_detail::stressMatrix(stresses, m, [](int) { return true; });
    reduction.pivot[r] = elimination.addRow(Y, r, 1.0).dependent ? 0 : 1;
    taken += static_cast<size_t>(Y.outerIndexPtr()[r + 1] - Y.outerIndexPtr()[r]);
  }
  reduction.rank = elimination.rank();
  reduction.smallestKeptPivot = elimination.smallestKeptPivot();
  reduction.largestDroppedResidual = elimination.largestDroppedResidual();
  return reduction;
}

/**
 * Where @p priority numbers every coordinate once: for each priority, the one its column takes when the
 * links' blocks of consecutive priorities are taken in reverse, each block in its own order; else nothing.
 */
std::optional<std::vector<int>> reversedLinkBlocks(const std::vector<int>& priority,
                                                   const CoordinateModel& model) {
  const int n = static_cast<int>(priority.size());
  std::vector<int> linkAt(static_cast<size_t>(n), -2);  // the link of the column at each priority
  for (const Element& element : model.elements) {
    for (int i = 0; i < model.dim; ++i) {
      const int p = priority[static_cast<size_t>(element.offset + i)];
      if (p < 0 || p >= n || linkAt[static_cast<size_t>(p)] != -2)
        return std::nullopt;
      linkAt[static_cast<size_t>(p)] = element.body;
    }
  }
  if (std::find(linkAt.begin(), linkAt.end(), -2) != linkAt.end())
    return std::nullopt;
  // A block [begin, end) of one link's priorities goes to [n - end, n - begin).
  std::vector<int> moved(static_cast<size_t>(n));
  for (int begin = 0; begin < n;) {
    int end = begin + 1;
    while (end < n && linkAt[static_cast<size_t>(end)] == linkAt[static_cast<size_t>(begin)])
      ++end;
    for (int p = begin; p < end; ++p)
      moved[static_cast<size_t>(p)] = n - end + (p - begin);
    begin = end;
  }
  return moved;
}

/**
 * The sweep's spanning tree taken backwards, from its leaves to the ground, then the connections that close
 * loops in the sweep's order: the rows of each link pivot on its own coordinates before its parent's are seen
 * (no fill along a chain), and each closing connection is reduced once along its loop.
 * @param[in] keepWithinLinks the links' blocks of columns are taken in reverse, but within each link the
 * sweep's order is kept: the elements its rigid-link equations express before its basis (orderFromSweep).
 * Reversed as well, the basis comes first and each expressed element's equation pivots on it: a star of
 * 8 000 links on one hub filled 3 GB in 3.4 s. A tree keeps them; a mechanism with loops, whose sweep from
 * the ground filled, does not: the strips of a continuous-bar grid, which the reversed order passes its
 * budget on and minimum degree then takes, are swept from their leaves with it kept, and their stresses share
 * last equations in contract order (10 x 1 000 cells: 1.5 -> 7.4 s, 6.2 s of it in the ordered redundancy).
 */
EliminationOrder leavesFirst(const EliminationOrder& order, const CoordinateModel& model,
                             bool keepWithinLinks) {
  EliminationOrder result = order;
  result.rows.clear();
  for (auto it = order.rows.rbegin(); it != order.rows.rend(); ++it) {
    if (order.closing[*it] == 0)
      result.rows.push_back(*it);
  }
  for (int r : order.rows) {
    if (order.closing[r] != 0)
      result.rows.push_back(r);
  }
  const int n = static_cast<int>(order.columnPriority.size());
  std::optional<std::vector<int>> moved;
  if (keepWithinLinks)
    moved = reversedLinkBlocks(order.columnPriority, model);
  for (int& priority : result.columnPriority)
    priority = moved ? (*moved)[static_cast<size_t>(priority)] : n - 1 - priority;
  return result;
}

}  // namespace

SelfStressBasis sweepSelfStressBasis(const Mechanism& mechanism, const CoordinateModel& model,
                                     const SparseJacobian& J, double tolerance,
                                     const ProgressCallback& progress, size_t fillBudget, bool sideThread) {
  EliminationOrder order = computeSweepOrder(mechanism, model);
  const bool findAhead = sideThread && J.rows() >= core_detail::kSecondThreadEquations;
  // A tree (only tree joints carry equations) has no loop for a stress to close, but swept from the ground
  // every reduced row is written in the free coordinates of all the links above it: the fill, and the time,
  // grow as the square of its depth (a 2 10^5-link chain ran out of memory). Swept from the leaves instead,
  // each link's rows pivot on its own coordinates before its parent's are seen, and nothing fills in.
  const bool tree = std::all_of(mechanism.joints.begin(), mechanism.joints.end(),
                                [&](const Joint& joint) { return joint.kind == ConnectionKind::TreeJoint; });
  // One elimination in @p by, within @p budget, remembering which order it took.
  auto sweepIn = [&](const EliminationOrder& by, FillBudget budget, SweepOrderKind kind) {
    std::optional<SelfStressBasis> basis =
        sweepBasis(mechanism, model, J, by, tolerance, budget, findAhead, progress);
    if (basis)
      basis->sweptBy = kind;
    return basis;
  };
  std::optional<SelfStressBasis> found;
  if (tree) {
    found = sweepIn(leavesFirst(order, model, true), FillBudget::none(), SweepOrderKind::FromTheLeaves);
  } else {
    // Loops can fill the same way: each arc of a long ring is such a chain, and swept from the ground the
    // 2.5 10^4 links of a ring stored 3 10^8 entries (10^5 links: out of memory). The sweep from the ground
    // keeps the stresses of short loops local and is kept while its fill stays within kFillFactor times J's
    // entries (on every bundled mechanism, the masts and the grids it stays below twice; past it the fill
    // grows as the square of the depth); past that it is abandoned for the spanning tree from the leaves and
    // the closing connections after it (a ring: about J's entries), and if that fills as well, the sweep from
    // the ground is run to the end. The budget is checked against the rows taken so far, not all of J: a
    // quadratic fill passes a fixed budget only after about sqrt(budget) rows and has cost their cube by
    // then, and it passes the running one after a few thousand rows (a ring of 10^5 links: self-stresses 0.67
    // -> 0.37 CPU s, peak 503 -> 294 MB); a sweep whose fill stays linear (every mast, grid and lattice
    // measured, at most about twice its rows' entries) meets neither, and their reports are unchanged byte
    // for byte.
    //
    // Where both fill (a long strip of a grid of continuous bars, whose few long bars are pinned to every
    // short one: 2 x 5 000 cells took 9.7 s and 2.1 GB), the links are taken in a minimum degree order of
    // their graph, which eliminates each short bar onto the long ones it crosses (computeMinimumDegreeOrder).
    const FillBudget budget = FillBudget::total(kFillFactor * static_cast<size_t>(J.nonZeros()) + kFillFloor);
    found =
        sweepIn(order, fillBudget > 0 ? FillBudget::total(fillBudget) : FillBudget::proportional(kFillFactor),
                SweepOrderKind::FromTheGround);
    if (!found)
      found = sweepIn(leavesFirst(order, model, false), budget, SweepOrderKind::FromTheLeaves);
    if (!found)
      found = sweepIn(computeMinimumDegreeOrder(mechanism, model), budget, SweepOrderKind::MinimumDegree);
    if (!found)
      found = sweepIn(order, FillBudget::none(), SweepOrderKind::FromTheGround);
  }
  SelfStressBasis basis = std::move(*found);

  for (SelfStress& stress : basis.stresses)
    core_detail::scaleToUnitLargest(stress);

  return basis;
}

void reduceToContractOrder(const Mechanism& mechanism, const CoordinateModel& model, const SparseJacobian& J,
                           double tolerance, SelfStressBasis& basis) {
  // Reduced to echelon form on their last equations in contract order, the sweep's stresses fill where
  // they share last equations (on a lattice of bars braced by cables they combine along whole rows of cells:
  // 1.2 10^6 entries and 5.5 s at 50 x 50, far past a minute at 100 x 100). Where the reduction passes its
  // budget, stresses local in contract order are found instead, and the reduction of those does not fill.
  // A reduction that stays within its budget is the one the ordered rank needs: it is kept (basis.echelon).
  bool ownLastRows = true;
  std::vector<char> isLast(J.rows(), 0);
  for (const SelfStress& stress : basis.stresses) {
    if (!stress.empty()) {
      ownLastRows = ownLastRows && isLast[stress.back().first] == 0;
      isLast[stress.back().first] = 1;
    }
  }
  if (!ownLastRows) {
    basis.echelon = reduceStresses(basis.stresses, static_cast<int>(J.rows()), tolerance, true);
    if (!basis.echelon) {
      if (std::optional<std::vector<SelfStress>> echelon =
              findContractEchelon(mechanism, model, J, basis.stresses, tolerance))
        basis.contractEchelon = std::move(*echelon);
    }
  }
}

SelfStressBasis computeSelfStressBasis(const Mechanism& mechanism, const CoordinateModel& model,
                                       const SparseJacobian& J, double tolerance,
                                       const ProgressCallback& progress, size_t fillBudget, bool sideThread) {
  SelfStressBasis basis =
      sweepSelfStressBasis(mechanism, model, J, tolerance, progress, fillBudget, sideThread);
  reduceToContractOrder(mechanism, model, J, tolerance, basis);
  return basis;
}

std::optional<OrderedRank> computeOrderedRankFromStresses(const SelfStressBasis& basis, double tolerance,
                                                          bool limited) {
  const int m = basis.numConstraints;
  const int n = basis.numCoordinates;
  OrderedRank result;
  result.numCoordinates = n;
  result.tolerance = tolerance;
  result.rank = basis.rank;
  result.redundant.assign(m, false);
  result.smallestKeptPivot = basis.smallestKeptPivot;
  result.largestDroppedResidual = basis.largestDroppedResidual;

  // The basis in contract-order echelon form, where one was found, spans the same stresses and reduces
  // without fill.
  const bool echelon =
      !basis.contractEchelon.empty() && basis.contractEchelon.size() == basis.stresses.size();
  const std::vector<SelfStress>& stresses = echelon ? basis.contractEchelon : basis.stresses;
  if (!stresses.empty()) {
    // The reduction computeSelfStressBasis made (within its budget, so the same as an unbounded one).
    const bool made = !echelon && basis.echelon && basis.echelon->tolerance == tolerance;
    const std::optional<StressEchelon> reduction =
        made ? basis.echelon : reduceStresses(stresses, m, tolerance, limited);
    if (!reduction || reduction->rank != static_cast<int>(stresses.size()))
      return std::nullopt;
    for (int r = 0; r < m; ++r)
      result.redundant[r] = reduction->pivot[r] != 0;
    if (reduction->smallestKeptPivot > 0.0) {
      result.smallestKeptPivot = result.smallestKeptPivot > 0.0
                                     ? std::min(result.smallestKeptPivot, reduction->smallestKeptPivot)
                                     : reduction->smallestKeptPivot;
    }
    result.largestDroppedResidual =
        std::max(result.largestDroppedResidual, reduction->largestDroppedResidual);
  }
  result.nullityTrace.resize(m);
  int independent = 0;
  for (int r = 0; r < m; ++r) {
    if (!result.redundant[r])
      ++independent;
    result.nullityTrace[r] = n - independent;
  }
  return result;
}

}  // namespace mobility_analysis
