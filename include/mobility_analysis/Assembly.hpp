#pragma once

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"

namespace mobility_analysis {

/// A model whose loops are closed, with the coordinates and link poses that close them.
struct AssembledMechanism {
  CoordinateModel model;      ///< Built at the assembled pose.
  Eigen::VectorXd q;          ///< Coordinates that satisfy Phi(q) = 0 (dim num_coordinates).
  LinkPoses poses;            ///< Link poses in the root frame.
  double initialResidual = 0.0;  ///< max |Phi| before assembly [m].
  double finalResidual = 0.0;    ///< max |Phi| after assembly [m].
  int iterations = 0;            ///< Newton iterations used.
};

/**
 * @brief Closes the loops from @p startPoses by Newton's method with least change, then builds the model there.
 *
 * Always in spatial coordinates (every joint equation holds in 3-D); the model for @p mode is built at the
 * result. Each step is the minimum-norm solution of \f$ \Phi_q \Delta q = -\Phi \f$ (damped, so redundant
 * equations are harmless when consistent).
 * @return The assembled mechanism, or a Diagnostic naming the loop element with the largest residual.
 */
Result<AssembledMechanism> assembleMechanism(const Mechanism& mechanism, const LinkPoses& startPoses,
                                             AnalysisMode mode);

}  // namespace mobility_analysis
