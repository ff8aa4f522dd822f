#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/SparseElimination.hpp"

namespace mobility_analysis {

/// How findCablePrestress reached its answer.
enum class PrestressMethod {
  None,            ///< Nothing to decide (no cables or no states): not prestressable.
  UntouchedCable,  ///< Some cable has coefficient 0 in every state: not prestressable, no LP.
  LocalStates,     ///< A sum of local states, each nonnegative on every cable: prestressable, no LP.
  LinearProgram,   ///< The linear program over the states' weights decided.
};

/// The best cable prestress a set of self-stress states allows.
struct CablePrestress {
  bool feasible = false;  ///< Every cable row ends with a positive multiplier (tension).
  /// LinearProgram: max over combinations of min over cables of the multiplier (weights in [-1, 1]);
  /// LocalStates: the smallest cable multiplier of the prestress found (largest |multiplier| 1).
  double smallestTension = 0;
  Eigen::VectorXd weights;      ///< Weight of each state (dim states; empty for LocalStates).
  Eigen::VectorXd multipliers;  ///< The combined stress over all equations (dim numConstraints).
  PrestressMethod decidedBy = PrestressMethod::None;
};

/// With more states than this (and the Jacobian given), findCablePrestress looks for local states first.
constexpr int kLocalPrestressStates = 1000;

/**
 * @brief Whether some combination of self-stress states puts every cable in tension (a linear program).
 *
 * maximise t over the weights a in [-1, 1]^k and t <= 1 subject to y_c(a) = sum_k a_k Y(c, k) >= t for every
 * cable row c. The cables can be prestressed exactly when t* > 0 (any feasible a with all y_c > 0 can be
 * scaled into the box). Solved with COIN-OR Clp (dual simplex); the states are local, so Y is sparse.
 * @param[in] states self-stress states (rows of the contract order with coefficients; tension positive on
 * the distance equation |p2 - p1|^2 = L^2).
 * @param[in] numConstraints number of equations (size of the multipliers).
 * Two exact shortcuts come first. A cable that no state touches stays at 0 in every combination: not
 * prestressable (UntouchedCable). With more than @p localAboveStates states and @p J given, local states
 * around each cable are tried (findLocalCablePrestress): when they tension every cable, their sum is a
 * feasible point of the program, so the cables are prestressable (LocalStates; the prestress is that sum,
 * not the program's optimum). Otherwise the program decides. Below the threshold the program always decides,
 * so small models keep the program's vertex as their reported prestress.
 * @param[in] cableRows the rows of the taut cables' distance equations.
 * @param[in] J the constraint Jacobian the states belong to (optional: without it no local search).
 * @param[in] localAboveStates the local search runs only with more states than this.
 * @return The best pattern; feasible false when no combination tensions them all, or when @p cableRows is
 * empty.
 */
CablePrestress findCablePrestress(const std::vector<SelfStress>& states, int numConstraints,
                                  const std::vector<int>& cableRows, const SparseJacobian* J = nullptr,
                                  int localAboveStates = kLocalPrestressStates);

/**
 * @brief A cable prestress from local self-stresses alone, without a linear program.
 *
 * Around each cable not yet in tension, the equations within a growing number of layers of it (neighbours
 * share a coordinate) until their rows have a left null vector involving that cable: a self-stress of J
 * (the rows outside are 0). When it puts no cable in compression it is added; the sum then has every cable
 * in tension, a feasible point of findCablePrestress's program (every self-stress is a combination of any
 * basis), so the cables are prestressable. A braced cell's two diagonals and four sides are such a state.
 * @param[in] J the constraint Jacobian (rows as written).
 * @param[in] cableRows the rows of the taut cables' distance equations.
 * @return The multipliers y (dim J.rows(), y^T J = 0, largest |y| 1, every cable row > 0), or nothing when
 * some cable has no such local state (the structure may still be prestressable: ask the program).
 */
std::optional<Eigen::VectorXd> findLocalCablePrestress(const SparseJacobian& J,
                                                       const std::vector<int>& cableRows);

}  // namespace mobility_analysis
