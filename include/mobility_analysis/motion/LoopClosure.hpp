#pragma once

#include <vector>

#include <Eigen/Core>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/motion/TreeCoordinates.hpp"

namespace mobility_analysis {

/**
 * @brief The damped least-squares step \f$ -(J^T J + \mu I)^{-1} J^T r \f$, in the smaller of its two
 *        equivalent forms (\f$ -J^T (J J^T + \mu I)^{-1} r \f$ when J has fewer rows than columns).
 * @return false when the factorisation fails (the caller raises \f$ \mu \f$).
 */
bool solveDampedLeastSquares(const Eigen::SparseMatrix<double>& J, const Eigen::VectorXd& r, double mu,
                             Eigen::VectorXd& step);

/// What one Levenberg–Marquardt run on the loop residual did.
struct ClosureSolve {
  int iterations = 0;
  double residual = 0.0;   ///< max |residual| at the end [Lc or rad].
  bool converged = false;  ///< residual <= the layout's target (ClosureLayout::target).
  LinkPoses poses;         ///< The end point's poses (posesOf the configuration).
};

/**
 * @brief Levenberg–Marquardt on the loop residual over the kept unknowns, from @p configuration.
 *
 * Each step is \f$ \delta = -(J^T J + \mu I)^{-1} J^T r \f$ (computed in whichever of the two equivalent
 * forms is smaller), with a trust radius of 1 rad / 1 Lc and Nielsen's update of \f$ \mu \f$ from the gain
 * ratio; consistent redundant equations (over-constrained loops) are harmless. Stops at the target, at a
 * stationary point, or after @p maxIterations.
 * @param[in,out] configuration start, then the end point.
 * @param[in,out] change if not null, the increments taken are added to it (dim numColumns).
 */
ClosureSolve solveClosure(const Mechanism& mechanism, const ClosureLayout& layout,
                          const std::vector<int>& columns, int numColumns, TreeConfiguration& configuration,
                          int maxIterations, Eigen::VectorXd* change = nullptr);

/// A configuration whose loops close.
struct ClosedConfiguration {
  TreeConfiguration configuration;
  LinkPoses poses;
  double residual = 0.0;  ///< max |residual| [Lc or rad].
  int iterations = 0;     ///< Levenberg–Marquardt iterations, restarts included.
  int restarts = 0;       ///< Restarts needed (0: closed from the start).
};

/**
 * @brief Closes the loops from @p start, holding the unknowns whose column is -1.
 *
 * Globalised: Levenberg–Marquardt from the start; if it stalls (a straight four-bar's start is a stationary
 * point of the residual: every joint moves the loop's end across the line, none along it), restarts from
 * deterministic perturbations of growing size (0.1 to 2 rad, 0.1 to 2 Lc) and keeps, of the first size that
 * closes, the solution that changed the start least.
 * @return The closed configuration, or a Diagnostic naming the loop element with the largest residual, the
 *         residual [m] and the joint values reached, in one line.
 */
Result<ClosedConfiguration> closeLoops(const Mechanism& mechanism, const ClosureLayout& layout,
                                       const TreeConfiguration& start, const std::vector<int>& columns,
                                       int numColumns);

}  // namespace mobility_analysis
