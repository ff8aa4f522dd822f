#pragma once

#include <string>
#include <vector>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/Kinematics.hpp"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

/// How followDrivenPositions steps.
struct DrivenMotionSettings {
  /// Largest change of any joint per continuation step [rad] or [Lc].
  double maxStep = tolerances::kContinuationStep;
  /// Characteristic length Lc [m]; <= 0: computeCharacteristicLength at the start poses.
  double lengthScale = -1.0;
  /// Values the start's revolute angles are unwrapped towards (the previous call's `positions`, so a
  /// continuous joint followed through several calls keeps counting turns); may be empty.
  JointPositions reference;
  /// Look for branch and dead points (singular values of the Jacobian at every step); only for models with
  /// at most this many tree unknowns (0: never).
  int eventSearchLimit = 120;
};

/// Where a driven motion ended up.
struct DrivenMotion {
  LinkPoses poses;           ///< Every link in the root frame, loops closed.
  JointPositions positions;  ///< Every 1-DOF tree joint: driven ones exactly as asked, others unwrapped
                             ///< continuously along the motion.
  double residual = 0.0;     ///< max loop residual at the end [Lc or rad].
  int steps = 0;             ///< Continuation steps accepted.
  int iterations = 0;        ///< Levenberg–Marquardt iterations (closing the start included).
  std::vector<std::string> events;  ///< Branch or dead points met, one readable line each.
};

/**
 * @brief Moves a mechanism from @p start to the driven joint values @p targets, holding them exactly, and
 *        finds the other joints by continuation on the start's assembly mode.
 *
 * The driven joints are driving constraints: their values are not unknowns but are set, step by step, on the
 * straight line from their start values (the representative nearest each target, so a revolute never turns
 * the long way) to the targets. Each step predicts the other joints along the tangent of the solution curve
 * (the least-change solution of \f$ J_{free} \dot x = -J_{driven} \dot\theta \f$) and corrects by
 * Levenberg–Marquardt with the driven joints held; a step whose correction is not small beside the step (a
 * jump to another assembly mode) or that does not converge is halved. Loops open at @p start are closed
 * first (closeLoops). Use it repeatedly to follow a motion: pass the previous call's poses as @p start and
 * its positions as `settings.reference`.
 * @param[in] mechanism the mechanism.
 * @param[in] start link poses to start from (the written pose, or the previous state).
 * @param[in] targets driven values by tree-joint name [rad] or [m]; revolute, continuous or prismatic joints.
 * @return The motion's end, or a Diagnostic: the joint, the requested value and the last value reached when
 *         the target lies beyond a dead point of that assembly mode (or the driven joints contradict each
 * other).
 */
Result<DrivenMotion> followDrivenPositions(const Mechanism& mechanism, const LinkPoses& start,
                                           const JointPositions& targets,
                                           const DrivenMotionSettings& settings = {});

}  // namespace mobility_analysis
