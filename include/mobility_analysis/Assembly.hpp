#pragma once

#include <string>
#include <vector>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"

namespace mobility_analysis {

/// A model whose loops are closed, with the coordinates and link poses that close them.
struct AssembledMechanism {
  CoordinateModel model;            ///< Built at the assembled pose.
  Eigen::VectorXd q;                ///< Coordinates that satisfy Phi(q) = 0 (dim num_coordinates).
  LinkPoses poses;                  ///< Link poses in the root frame.
  double initialResidual = 0.0;     ///< Largest loop residual before assembly [m] (angles times Lc).
  double finalResidual = 0.0;       ///< max |Phi| of the analysis model after assembly [m].
  int iterations = 0;               ///< Levenberg–Marquardt iterations, restarts and continuation included.
  int restarts = 0;                 ///< Restarts the closure needed (0: closed from the start pose).
  int steps = 0;                    ///< Continuation steps towards driven positions (0 without).
  JointPositions positions;         ///< Every 1-DOF tree joint's value; driven ones exactly as asked.
  std::vector<std::string> events;  ///< Branch or dead points met on the way to driven positions.
};

/**
 * @brief Closes the loops from @p startPoses (holding @p driven joints at their values, reached by
 *        continuation), then builds the model for @p mode there.
 *
 * The closure works in tree coordinates (motion/LoopClosure.hpp): the tree joints hold by construction, the
 * loop-closing connections are residuals written as differences of frames (so a revolute or weld cannot close
 * on an axis turned by 180°), and a Levenberg–Marquardt solver with restarts brings them to
 * tolerances::kAssemblyTarget (normalised; far from the model's origin, the rounding of its coordinates:
 * ClosureLayout::target). With @p driven values, followDrivenPositions
 * (motion/DrivenAssembly.hpp) moves the mechanism there on the start's assembly mode. The analysis model is
 * then built at the closed poses and checked.
 * @param[in] startPoses the written pose or the previous state; distance constraints take their lengths here.
 * @param[in] driven driven tree-joint values [rad] or [m]; empty: close from the start pose only.
 * @param[in] sideThread whether a large model's joint values may be read off its poses on a second thread
 *            while the model is built (the same values either way: AnalysisOptions::sideThreads).
 * @return The assembled mechanism, or a Diagnostic naming the loop element (residual and pose reached) or the
 *         driven joint that cannot reach its value.
 */
Result<AssembledMechanism> assembleMechanism(const Mechanism& mechanism, const LinkPoses& startPoses,
                                             AnalysisMode mode, const JointPositions& driven = {},
                                             bool sideThread = false);

/**
 * @brief assembleMechanism from the written pose (every tree joint at 0: computeTreePoses with no values),
 *        nothing driven.
 *
 * Where the loops close there already (a tree, a lattice written closed), nothing moves: the poses are the
 * written pose's as computed, and every revolute, continuous and prismatic tree joint's value is exactly 0
 * (writtenJointPositions), not read back off the poses, which gives rounding (-5.6e-17 rad).
 */
Result<AssembledMechanism> assembleMechanism(const Mechanism& mechanism, AnalysisMode mode,
                                             bool sideThread = false);

}  // namespace mobility_analysis
