#pragma once

#include <algorithm>
#include <limits>

namespace mobility_analysis {

/**
 * @brief Every numerical threshold of the core, in one place.
 *
 * Lengths are divided by the mechanism's characteristic length (the RMS distance of its joint
 * points from their centroid) before any equation is built, so every tolerance below is
 * dimensionless and the same mechanism in millimetres and in metres gives the same answer.
 */
namespace tolerances {

/// Relative threshold of the ordered rank test [-]: an equation whose Jacobian row, reduced by the
/// rows before it, keeps less than this fraction of its own norm is redundant. Overridden by
/// `~rank_tolerance` / `--rank-tolerance`.
constexpr double kRank = 1e-8;

/// A rank decision whose margin (kept pivot / threshold or threshold / dropped residual) is
/// below this factor is reported as near the tolerance [-].
constexpr double kNearDecisionFactor = 100.0;

/// Loop closure residual accepted as closed [normalised length].
constexpr double kClosure = 1e-9;

/// The assembly closes the loops to this largest residual [normalised length / rad]; a model that
/// cannot reach it from its pose and from any restart cannot be closed.
constexpr double kAssemblyTarget = 1e-12;

/// A closure residual computed from coordinates far from the model's origin is rounded to about this many
/// eps times their largest magnitude: where that exceeds a target (a mechanism 10^4 Lc off its URDF's
/// origin), the target is that instead [-].
constexpr double kCoordinateRounding = 16.0;

/// @p target, or the rounding of coordinates of largest magnitude @p magnitude (kCoordinateRounding eps
/// times it) where that is larger: the smallest residual such coordinates can reach [same unit as both].
inline double reachableTarget(double target, double magnitude) {
  return std::max(target, kCoordinateRounding * std::numeric_limits<double>::epsilon() * magnitude);
}

/// Levenberg–Marquardt iterations of one closure attempt (from the pose or from one restart).
constexpr int kClosureMaxIterations = 200;

/// Continuation towards driven positions: the largest change of any joint per step [rad] or [Lc].
constexpr double kContinuationStep = 0.05;

/// Two directions of a body are independent when the sine of their angle exceeds this [-].
constexpr double kIndependentDirection = 1e-3;

/// A vector given in the URDF is zero when its norm is below this [-] (axis) or [m] (offsets).
constexpr double kZeroVector = 1e-12;

/// Axes are parallel (or a prismatic axis perpendicular) for the planar test when the sine
/// (cosine) of their angle is below this [-].
constexpr double kPlanarAxis = 1e-6;

/// Largest magnitude accepted for any length, position or joint value read from a model or given by a caller
/// [m] or [rad]: beyond it squares overflow or lose every digit of the mechanism's own size (a coordinate of
/// 1e155 makes the characteristic length inf). Input outside |x| <= kMaxCoordinate is refused where it enters.
constexpr double kMaxCoordinate = 1e12;

/// Largest ratio of any length of a model (joint offset, anchor, cable length) to its typical length (the
/// median of its nonzero lengths, io/LengthRange.hpp) [-]. A four-bar with one link welded 1e9 times its size
/// away gave DOF 3 instead of 1 (its rank decisions lost the four-bar); 1e6 keeps a factor 1000 from there.
constexpr double kMaxRelativeLength = 1e6;

/// Largest driven prismatic value, as a multiple of the characteristic length at the start [-]: the
/// continuation moves every joint by at most kContinuationStep per step, so 1e3 takes about 2e4 steps when the
/// other joints move with the driven one (the continuation gives up after 1e5); 1e5 Lc ran out of steps and was
/// reported as stopped at a dead point.
constexpr double kMaxDrivenTravel = 1e3;

/// A passive cable is taut when |distance - length| is below this fraction of its length [-].
constexpr double kCableTaut = 1e-6;

/// Pivot acceptance in the sparse ordered elimination: any entry at least this fraction of the
/// largest entry of the reduced row may be the pivot (threshold partial pivoting) [-].
constexpr double kPivotThreshold = 0.1;

}  // namespace tolerances
}  // namespace mobility_analysis
