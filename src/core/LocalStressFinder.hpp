#pragma once

// Private to src/core: the sweep (SelfStressBasis.cpp) finds the stresses its trace would make long among the
// equations near each dependent row.

#include <algorithm>
#include <optional>
#include <vector>

#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/EliminationOrder.hpp"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"
#include "mobility_analysis/SelfStressBasis.hpp"
#include "mobility_analysis/SparseElimination.hpp"

#include "EquationGraph.hpp"
#include "EquationPlaces.hpp"
#include "IntSorter.hpp"
#include "LocalMemo.hpp"
#include "LocalRows.hpp"

namespace mobility_analysis {
namespace core_detail {

/// A traced stress with more equations than this is probably running down a chain of loops (a loop of four
/// spatial links has about 70); it is found again by a local elimination instead [equations].
constexpr size_t kTraceLimit = 160;

/// The local elimination gives up on balls with more equations than this; the stress is then traced in full,
/// as it really is global (a ring's) [equations].
constexpr size_t kLocalLimit = 6000;

/// The ball in space starts at this many times the typical spacing of the places where equations act, and
/// grows by kSpaceGrowth each time it holds no stress for its row.
constexpr double kSpaceStart = 2.0;
constexpr double kSpaceGrowth = 1.5;

/**
 * Finds a stress whose last equation (in sweep order) is a given row among the links within a growing radius
 * of the row's links: the sweep's elimination restricted to the rows of that ball. Workspaces are kept across
 * calls, so one call costs what its ball holds, not what the mechanism holds. Where a ball of links is the
 * whole mechanism at once (links through many joints), the ball is taken in space instead (EquationPlaces).
 */
class LocalStressFinder {
 public:
  /// What a finder reads (all of it const while it lives): another thread's finder is made from the same.
  struct Inputs {
    const Mechanism& mechanism;
    const CoordinateModel& model;
    const SparseJacobian& J;
    const EliminationOrder& order;
    const std::vector<int>& position;
    double tolerance;
  };
  explicit LocalStressFinder(const Inputs& in)
      : LocalStressFinder(in.mechanism, in.model, in.J, in.order, in.position, in.tolerance) {}
  LocalStressFinder(const Mechanism& mechanism, const CoordinateModel& model, const SparseJacobian& J,
                    const EliminationOrder& order, const std::vector<int>& position, double tolerance)
      : mechanism_(mechanism),
        model_(model),
        J_(J),
        order_(order),
        position_(position),
        tolerance_(tolerance),
        graph_(mechanism, model),
        inBall_(mechanism.links.size(), 0),
        jointTaken_(mechanism.joints.size(), 0),
        columnMap_(J.cols(), -1),
        localElimination_(0, {}, tolerance, true) {}

  /// Whether the ball in space is tried first (it found shorter stresses than the links' ball).
  bool inSpaceFirst() const { return inSpaceFirst_; }

  /**
   * What one find hands on to the next: the radii that sufficed last and which ball goes first. With the row,
   * it is all a find's stress depends on (the memo returns only what the same inputs gave, the workspaces are
   * emptied after each find, the lazily built tables are the same whenever they are built), so finders in
   * the same state give the same stress to the bit: the sweep can take a find made ahead on another thread
   * (FindsAhead.hpp) when it was made from the state the sweep is in.
   */
  struct State {
    int lastRadius = 1;
    double spaceRadius = 0.0;
    bool inSpaceFirst = false;
    bool operator==(const State& other) const {
      return lastRadius == other.lastRadius && spaceRadius == other.spaceRadius &&
             inSpaceFirst == other.inSpaceFirst;
    }
    bool operator!=(const State& other) const { return !(*this == other); }
  };
  State state() const { return State{lastRadius_, spaceRadius_, inSpaceFirst_}; }
  void setState(const State& state) {
    lastRadius_ = state.lastRadius;
    spaceRadius_ = state.spaceRadius;
    inSpaceFirst_ = state.inSpaceFirst;
  }

  /// @return The stress, or nothing when the ball grows past kLocalLimit equations first.
  std::optional<SelfStress> find(int row) {
    // Once the ball in space has found a shorter stress than the links' ball, the links' is not tried first
    // again: on a grid of continuous bars it is the whole mechanism for every row.
    if (inSpaceFirst_) {
      if (std::optional<SelfStress> found = findInSpace(row))
        return found;
      return findAmongLinks(row);
    }
    std::optional<SelfStress> amongLinks = findAmongLinks(row);
    if (amongLinks && amongLinks->size() <= kTraceLimit)
      return amongLinks;
    // Failed, or as long as a trace: the ball of links was most of the mechanism.
    std::optional<SelfStress> inSpace = findInSpace(row);
    if (inSpace && (!amongLinks || inSpace->size() < amongLinks->size())) {
      inSpaceFirst_ = true;
      return inSpace;
    }
    return amongLinks;
  }

 private:
  /// The ball of links around the row's links.
  std::optional<SelfStress> findAmongLinks(int row) {
    const ConstraintEquation& eq = model_.equations[row];
    ball_.clear();
    if (eq.source == EquationSource::Joint) {
      include(mechanism_.joints[eq.element].link1);
      include(mechanism_.joints[eq.element].link2);
    } else {
      include(eq.element);
    }
    // Start at the radius that sufficed last time: in a regular structure every stress needs the same one.
    std::optional<SelfStress> found;
    size_t frontBegin = 0;
    for (int radius = lastRadius_, reached = 0; !found; radius = radius < 4 ? radius + 1 : 2 * radius) {
      for (; reached < radius && frontBegin < ball_.size(); ++reached) {
        const size_t frontEnd = ball_.size();
        for (size_t i = frontBegin; i < frontEnd; ++i) {
          for (int j : graph_.incident[ball_[i]]) {
            include(mechanism_.joints[j].link1);
            include(mechanism_.joints[j].link2);
          }
        }
        frontBegin = frontEnd;
      }
      const std::vector<int>& rows = collectRows(row);
      if (rows.size() > kLocalLimit) {
        break;
      }
      found = eliminate(rows);
      if (found) {
        lastRadius_ = std::min(radius, 4);  // a ring's global stress must not make every later search global
      } else if (frontBegin == ball_.size()) {
        break;  // the whole component
      }
    }
    for (int link : ball_)
      inBall_[link] = 0;
    return found;
  }

  /// The ball in space around the row's place: the located rows within a growing radius, and the attached
  /// rows of every link they reach.
  std::optional<SelfStress> findInSpace(int row) {
    if (!places_)
      places_.emplace(mechanism_, model_, J_);
    if (!places_->located(row))
      return std::nullopt;
    const Eigen::Vector3d center = places_->place(row);
    std::vector<int>& rows = spaceRows_;
    std::vector<int>& links = spaceLinks_;
    const double start = kSpaceStart * places_->spacing();
    for (double radius = spaceRadius_ > 0.0 ? spaceRadius_ : start;; radius *= kSpaceGrowth) {
      rows.clear();
      links.clear();
      size_t within = 0;
      auto touch = [&](int link) {
        if (inBall_[link] == 0) {
          inBall_[link] = 1;
          links.push_back(link);
        }
      };
      places_->forEachWithin(center, radius, [&](int r) {
        ++within;
        if (position_[r] > position_[row])
          return;
        rows.push_back(r);
        const ConstraintEquation& eq = model_.equations[r];
        if (eq.source == EquationSource::Joint) {
          touch(mechanism_.joints[eq.element].link1);
          touch(mechanism_.joints[eq.element].link2);
        } else {
          touch(eq.element);
        }
      });
      for (int link : links) {
        inBall_[link] = 0;
        for (int r : places_->attached(link)) {
          if (position_[r] < position_[row])
            rows.push_back(r);
        }
      }
      if (rows.size() > kLocalLimit)
        return std::nullopt;
      sortBySweep(rows);
      if (std::optional<SelfStress> found = eliminate(rows)) {
        // The next row starts where this one succeeded (a regular structure needs the same radius), but a
        // global stress must not make every later ball global.
        spaceRadius_ = std::min(radius, 4.0 * start);
        return found;
      }
      if (within == places_->numLocated())
        return std::nullopt;  // the whole mechanism
    }
  }

  void include(int link) {
    if (inBall_[link] == 0) {
      inBall_[link] = 1;
      ball_.push_back(link);
    }
  }

  /// The ball's rows up to @p row, in sweep order (in a list kept from call to call).
  const std::vector<int>& collectRows(int row) {
    std::vector<int>& rows = ballRows_;
    rows.clear();
    joints_.clear();
    for (int link : ball_) {
      for (int r : graph_.linkRows[link]) {
        if (position_[r] < position_[row])
          rows.push_back(r);
      }
      for (int j : graph_.incident[link]) {
        const Joint& joint = mechanism_.joints[j];
        if (jointTaken_[j] != 0 || inBall_[joint.link1] == 0 || inBall_[joint.link2] == 0)
          continue;
        jointTaken_[j] = 1;
        joints_.push_back(j);
        for (int r : graph_.jointRows[j]) {
          if (position_[r] <= position_[row])
            rows.push_back(r);
        }
      }
    }
    for (int j : joints_)
      jointTaken_[j] = 0;
    sortBySweep(rows);
    return rows;
  }

  /// @p rows in sweep order. Their positions are sorted and read back through the order (every row is in it
  /// once): the same order as sorting the rows by position, without the indirection in every comparison.
  void sortBySweep(std::vector<int>& rows) {
    for (int& r : rows)
      r = position_[r];
    sorter_.sort(rows);
    for (int& r : rows)
      r = order_.rows[static_cast<size_t>(r)];
  }

  /// The elimination of @p rows (the last one the row in question): its dependency, if it is dependent.
  std::optional<SelfStress> eliminate(const std::vector<int>& rows) {
    // The columns the rows touch, by sweep priority.
    std::vector<int>& columns = columns_;
    columns.clear();
    for (int r : rows) {
      for (SparseJacobian::InnerIterator it(J_, r); it; ++it) {
        if (columnMap_[it.col()] < 0) {
          columnMap_[it.col()] = 0;
          columns.push_back(static_cast<int>(it.col()));
        }
      }
    }
    if (!inverseTried_) {
      buildColumnOfPriority();
      inverseTried_ = true;
    }
    if (!columnOfPriority_.empty()) {
      for (int& c : columns)
        c = order_.columnPriority[c];
      sorter_.sort(columns);
      for (int& c : columns)
        c = columnOfPriority_[static_cast<size_t>(c)];
    } else {
      std::sort(columns.begin(), columns.end(),
                [&](int a, int b) { return order_.columnPriority[a] < order_.columnPriority[b]; });
    }
    SparseJacobian& local = local_;
    core_detail::copyRowsOver(J_, rows, columns, columnMap_, local);

    // The same local problem elsewhere (a regular structure) has the same dependency to the bit
    // (LocalMemo): the elimination reads the local matrix and nothing else.
    std::optional<SelfStress> stress;
    const bool keyed = memo_.active();
    const std::optional<SelfStress>* known = nullptr;
    if (keyed) {
      memo_.clearKey();
      memo_.appendKey(local);
      known = memo_.find();
    }
    if (known) {
      stress = *known;
    } else {
      stress = lastDependency(local);
      if (keyed)
        memo_.insert(stress, sizeof(stress) + (stress ? stress->size() * sizeof(SelfStress::value_type) : 0));
    }
    if (!stress)
      return std::nullopt;
    for (auto& entry : *stress)
      entry.first = rows[entry.first];
    std::sort(stress->begin(), stress->end());
    return stress;
  }

  /// Where the priorities are a permutation (the sweep numbers every coordinate once), a ball's columns are
  /// put in priority order by sorting their priorities and reading the columns back: the same order as
  /// sorting the columns by priority, without the indirection. Built at the first ball only.
  void buildColumnOfPriority() {
    std::vector<int> columnOf(order_.columnPriority.size(), -1);
    for (size_t c = 0; c < order_.columnPriority.size(); ++c) {
      const int p = order_.columnPriority[c];
      if (p < 0 || p >= static_cast<int>(columnOf.size()) || columnOf[static_cast<size_t>(p)] >= 0)
        return;  // not a permutation: the indirect sort
      columnOf[static_cast<size_t>(p)] = static_cast<int>(c);
    }
    columnOfPriority_ = std::move(columnOf);
  }

  /// The dependency of @p local's last row on the rows before it (local row numbers), if it is dependent.
  std::optional<SelfStress> lastDependency(const SparseJacobian& local) {
    // Columns are sorted by sweep priority, so the local column index is the priority.
    SparseElimination& elimination = localElimination_;
    elimination.reset(static_cast<int>(local.cols()));
    SparseElimination::Step step;
    for (int i = 0; i < local.rows(); ++i) {
      const double norm = core_detail::rowNorm(local, i);
      step = elimination.addRow(local, i, norm > 0.0 ? 1.0 / norm : 0.0);
    }
    if (!step.dependent)
      return std::nullopt;
    return elimination.traceDependency(static_cast<int>(local.rows()) - 1, elimination.multipliers());
  }

  const Mechanism& mechanism_;
  const CoordinateModel& model_;
  const SparseJacobian& J_;
  const EliminationOrder& order_;
  const std::vector<int>& position_;
  double tolerance_;
  core_detail::EquationGraph graph_;
  std::vector<int> ball_;
  std::vector<char> inBall_, jointTaken_;
  std::vector<int> columnMap_;
  // Kept from call to call (a braced lattice asks for one ball per redundant row): no allocation once warm.
  std::vector<int> ballRows_, joints_, columns_;
  std::vector<int> columnOfPriority_;  ///< Inverse of order_.columnPriority where that is a permutation.
  IntSorter sorter_;                   ///< The balls' rows by position and columns by priority.
  bool inverseTried_ = false;
  SparseJacobian local_;
  SparseElimination localElimination_;       ///< Reset for each ball (its pools keep their capacity).
  std::vector<int> spaceRows_, spaceLinks_;  ///< findInSpace's ball: its rows and the links they reach.
  core_detail::LocalMemo<std::optional<SelfStress>> memo_;
  int lastRadius_ = 1;
  std::optional<EquationPlaces> places_;  ///< Built the first time a ball in space is needed.
  double spaceRadius_ = 0.0;
  bool inSpaceFirst_ = false;
};

}  // namespace core_detail
}  // namespace mobility_analysis
