#pragma once

#include <functional>
#include <optional>
#include <string>

#include "mobility_analysis/Assembly.hpp"
#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/MobilityReport.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"
#include "mobility_analysis/RedundancyAnalysis.hpp"

namespace mobility_analysis {

/// Options of one analysis.
struct AnalysisOptions {
  AnalysisMode mode = AnalysisMode::Auto;
  /// Driven tree-joint values [rad] or [m], held exactly; the other joints follow by continuation from the
  /// start on its assembly mode (followDrivenPositions). Empty: the start pose, closed.
  JointPositions positions;
  /// Where the assembly starts (the previous state when following a motion); empty: the written pose.
  std::optional<LinkPoses> startPoses;
  double rankTolerance = -1.0;  ///< Relative rank threshold; <= 0: tolerances::kRank.
  /// Analyse every active cable as locked: a taut cable of the length it has at the assembled pose (the
  /// deployed mast with its actuator locked), instead of ignoring it as the driver.
  bool lockActiveCables = false;
  /// Large models (from 2 10^4 equations) run the passive-freedom search and the self-stress report on a second
  /// thread beside the phases they do not feed; false keeps the whole analysis on the caller's thread. The
  /// answer is the same to the bit either way.
  bool sideThreads = true;
  /// Called with a phase name and a fraction in [0, 1] during long analyses; may be empty.
  std::function<void(const std::string&, double)> progress;
};

/// The whole answer for one mechanism: the report plus what the ROS layer draws.
struct MobilityAnalysis {
  MobilityReport report;
  AssembledMechanism assembled;
};

/**
 * @brief Assembles @p mechanism, builds its natural coordinates, and answers DOF, Grübler and redundancy.
 *
 * The one path shared by the CLI and the services.
 * @return The analysis, or the Diagnostic of the first thing that went wrong.
 */
Result<MobilityAnalysis> analyzeMechanism(const Mechanism& mechanism, const AnalysisOptions& options);

/**
 * @brief Grübler–Kutzbach count, eq. (1) of the lecture: lambda (N - J - 1) + sum F_i, with each connection's
 *        freedom in the model's mode (a distance constraint or taut cable counts as one equation; ignored
 *        cables count as nothing).
 */
int computeGrublerKutzbach(const Mechanism& mechanism, const CoordinateModel& model);

}  // namespace mobility_analysis
