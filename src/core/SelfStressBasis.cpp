#include "mobility_analysis/SelfStressBasis.hpp"

#include "mobility_analysis/ContractEchelon.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "EquationGraph.hpp"
#include "LocalMemo.hpp"
#include "LocalRows.hpp"
#include "StressMatrix.hpp"

namespace mobility_analysis {

namespace {

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

/// Local searches that may fail in a row before the basis stops searching locally (see futileFinds).
constexpr int kFutileFinds = 8;

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

/// Stress coefficients below this fraction of the stress's largest are rounding noise [-].
constexpr double kStressNoise = 1e-10;

/**
 * Where each equation acts, at the pose the model was built at: a joint's equations at the points they
 * join, a point's rigid-link combination at the point. The rest of a link's equations (those between its
 * basis elements, its boundary) act on the link as a whole and are attached to it.
 *
 * Why in space: on a link through many joints (a continuous bar pinned at every crossing of a grid) every
 * joint's equations reach every other's through the link's basis, so a ball of links is the whole mechanism
 * after one step, while the self-stresses stay among a few neighbouring joints; their neighbourhood along the
 * link is only visible in where they are.
 */
class EquationPlaces {
 public:
  EquationPlaces(const Mechanism& mechanism, const CoordinateModel& model, const SparseJacobian& J)
      : place_(J.rows(), Eigen::Vector3d::Zero()), located_(J.rows(), 0), attached_(mechanism.links.size()) {
    std::vector<int> elementOf(J.cols(), -1);
    for (size_t e = 0; e < model.elements.size(); ++e) {
      for (int i = 0; i < model.dim; ++i)
        elementOf[model.elements[e].offset + i] = static_cast<int>(e);
    }
    auto position = [&](int e) {
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      x.head(model.dim) = model.q0.segment(model.elements[e].offset, model.dim);
      return x;
    };
    std::vector<int> seen;
    for (int r = 0; r < J.rows(); ++r) {
      const ConstraintEquation& eq = model.equations[r];
      if (eq.source == EquationSource::Joint) {
        // The mean of the points it touches (each point once).
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        int count = 0;
        seen.clear();
        for (SparseJacobian::InnerIterator it(J, r); it; ++it) {
          const int e = elementOf[it.col()];
          if (e < 0 || !model.elements[e].isPoint || std::find(seen.begin(), seen.end(), e) != seen.end())
            continue;
          seen.push_back(e);
          sum += position(e);
          ++count;
        }
        if (count > 0) {
          place_[r] = sum / count;
          located_[r] = 1;
        }
      } else if (eq.source == EquationSource::Link && eq.form == EquationForm::Combination &&
                 model.elements[eq.target].isPoint) {
        place_[r] = position(eq.target);
        located_[r] = 1;
      } else {
        attached_[eq.element].push_back(r);
      }
    }
    // The typical spacing: on each link with located equations, its extent over the places it has less one.
    std::vector<std::vector<int>> linkPlaces(mechanism.links.size());
    for (int r = 0; r < J.rows(); ++r) {
      if (located_[r] != 0 && model.equations[r].source == EquationSource::Link)
        linkPlaces[model.equations[r].element].push_back(r);
    }
    std::vector<double> spacings;
    for (const std::vector<int>& rows : linkPlaces) {
      if (rows.size() < 2)
        continue;
      Eigen::Vector3d low = place_[rows[0]], high = low;
      for (int r : rows) {
        low = low.cwiseMin(place_[r]);
        high = high.cwiseMax(place_[r]);
      }
      const double extent = (high - low).norm();
      if (extent > 0.0)
        spacings.push_back(extent / static_cast<double>(rows.size() - 1));
    }
    if (!spacings.empty()) {
      std::nth_element(spacings.begin(), spacings.begin() + spacings.size() / 2, spacings.end());
      spacing_ = spacings[spacings.size() / 2];
    } else {
      spacing_ = model.characteristicLength > 0.0 ? model.characteristicLength : 1.0;
    }
    // Located rows bucketed in cubes of the spacing.
    for (int r = 0; r < J.rows(); ++r) {
      if (located_[r] == 0)
        continue;
      const Eigen::Vector3i cell = cellOf(place_[r]);
      lowest_ = numLocated_ == 0 ? cell : lowest_.cwiseMin(cell);
      highest_ = numLocated_ == 0 ? cell : highest_.cwiseMax(cell);
      cells_[key(cell)].push_back(r);
      ++numLocated_;
    }
  }

  bool located(int row) const { return located_[row] != 0; }
  size_t numLocated() const { return numLocated_; }
  const Eigen::Vector3d& place(int row) const { return place_[row]; }
  double spacing() const { return spacing_; }
  /// Rows without a place, acting on @p link as a whole.
  const std::vector<int>& attached(int link) const { return attached_[link]; }

  /// Calls @p visit for every located row within @p radius of @p center.
  template <class Visit>
  void forEachWithin(const Eigen::Vector3d& center, double radius, Visit&& visit) const {
    // Only the cells within the places' bounds (a planar model is one cell thick).
    const Eigen::Vector3i low = cellOf(center - Eigen::Vector3d::Constant(radius)).cwiseMax(lowest_);
    const Eigen::Vector3i high = cellOf(center + Eigen::Vector3d::Constant(radius)).cwiseMin(highest_);
    // A box with more cells than there are occupied ones (a wide ball over a ring, whose box is mostly empty:
    // (ring radius / spacing)^2 cells, quadratic in the ring's length) is read by its occupied cells instead.
    const Eigen::Vector3d extent = (high - low + Eigen::Vector3i::Ones()).cast<double>();
    if (extent.x() * extent.y() * extent.z() > static_cast<double>(cells_.size())) {
      for (const auto& cell : cells_) {
        for (int r : cell.second) {
          if ((place_[r] - center).squaredNorm() <= radius * radius)
            visit(r);
        }
      }
      return;
    }
    for (int x = low.x(); x <= high.x(); ++x) {
      for (int y = low.y(); y <= high.y(); ++y) {
        for (int z = low.z(); z <= high.z(); ++z) {
          const auto cell = cells_.find(key(Eigen::Vector3i(x, y, z)));
          if (cell == cells_.end())
            continue;
          for (int r : cell->second) {
            if ((place_[r] - center).squaredNorm() <= radius * radius)
              visit(r);
          }
        }
      }
    }
  }

 private:
  Eigen::Vector3i cellOf(const Eigen::Vector3d& x) const {
    return (x / spacing_).array().floor().cast<int>();
  }
  static uint64_t key(const Eigen::Vector3i& cell) {
    auto part = [](int v) { return static_cast<uint64_t>(static_cast<uint32_t>(v) & 0x1fffffu); };
    return part(cell.x()) | part(cell.y()) << 21 | part(cell.z()) << 42;
  }

  std::vector<Eigen::Vector3d> place_;
  std::vector<char> located_;
  std::vector<std::vector<int>> attached_;
  double spacing_ = 1.0;
  size_t numLocated_ = 0;
  Eigen::Vector3i lowest_ = Eigen::Vector3i::Zero(), highest_ = Eigen::Vector3i::Zero();
  std::unordered_map<uint64_t, std::vector<int>> cells_;
};

/**
 * Finds a stress whose last equation (in sweep order) is a given row among the links within a growing radius
 * of the row's links: the sweep's elimination restricted to the rows of that ball. Workspaces are kept across
 * calls, so one call costs what its ball holds, not what the mechanism holds. Where a ball of links is the
 * whole mechanism at once (links through many joints), the ball is taken in space instead (EquationPlaces).
 */
class LocalStressFinder {
 public:
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
  void sortBySweep(std::vector<int>& rows) const {
    for (int& r : rows)
      r = position_[r];
    std::sort(rows.begin(), rows.end());
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
      std::sort(columns.begin(), columns.end());
      for (int& c : columns)
        c = columnOfPriority_[static_cast<size_t>(c)];
    } else {
      std::sort(columns.begin(), columns.end(),
                [&](int a, int b) { return order_.columnPriority[a] < order_.columnPriority[b]; });
    }
    for (size_t c = 0; c < columns.size(); ++c)
      columnMap_[columns[c]] = static_cast<int>(c);
    SparseJacobian& local = local_;
    core_detail::copyRows(
        J_, rows, [&](int column) { return columnMap_[column]; }, static_cast<int>(columns.size()), local);
    for (int c : columns)
      columnMap_[c] = -1;

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

/**
 * One elimination of J in @p order, tracing each dependent row's stress (locally where the trace runs long).
 * @param[in] fillBudget give up (return nothing) once the elimination has stored more entries than it allows.
 */
std::optional<SelfStressBasis> sweepBasis(const Mechanism& mechanism, const CoordinateModel& model,
                                          const SparseJacobian& J, const EliminationOrder& order,
                                          double tolerance, FillBudget fillBudget,
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
  // A traced stress longer than this is found again locally; it follows the local stresses' size, so a
  // mechanism whose loops are large is not re-solved stress by stress.
  size_t traceLimit = kTraceLimit;
  // Local searches that failed in a row. A failed search grows its ball to kLocalLimit equations and costs
  // far more than the full trace it falls back on; where the stresses are really long (a grid of continuous
  // bars: 1 of 19 800 stresses of the 100 x 100 grid was found locally, after 1 500 failed searches that took
  // 80% of the whole report's time) the search stops after kFutileFinds failures in a row. One global stress
  // among local ones (a ring's) fails once and leaves the search on.
  int futileFinds = 0;
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
    // Where the balls in space have taken over (a grid of continuous bars), the sweep's traces run along
    // whole rows of cells and mostly reach the trace limit before they are dropped: the ball goes first.
    std::optional<SelfStress> stress;
    if (finder().inSpaceFirst() && futileFinds < kFutileFinds) {
      stress = finder().find(r);
      if (stress)
        ++basis.locallyResolved;
      else
        ++futileFinds;
    }
    if (!stress)
      stress = elimination.traceDependency(r, elimination.multipliers(), traceLimit);
    if (!stress && futileFinds < kFutileFinds) {
      stress = finder().find(r);
      if (stress) {
        ++basis.locallyResolved;
        traceLimit = std::max(traceLimit, 2 * stress->size());
        futileFinds = 0;
      } else {
        ++futileFinds;
      }
    }
    if (!stress)
      stress = elimination.traceDependency(r, elimination.multipliers());
    basis.stresses.push_back(std::move(*stress));
  }
  basis.rank = elimination.rank();
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
  const SparseJacobian Y = core_detail::stressMatrix(stresses, m, [](int) { return true; });

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
    reduction.pivot[r] = elimination.addRow(Y, r, 1.0).dependent ? 0 : 1;
    taken += static_cast<size_t>(Y.outerIndexPtr()[r + 1] - Y.outerIndexPtr()[r]);
  }
  reduction.rank = elimination.rank();
  reduction.smallestKeptPivot = elimination.smallestKeptPivot();
  reduction.largestDroppedResidual = elimination.largestDroppedResidual();
  return reduction;
}

/**
 * The sweep's spanning tree taken backwards, from its leaves to the ground, then the connections that close
 * loops in the sweep's order: the rows of each link pivot on its own coordinates before its parent's are seen
 * (no fill along a chain), and each closing connection is reduced once along its loop.
 */
EliminationOrder leavesFirst(const EliminationOrder& order) {
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
  for (int& priority : result.columnPriority)
    priority = n - 1 - priority;
  return result;
}

}  // namespace

SelfStressBasis computeSelfStressBasis(const Mechanism& mechanism, const CoordinateModel& model,
                                       const SparseJacobian& J, double tolerance,
                                       const ProgressCallback& progress, size_t fillBudget) {
  EliminationOrder order = computeSweepOrder(mechanism, model);
  // A tree (only tree joints carry equations) has no loop for a stress to close, but swept from the ground
  // every reduced row is written in the free coordinates of all the links above it: the fill, and the time,
  // grow as the square of its depth (a 2 10^5-link chain ran out of memory). Swept from the leaves instead,
  // each link's rows pivot on its own coordinates before its parent's are seen, and nothing fills in.
  const bool tree = std::all_of(mechanism.joints.begin(), mechanism.joints.end(),
                                [&](const Joint& joint) { return joint.kind == ConnectionKind::TreeJoint; });
  std::optional<SelfStressBasis> found;
  if (tree) {
    found = sweepBasis(mechanism, model, J, leavesFirst(order), tolerance, FillBudget::none(), progress);
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
    const FillBudget budget = FillBudget::total(kFillFactor * static_cast<size_t>(J.nonZeros()) + kFillFloor);
    found = sweepBasis(mechanism, model, J, order, tolerance,
                       fillBudget > 0 ? FillBudget::total(fillBudget) : FillBudget::proportional(kFillFactor),
                       progress);
    if (!found)
      found = sweepBasis(mechanism, model, J, leavesFirst(order), tolerance, budget, progress);
    if (!found)
      found = sweepBasis(mechanism, model, J, order, tolerance, FillBudget::none(), progress);
  }
  SelfStressBasis basis = std::move(*found);

  // Each stress scaled to unit largest coefficient, rounding noise dropped.
  for (SelfStress& stress : basis.stresses) {
    double largest = 0.0;
    for (const auto& entry : stress)
      largest = std::max(largest, std::abs(entry.second));
    SelfStress kept;
    kept.reserve(stress.size());
    for (const auto& [row, value] : stress) {
      if (std::abs(value) > kStressNoise * largest)
        kept.emplace_back(row, value / largest);
    }
    stress = std::move(kept);
  }

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
  return basis;
}

std::optional<OrderedRank> computeOrderedRankFromStresses(const SelfStressBasis& basis, double tolerance) {
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
        made ? basis.echelon : reduceStresses(stresses, m, tolerance, false);
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
