#include "mobility_analysis/analysis/Prestress.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <unordered_map>

#include <coin/ClpSimplex.hpp>
#include <coin/ClpSolve.hpp>
#include <coin/CoinPackedMatrix.hpp>

#include "../LocalMemo.hpp"
#include "../LocalRows.hpp"
#include "../SignificantBits.hpp"

namespace mobility_analysis {

namespace {

/// A tension below this (weights in [-1, 1], states scaled to unit largest coefficient) is no tension.
constexpr double kTensionFloor = 1e-9;
/// Above this many states the linear program is solved by the primal simplex (see findCablePrestress).
constexpr int kPrimalStates = 1000;
/// A local search gives up once the ball around a cable holds more equations than this,
constexpr int kMaxBallEquations = 400;
/// ... or more coordinates than this,
constexpr int kMaxBallColumns = 1200;
/// ... or after this many layers of neighbours.
constexpr int kMaxBallLayers = 12;
/// Relative threshold below which a reduced row (scaled to unit norm) is dependent (tolerances::kRank) [-].
constexpr double kLocalRank = 1e-8;
/// A dependency passes through the seed when its coefficient there is above this fraction of its largest [-].
constexpr double kSeedShare = 1e-6;
/// Entries of a local state below this fraction of its largest are rounding noise and dropped [-].
constexpr double kLocalNoise = 1e-11;
/// The sum of local states must be in equilibrium to this (|J^T y| against |J| |y|, both at most 1) [-].
constexpr double kLocalResidual = 1e-9;

/// The program's coefficients (states at unit largest coefficient) are rounded to multiples of 2^-40 (about
/// 10^-12) before Clp sees them. Why: its optimum is mostly not unique, and which vertex Clp reaches follows
/// its pivots, which the rounding of the states decides: the same braced lattice in millimetres and in
/// metres got different prestress patterns. Rounded, the same model gives the same program, bit for bit, and
/// the tension floor (10^-9) is far above the change.
constexpr int kProgramFractionBits = 40;

/// The linear program over the states' weights (see findCablePrestress); cableIndex maps rows to cables.
CablePrestress solvePrestressProgram(const std::vector<SelfStress>& states, int numConstraints,
                                     const std::vector<int>& cableRows,
                                     const std::unordered_map<int, int>& cableIndex) {
  CablePrestress result;
  const int k = static_cast<int>(states.size());
  result.weights = Eigen::VectorXd::Zero(k);
  result.multipliers = Eigen::VectorXd::Zero(numConstraints);
  result.decidedBy = PrestressMethod::LinearProgram;
  // Columns: the k weights, then t. Rows: one per cable, y_c(a) - t >= 0.
  const int numCables = static_cast<int>(cableRows.size());
  std::vector<int> rowIndices, columnIndices;
  std::vector<double> elements;
  for (int s = 0; s < k; ++s) {
    for (const auto& [row, value] : states[s]) {
      const auto it = cableIndex.find(row);
      if (it == cableIndex.end())
        continue;
      rowIndices.push_back(it->second);
      columnIndices.push_back(s);
      elements.push_back(core_detail::roundToGrid(value, kProgramFractionBits));
    }
  }
  for (int c = 0; c < numCables; ++c) {
    rowIndices.push_back(c);
    columnIndices.push_back(k);
    elements.push_back(-1.0);
  }
  const CoinPackedMatrix matrix(true, rowIndices.data(), columnIndices.data(), elements.data(),
                                static_cast<CoinBigIndex>(elements.size()));
  std::vector<double> columnLower(k + 1, -1.0), columnUpper(k + 1, 1.0), objective(k + 1, 0.0);
  columnLower[k] = -1.0;
  objective[k] = 1.0;
  std::vector<double> rowLower(numCables, 0.0), rowUpper(numCables, COIN_DBL_MAX);

  ClpSimplex lp;
  lp.setLogLevel(0);
  lp.loadProblem(matrix, columnLower.data(), columnUpper.data(), objective.data(), rowLower.data(),
                 rowUpper.data());
  lp.setOptimizationDirection(-1.0);  // maximise t
  if (k <= kPrimalStates) {
    lp.initialSolve();  // presolve, then the method Clp picks (its dual simplex)
  } else {
    // Many states (a lattice braced by cables: one per cell): the primal simplex. Clp's default dual took 7 s
    // of a 40 x 40 braced lattice's 7.7 s, the primal 0.4 s, with the same answer; small problems keep the
    // dual, whose vertex among equal optima the bundled reports show.
    ClpSolve options;
    options.setSolveType(ClpSolve::usePrimal);
    lp.initialSolve(options);
  }
  if (!lp.isProvenOptimal())
    return result;
  const double* solution = lp.getColSolution();
  for (int s = 0; s < k; ++s)
    result.weights(s) = solution[s];
  result.smallestTension = solution[k];
  for (int s = 0; s < k; ++s) {
    if (result.weights(s) == 0.0)
      continue;
    for (const auto& [row, value] : states[s])
      result.multipliers(row) += result.weights(s) * value;
  }
  // The optimum's own cable multipliers decide (the LP's t is only a bound on them).
  double smallest = std::numeric_limits<double>::infinity();
  for (int row : cableRows)
    smallest = std::min(smallest, result.multipliers(row));
  result.feasible = result.smallestTension > kTensionFloor && smallest > kTensionFloor;
  return result;
}

/// The rows of a ball that can carry a state: a row alone on one of its coordinates (within the ball) has
/// multiplier 0 in every state of the ball, so it goes, and so on inwards. What stays is the largest set of
/// rows with no coordinate held by exactly one of them (the union of two such sets is one), whatever the
/// order of peeling. Workspaces are kept from ball to ball.
class LonelyRowPeeler {
 public:
  /// Row i's entries are entryColumn[rowStart[i] .. rowStart[i + 1]) (rowStart has one entry past the last
  /// row), columns below @p numColumns. Returns 1 for each row that stays.
  const std::vector<char>& peel(const std::vector<int>& entryColumn, const std::vector<int>& rowStart,
                                int numRows, size_t numColumns) {
    count_.assign(numColumns, 0);
    for (int c : entryColumn)
      ++count_[static_cast<size_t>(c)];
    columnStart_.assign(numColumns + 1, 0);
    for (size_t c = 0; c < numColumns; ++c)
      columnStart_[c + 1] = columnStart_[c] + count_[c];
    columnRows_.resize(entryColumn.size());
    fill_.assign(columnStart_.begin(), columnStart_.end() - 1);
    for (int i = 0; i < numRows; ++i) {
      for (int e = rowStart[static_cast<size_t>(i)]; e < rowStart[static_cast<size_t>(i) + 1]; ++e)
        columnRows_[static_cast<size_t>(fill_[static_cast<size_t>(entryColumn[static_cast<size_t>(e)])]++)] =
            i;
    }
    alive_.assign(static_cast<size_t>(numRows), 1);
    lonely_.clear();
    for (size_t c = 0; c < numColumns; ++c) {
      if (count_[c] == 1)
        lonely_.push_back(columnRows_[static_cast<size_t>(columnStart_[c])]);
    }
    while (!lonely_.empty()) {
      const int i = lonely_.back();
      lonely_.pop_back();
      if (!alive_[static_cast<size_t>(i)])
        continue;
      alive_[static_cast<size_t>(i)] = 0;
      for (int e = rowStart[static_cast<size_t>(i)]; e < rowStart[static_cast<size_t>(i) + 1]; ++e) {
        const size_t c = static_cast<size_t>(entryColumn[static_cast<size_t>(e)]);
        if (--count_[c] != 1)
          continue;
        for (int k = columnStart_[c]; k < columnStart_[c + 1]; ++k) {
          if (alive_[static_cast<size_t>(columnRows_[static_cast<size_t>(k)])])
            lonely_.push_back(columnRows_[static_cast<size_t>(k)]);
        }
      }
    }
    return alive_;
  }

 private:
  std::vector<int> count_, columnStart_, columnRows_, fill_, lonely_;
  std::vector<char> alive_;
};

/// What eliminating the kept rows of a ball gave, numbered by kept row (0 the seed): the states elsewhere in
/// the ball (each pulls its own cables), in the order found, then the state through the seed, if any.
struct BallOutcome {
  std::vector<SelfStress> elsewhere;
  std::optional<SelfStress> throughSeed;

  size_t bytes() const {
    size_t entries = throughSeed ? throughSeed->size() : 0;
    for (const SelfStress& state : elsewhere)
      entries += state.size();
    return sizeof(BallOutcome) + entries * sizeof(SelfStress::value_type);
  }
};

/// Workspace of localStressAround: marks sized once for the whole Jacobian (a stamp per ball instead of
/// clearing them), and the ball's own lists, reused from ball to ball, so a ball costs what it holds (a
/// braced lattice asks for one per cell).
struct BallWorkspace {
  std::vector<int> rowStamp, columnStamp, columnGrown, columnLocal;
  int stamp = 0;
  std::vector<int> ball, columns, entryColumn, rowStart, kept, keptRows;
  LonelyRowPeeler peeler;
  SparseJacobian local;
  core_detail::LocalMemo<BallOutcome> memo;
  core_detail::LocalMemo<std::vector<char>> peelMemo;
};

/**
 * Kept row k's dependency (it depends on the rows before it) as a state: multipliers y (y^T J = 0 for J as
 * written), signed so that its cables are in tension, by kept row; nothing when it has no cable or pulls some
 * cables and pushes others. A state through the seed (kept row 0) has y_seed = 1 and becomes
 * outcome.throughSeed (returns true); one elsewhere in the ball is scaled to unit largest and added to
 * outcome.elsewhere.
 */
bool readState(SparseElimination& elimination, int k, const std::vector<int>& keptRows,
               const Eigen::VectorXd& rowNorm, const std::vector<char>& isCable, BallOutcome& outcome) {
  const std::optional<SelfStress> dependency =
      elimination.traceDependency(k, elimination.multipliers(), kMaxBallEquations);
  if (!dependency)
    return false;
  double seedValue = 0.0, largest = 0.0;
  for (const auto& [i, z] : *dependency) {
    largest = std::max(largest, std::abs(z));
    if (i == 0)
      seedValue = z;
  }
  SelfStress stress;
  stress.reserve(dependency->size());
  int pulled = 0, pushed = 0;
  for (const auto& [i, z] : *dependency) {
    if (std::abs(z) <= kLocalNoise * largest)
      continue;
    const int row = keptRows[static_cast<size_t>(i)];
    const double y = z / rowNorm(row);  // z refers to the scaled rows
    if (isCable[static_cast<size_t>(row)])
      (y > 0.0 ? pulled : pushed) += 1;
    stress.emplace_back(i, y);
  }
  if ((pulled > 0) == (pushed > 0))
    return false;
  const bool throughSeed = std::abs(seedValue) > kSeedShare * largest;
  double unit = pulled > 0 ? 1.0 : -1.0;
  if (throughSeed)
    unit = seedValue / rowNorm(keptRows[0]);
  else
    unit /= largest;
  for (auto& entry : stress)
    entry.second /= unit;
  if (!throughSeed) {
    outcome.elsewhere.push_back(std::move(stress));  // it tensions its own cables
    return false;
  }
  outcome.throughSeed = std::move(stress);
  return true;
}

/// Eliminates the kept rows of a ball afresh, in their order (@p local: row k is J's row keptRows[k]), and
/// reads each dependent row's state (readState) until one passes through the seed.
BallOutcome eliminateBall(const SparseJacobian& local, const std::vector<int>& keptRows,
                          const Eigen::VectorXd& rowNorm, const std::vector<char>& isCable) {
  BallOutcome outcome;
  SparseElimination elimination(static_cast<int>(local.cols()), {}, kLocalRank, true);
  for (int k = 0; k < static_cast<int>(local.rows()); ++k) {
    if (elimination.addRow(local, k, 1.0 / rowNorm(keptRows[static_cast<size_t>(k)])).dependent &&
        readState(elimination, k, keptRows, rowNorm, isCable, outcome))
      break;
  }
  return outcome;
}

/// The ball's rows that can carry a state (LonelyRowPeeler), known from an equal pattern where there was one.
const std::vector<char>& peel(BallWorkspace& work, int numRows, size_t numColumns) {
  core_detail::LocalMemo<std::vector<char>>& memo = work.peelMemo;
  if (!memo.active())
    return work.peeler.peel(work.entryColumn, work.rowStart, numRows, numColumns);
  memo.clearKey();
  memo.appendKey(static_cast<uint64_t>(numRows));
  memo.appendKey(static_cast<uint64_t>(numColumns));
  memo.appendKey(work.rowStart.data(), work.rowStart.size());
  memo.appendKey(work.entryColumn.data(), work.entryColumn.size());
  if (const std::vector<char>* known = memo.find())
    return *known;
  const std::vector<char>& alive = work.peeler.peel(work.entryColumn, work.rowStart, numRows, numColumns);
  memo.insert(alive, alive.size());
  return alive;
}

/**
 * A state of self-stress through cable row @p seed that puts no cable in compression, from the rows near
 * it: the ball of rows within a growing number of layers (two rows are neighbours when they share a
 * coordinate). At each size the rows that are alone on one of their coordinates within the ball are peeled
 * off, inwards (such a row has multiplier 0 in every state of the ball); if the seed stays, what stays is
 * eliminated afresh in the order seed, the other rows, the other cables (each by layer). Every row that then
 * depends on the rows before it gives a self-stress of the whole J: the rows outside the ball get 0, and
 * each row of the ball brings all its coordinates. The first one through the seed with no cable pushed is
 * returned, as rows and multipliers y (y^T J = 0 for J as written) with y_seed = 1; with the other cables
 * last it is a short loop of stress that needs few cables (a braced cell: its two diagonals and four sides).
 * Dependencies that miss the seed but pull all their cables are passed to @p found. Nothing when the ball
 * grew past its limits first.
 */
std::optional<SelfStress> localStressAround(const SparseJacobian& J,
                                            const Eigen::SparseMatrix<double, Eigen::ColMajor>& byColumn,
                                            const Eigen::VectorXd& rowNorm, const std::vector<char>& isCable,
                                            int seed, BallWorkspace& work,
                                            const std::function<void(const SelfStress&)>& found) {
  const int stamp = work.stamp++;
  std::vector<int>& ball = work.ball;
  std::vector<int>& columns = work.columns;
  std::vector<int>& entryColumn = work.entryColumn;  // local column of each entry of ball[0, entryRows)
  std::vector<int>& rowStart = work.rowStart;        // row i's entries: [rowStart[i], rowStart[i + 1])
  ball.assign(1, seed);
  columns.clear();
  entryColumn.clear();
  rowStart.clear();
  work.rowStamp[seed] = stamp;
  size_t layerStart = 0;
  int entryRows = 0;
  for (int layer = 0; layer < kMaxBallLayers; ++layer) {
    // Grow: every row on a coordinate of the last layer's rows.
    const size_t layerEnd = ball.size();
    for (size_t i = layerStart; i < layerEnd; ++i) {
      for (SparseJacobian::InnerIterator it(J, ball[i]); it; ++it) {
        const int column = static_cast<int>(it.col());
        if (work.columnGrown[column] == stamp)
          continue;
        work.columnGrown[column] = stamp;
        for (Eigen::SparseMatrix<double, Eigen::ColMajor>::InnerIterator c(byColumn, column); c; ++c) {
          const int row = static_cast<int>(c.row());
          if (work.rowStamp[row] != stamp && rowNorm(row) > 0.0) {
            work.rowStamp[row] = stamp;
            ball.push_back(row);
          }
        }
      }
    }
    layerStart = layerEnd;
    if (ball.size() == layerEnd || static_cast<int>(ball.size()) > kMaxBallEquations)
      return std::nullopt;
    // The ball's rows over its columns, numbered locally in order of appearance.
    const int numRows = static_cast<int>(ball.size());
    for (int i = entryRows; i < numRows; ++i) {
      rowStart.push_back(static_cast<int>(entryColumn.size()));
      for (SparseJacobian::InnerIterator it(J, ball[static_cast<size_t>(i)]); it; ++it) {
        const int column = static_cast<int>(it.col());
        if (work.columnStamp[column] != stamp) {
          work.columnStamp[column] = stamp;
          work.columnLocal[column] = static_cast<int>(columns.size());
          columns.push_back(column);
        }
        entryColumn.push_back(work.columnLocal[column]);
      }
    }
    entryRows = numRows;
    rowStart.push_back(static_cast<int>(entryColumn.size()));  // end of the last row, popped below
    if (static_cast<int>(columns.size()) > kMaxBallColumns)
      return std::nullopt;
    // Peel the rows that cannot carry a state; what stays is where the ball's states can be. The peeling
    // reads the ball's pattern only, so the same pattern elsewhere peels the same (LocalMemo).
    const std::vector<char>& alive = peel(work, numRows, columns.size());
    rowStart.pop_back();
    if (!alive[0])
      continue;  // no state through the seed yet
    // What stays, in the order seed, other rows, other cables (each by layer).
    std::vector<int>& kept = work.kept;
    kept.assign(1, 0);
    for (int pass = 0; pass < 2; ++pass) {
      for (int i = 1; i < numRows; ++i) {
        if (alive[static_cast<size_t>(i)] &&
            bool(isCable[static_cast<size_t>(ball[static_cast<size_t>(i)])]) == (pass == 1))
          kept.push_back(i);
      }
    }
    work.keptRows.resize(kept.size());
    for (size_t k = 0; k < kept.size(); ++k)
      work.keptRows[k] = ball[static_cast<size_t>(kept[k])];
    SparseJacobian& local = work.local;
    core_detail::copyRows(
        J, work.keptRows, [&](int column) { return work.columnLocal[column]; },
        static_cast<int>(columns.size()), local);
    // The same ball elsewhere (a regular structure) gives the same outcome to the bit (LocalMemo): its
    // elimination reads the local matrix and each kept row's norm and kind, nothing else.
    core_detail::LocalMemo<BallOutcome>& memo = work.memo;
    const BallOutcome* outcome = nullptr;
    const bool keyed = memo.active();
    if (keyed) {
      memo.clearKey();
      memo.appendKey(local);
      for (int row : work.keptRows) {
        memo.appendKey(rowNorm(row));
        memo.appendKey(static_cast<uint64_t>(isCable[static_cast<size_t>(row)]));
      }
      outcome = memo.find();
    }
    BallOutcome fresh;
    if (!outcome) {
      fresh = eliminateBall(local, work.keptRows, rowNorm, isCable);
      outcome = &fresh;
    }
    auto inRows = [&](SelfStress state) {
      for (auto& entry : state)
        entry.first = work.keptRows[static_cast<size_t>(entry.first)];
      return state;
    };
    for (const SelfStress& state : outcome->elsewhere)
      found(inRows(state));
    std::optional<SelfStress> result;
    if (outcome->throughSeed)
      result = inRows(*outcome->throughSeed);
    if (keyed && outcome == &fresh) {
      const size_t bytes = fresh.bytes();
      memo.insert(std::move(fresh), bytes);
    }
    if (result)
      return result;
  }
  return std::nullopt;
}

}  // namespace

std::optional<Eigen::VectorXd> findLocalCablePrestress(const SparseJacobian& J,
                                                       const std::vector<int>& cableRows) {
  const int m = static_cast<int>(J.rows());
  if (cableRows.empty())
    return std::nullopt;
  Eigen::VectorXd rowNorm(m);
  for (int r = 0; r < m; ++r)
    rowNorm(r) = J.row(r).norm();
  const Eigen::SparseMatrix<double, Eigen::ColMajor> byColumn = J;
  std::vector<char> isCable(m, 0), covered(m, 0);
  for (int row : cableRows)
    isCable[row] = 1;
  BallWorkspace work;
  work.rowStamp.assign(static_cast<size_t>(m), -1);
  work.columnStamp.assign(static_cast<size_t>(J.cols()), -1);
  work.columnGrown.assign(static_cast<size_t>(J.cols()), -1);
  work.columnLocal.assign(static_cast<size_t>(J.cols()), -1);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(m);
  // Adds a state that tensions its cables and no cable pushed, when it tensions one not yet in tension.
  auto accept = [&](const SelfStress& stress) {
    bool fresh = false;
    for (const auto& [row, value] : stress)
      fresh =
          fresh || (isCable[static_cast<size_t>(row)] && value > 0.0 && !covered[static_cast<size_t>(row)]);
    if (!fresh)
      return;
    for (const auto& [row, value] : stress) {
      y(row) += value;
      if (isCable[static_cast<size_t>(row)] && value > 0.0)
        covered[static_cast<size_t>(row)] = 1;
    }
  };
  for (int seed : cableRows) {
    if (covered[static_cast<size_t>(seed)])
      continue;
    if (rowNorm(seed) <= 0.0)
      return std::nullopt;
    const std::optional<SelfStress> stress =
        localStressAround(J, byColumn, rowNorm, isCable, seed, work, accept);
    if (!stress)
      return std::nullopt;
    accept(*stress);
  }
  // The sum of nonnegative-on-cables states, each cable strictly positive in one: every cable in tension.
  const double largest = y.cwiseAbs().maxCoeff();
  if (!(largest > 0.0) || !std::isfinite(largest))
    return std::nullopt;
  y /= largest;
  // Each state passed the elimination's threshold; the sum must also be in equilibrium, to rounding.
  const double jScale = std::max(1.0, rowNorm.maxCoeff());
  if ((J.transpose() * y).cwiseAbs().maxCoeff() > kLocalResidual * jScale)
    return std::nullopt;
  for (int row : cableRows) {
    if (!(y(row) > kTensionFloor))
      return std::nullopt;
  }
  return y;
}

CablePrestress findCablePrestress(const std::vector<SelfStress>& states, int numConstraints,
                                  const std::vector<int>& cableRows, const SparseJacobian* J,
                                  int localAboveStates) {
  CablePrestress result;
  const int k = static_cast<int>(states.size());
  result.weights = Eigen::VectorXd::Zero(k);
  result.multipliers = Eigen::VectorXd::Zero(numConstraints);
  if (cableRows.empty() || k == 0)
    return result;
  std::unordered_map<int, int> cableIndex;
  for (size_t c = 0; c < cableRows.size(); ++c)
    cableIndex[cableRows[c]] = static_cast<int>(c);
  // A cable that no state touches has multiplier 0 in every combination: no prestress, no LP needed.
  // (Marked by row, not looked up in cableIndex: a 200 x 200 braced lattice's states have 3.5 10^6 entries.)
  std::vector<char> touchedRow(static_cast<size_t>(numConstraints), 0);
  for (const SelfStress& state : states) {
    for (const auto& entry : state) {
      if (entry.first >= 0 && entry.first < numConstraints)
        touchedRow[static_cast<size_t>(entry.first)] = 1;
    }
  }
  if (std::any_of(cableRows.begin(), cableRows.end(), [&](int row) {
        return row < 0 || row >= numConstraints || touchedRow[static_cast<size_t>(row)] == 0;
      })) {
    result.decidedBy = PrestressMethod::UntouchedCable;
    return result;
  }
  if (J != nullptr && k > localAboveStates) {
    std::optional<Eigen::VectorXd> local = findLocalCablePrestress(*J, cableRows);
    if (local) {
      result.feasible = true;
      result.decidedBy = PrestressMethod::LocalStates;
      result.weights.resize(0);
      result.multipliers = std::move(*local);
      result.smallestTension = std::numeric_limits<double>::infinity();
      for (int row : cableRows)
        result.smallestTension = std::min(result.smallestTension, result.multipliers(row));
      return result;
    }
  }
  return solvePrestressProgram(states, numConstraints, cableRows, cableIndex);
}

}  // namespace mobility_analysis
