#include "mobility_analysis/analysis/Prestress.hpp"

#include <algorithm>
#include <limits>
#include <unordered_map>

#include <coin/ClpSimplex.hpp>
#include <coin/ClpSolve.hpp>
#include <coin/CoinPackedMatrix.hpp>

namespace mobility_analysis {

namespace {

/// A tension below this (weights in [-1, 1], states scaled to unit largest coefficient) is no tension.
constexpr double kTensionFloor = 1e-9;
/// Above this many states the linear program is solved by the primal simplex (see findCablePrestress).
constexpr int kPrimalStates = 1000;

}  // namespace

CablePrestress findCablePrestress(const std::vector<SelfStress>& states, int numConstraints,
                                  const std::vector<int>& cableRows) {
  CablePrestress result;
  const int k = static_cast<int>(states.size());
  result.weights = Eigen::VectorXd::Zero(k);
  result.multipliers = Eigen::VectorXd::Zero(numConstraints);
  if (cableRows.empty() || k == 0)
    return result;
  std::unordered_map<int, int> cableIndex;
  for (size_t c = 0; c < cableRows.size(); ++c)
    cableIndex[cableRows[c]] = static_cast<int>(c);

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
      elements.push_back(value);
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

}  // namespace mobility_analysis
