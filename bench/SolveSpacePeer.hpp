#pragma once

#include <string>

#include "mobility_analysis/Kinematics.hpp"
#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis::bench {

/// What SolveSpace's solver (libslvs) says about a planar bar-and-pin mechanism.
struct SolveSpaceResult {
  std::string status;  ///< "ok", "inconsistent", "didnt_converge", "too_many_unknowns" or "unsupported: …".
  int dof = -1;        ///< Slvs_System::dof.
  int failed = -1;     ///< Constraints reported as failing (redundant or inconsistent), if asked.
  int parameters = 0;  ///< Unknowns handed to the solver (2 per point).
  int constraints = 0;      ///< Constraints handed to the solver.
  double solveSeconds = 0;  ///< Wall time of Slvs_Solve alone.
};

/**
 * @brief Writes the mechanism as a SolveSpace sketch in the x–y workplane and solves it once.
 *
 * Each link becomes its joint points (2D points; a link with one joint point gets a second point 0.1 m away
 * in x) held at their distance (PT_PT_DISTANCE); each revolute joint a POINTS_COINCIDENT between its two
 * links' points; the ground's points are in a group that is not solved (fixed). Expressible: planar models
 * whose joints are revolute/continuous about z and whose links carry at most two distinct joint points
 * (chain, ring, bar lattice, four-bar); anything else returns status "unsupported: …".
 * @param[in] mechanism The loaded mechanism.
 * @param[in] poses Link poses at the written configuration.
 * @param[in] findFailed Ask the solver for the failing constraints (slow: about one solve per constraint).
 */
SolveSpaceResult solveWithSolveSpace(const Mechanism& mechanism, const LinkPoses& poses, bool findFailed);

}  // namespace mobility_analysis::bench
