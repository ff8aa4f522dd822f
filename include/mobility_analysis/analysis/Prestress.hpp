#pragma once

#include <vector>

#include <Eigen/Core>

#include "mobility_analysis/SparseElimination.hpp"

namespace mobility_analysis {

/// The best cable prestress a set of self-stress states allows.
struct CablePrestress {
  bool feasible = false;  ///< Every cable row ends with a positive multiplier (tension).
  double smallestTension =
      0;  ///< max over combinations of min over cables of the multiplier (weights in [-1, 1]).
  Eigen::VectorXd weights;      ///< Weight of each state (dim states).
  Eigen::VectorXd multipliers;  ///< The combined stress over all equations (dim numConstraints).
};

/**
 * @brief Whether some combination of self-stress states puts every cable in tension (a linear program).
 *
 * maximise t over the weights a in [-1, 1]^k and t <= 1 subject to y_c(a) = sum_k a_k Y(c, k) >= t for every
 * cable row c. The cables can be prestressed exactly when t* > 0 (any feasible a with all y_c > 0 can be
 * scaled into the box). Solved with COIN-OR Clp (dual simplex); the states are local, so Y is sparse.
 * @param[in] states self-stress states (rows of the contract order with coefficients; tension positive on
 * the distance equation |p2 - p1|^2 = L^2).
 * @param[in] numConstraints number of equations (size of the multipliers).
 * @param[in] cableRows the rows of the taut cables' distance equations.
 * @return The best pattern; feasible false when no combination tensions them all, or when @p cableRows is
 * empty.
 */
CablePrestress findCablePrestress(const std::vector<SelfStress>& states, int numConstraints,
                                  const std::vector<int>& cableRows);

}  // namespace mobility_analysis
