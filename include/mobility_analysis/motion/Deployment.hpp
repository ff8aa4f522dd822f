#pragma once

#include <functional>
#include <optional>
#include <string>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/MobilityAnalysis.hpp"
#include "mobility_analysis/MobilityReport.hpp"

namespace mobility_analysis {

/// What to deploy and how.
struct DeploymentOptions {
  std::string cable;  ///< The active cable that drives (it is shortened).
  int steps = 100;    ///< Equal steps from its current length to targetLength.
  std::optional<double>
      targetLength;        ///< [m]; empty: 0 (the continuation stops earlier, when a cable goes taut).
  int recordedJoints = 4;  ///< Tree joints whose values each step records (first in document order).
  /// Mode, tolerance, start pose (positions / startPoses). With lockActiveCables the final report locks the
  /// active cables at their final lengths (the lecture: "at the end of deployment the actuator is locked").
  AnalysisOptions analysis;
  /// Called after each step with the step and the link poses there (the node animates with it); may be empty.
  std::function<void(const DeploymentStep&, const LinkPoses&)> onStep;
};

/**
 * @brief Deploys @p mechanism by shortening an active cable until the first passive cable goes taut.
 *
 * The cable becomes a driven distance \f$ |p_2 - p_1|^2 = L(s)^2 \f$ added to the natural-coordinate
 * equations (all other cables ignored), and L is stepped from its assembled length towards the target; each
 * step is predicted by the secant of the last two and corrected by damped Newton (minimum-norm steps, so
 * consistent redundant equations are harmless). After each step every passive cable's gap (length −
 * distance) is checked; when one turns negative the length where the first one reaches zero is located by
 * regula falsi (Illinois) between the last two steps, to a relative gap in [0, 1e-9]. The final pose is then
 * analysed as usual, so the passive cables that went taut count as constraints there.
 * @return The final analysis with report.deployment filled, or a Diagnostic (unknown or passive cable, no
 * assembly at the start).
 */
Result<MobilityAnalysis> deployMechanism(const Mechanism& mechanism, const DeploymentOptions& options);

}  // namespace mobility_analysis
