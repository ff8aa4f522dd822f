#pragma once

#include <functional>
#include <optional>
#include <vector>

#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/EliminationOrder.hpp"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"
#include "mobility_analysis/RedundancyAnalysis.hpp"
#include "mobility_analysis/SparseElimination.hpp"

namespace mobility_analysis {

/// A set of stresses reduced to echelon form on their last equations in contract order
/// (computeOrderedRankFromStresses): the pivots are the redundant equations.
struct StressEchelon {
  std::vector<char> pivot;  ///< Per equation: a pivot of the reduction (the equation is redundant).
  int rank = 0;
  double smallestKeptPivot = 0.0;
  double largestDroppedResidual = 0.0;
  double tolerance = 0.0;  ///< The threshold it was made with.
};

/// The order of the links the sweep's elimination took (computeSelfStressBasis tries them in this order).
enum class SweepOrderKind {
  FromTheGround,  ///< computeSweepOrder (also its unlimited run, when the others fill as well)
  FromTheLeaves,  ///< its spanning tree from the leaves, the closing connections after it
  MinimumDegree,  ///< computeMinimumDegreeOrder
};

/**
 * @brief A basis of the left null space of the constraint Jacobian: its self-stresses.
 *
 * Every redundancy of a mechanism is one self-stress, \f$ y^T \Phi_q = 0 \f$ (constraint forces in
 * equilibrium with nothing applied), so num_constraints − rank of them span the space. A sparse basis is
 * found once, by an elimination in an order where it stays local (computeSweepOrder), and every ordered
 * question is then answered from it.
 */
struct SelfStressBasis {
  /// The basis; stress k is the one the sweep revealed at its last equation, with coefficient 1 there.
  std::vector<SelfStress> stresses;
  int numConstraints = 0;
  int numCoordinates = 0;
  int rank = 0;                         ///< Rank of the Jacobian.
  double smallestKeptPivot = 0.0;       ///< Of the sweep's elimination (see OrderedRank) [-].
  double largestDroppedResidual = 0.0;  ///< Likewise [-].
  int locallyResolved = 0;              ///< Stresses found by a local elimination around their equation.
  SweepOrderKind sweptBy = SweepOrderKind::FromTheGround;  ///< The order the elimination took.
  /// Entries the elimination kept (its pivot rows and their multipliers): its fill, against J's nonzeros.
  size_t storedEntries = 0;
  /// A basis of the first-order motions (right null space of J, dim num_coordinates each) from the same
  /// elimination; empty with motionsComputed false when there were more than kMaxMotions.
  std::vector<Eigen::VectorXd> motions;
  bool motionsComputed = false;
  /// The same space again, each stress with a last equation of its own in contract order (findContractEchelon),
  /// when the sweep's stresses would fill their reduction to that form; else empty. The ordered redundancy
  /// is read off it (computeOrderedRankFromStresses).
  std::vector<SelfStress> contractEchelon;
  /// The reduction of `stresses` to echelon form, where computeSelfStressBasis already made it to decide
  /// whether contractEchelon is needed (computeOrderedRankFromStresses then reads it instead of reducing
  /// again, at the same tolerance); else empty. Whoever changes `stresses` afterwards must reset it.
  std::optional<StressEchelon> echelon;
  /// The most first-order motions the second-order test forms its quadratic forms for (d (d + 1) / 2
  /// entries each, FiniteMobility.hpp), and so the most the sweep computes: past it nothing reads them, and
  /// they cost d dense vectors of num_coordinates (a pin-jointed bar lattice of 100 x 100 cells, d = 199:
  /// 190 MB, and a quarter of its report's instructions).
  static constexpr size_t kMaxMotions = 64;
};

/// Progress of a long computation: a fraction in [0, 1]; may be empty.
using ProgressCallback = std::function<void(double)>;

/**
 * @brief Finds a sparse basis of the self-stresses by one elimination of @p J in sweep order.
 *
 * Each equation the sweep finds dependent on those before it reveals one stress: the unique one over that
 * equation and independent equations before it. That one is local when the loop the equation closes is short,
 * but where loops share a closing connection it runs back along the whole chain of loops; such a stress is
 * replaced by one found by the same elimination restricted to the links around the equation (a ball of
 * growing radius), which is as local as the mechanism's own loops and has the same last equation, so the
 * basis stays a basis. Where a ball of links is the whole mechanism at once (links through many joints: a grid
 * of continuous bars, every bar pinned to every crossing one) the ball is taken in space instead: the rows
 * acting within a growing radius of the equation's place (joint rows at their points, a point's rigid-link
 * combination at the point) and the rows acting on the links they reach as a whole. The sweep runs from the
 * ground; where it fills past a budget (a long ring, whose arcs
 * fill like chains swept from their root) the spanning tree of the sweep is taken from its leaves instead and
 * the loop-closing connections after it, and a tree is always taken from its leaves. Where the stresses
 * found share last equations in contract order and their reduction to echelon form there would fill (a
 * lattice braced by cables), the basis also carries stresses local in contract order (findContractEchelon).
 * @param[in] mechanism the mechanism.
 * @param[in] model its natural-coordinate model.
 * @param[in] J the constraint Jacobian at the assembled pose (rows in contract order; the basis uses these
 * rows).
 * @param[in] tolerance relative rank threshold.
 * @param[in] progress called with the fraction of equations swept.
 * @param[in] fillBudget entries the sweep from the ground may store before it is abandoned for the
 * leaves-first order (0: 8 times the entries of the rows it has taken so far, plus 10^6; tests pass 1 to take
 * the leaves-first order).
 * @param[in] sideThread whether a large model's local stresses may be found ahead on a second thread while
 * the sweep eliminates; the basis is the same to the bit either way.
 */
SelfStressBasis computeSelfStressBasis(const Mechanism& mechanism, const CoordinateModel& model,
                                       const SparseJacobian& J, double tolerance,
                                       const ProgressCallback& progress = {}, size_t fillBudget = 0,
                                       bool sideThread = false);

/**
 * @brief computeSelfStressBasis in its two steps: the sweep's basis (stresses scaled to unit largest
 *        coefficient, rank, margins, motions), then reduceToContractOrder.
 *
 * Why two: what reads only the stresses (the self-stress report) can start on another thread after the
 * first, as reduceToContractOrder writes no member but `echelon` and `contractEchelon`.
 */
SelfStressBasis sweepSelfStressBasis(const Mechanism& mechanism, const CoordinateModel& model,
                                     const SparseJacobian& J, double tolerance, const ProgressCallback& progress,
                                     size_t fillBudget, bool sideThread);

/// The second step of computeSelfStressBasis: `basis.echelon` where the sweep's stresses reduce to contract
/// order within budget, else `basis.contractEchelon` (findContractEchelon) where it is found; writes no other
/// member.
void reduceToContractOrder(const Mechanism& mechanism, const CoordinateModel& model, const SparseJacobian& J,
                           double tolerance, SelfStressBasis& basis);

/**
 * @brief The lecture's ordered rank test read off a self-stress basis, without eliminating in contract order.
 *
 * Equation r depends on the equations before it exactly when some self-stress has r as its last equation
 * (\f$ J_r = -\sum_{i<r} y_i J_i / y_r \f$). So the redundant equations are the pivots of the basis reduced
 * to echelon form on each vector's last equation: the rows of the basis matrix Y taken from the last equation
 * up, each one kept when it is independent of the rows after it. Y has one column per redundancy and is as
 * local as the stresses, so this costs little next to finding the basis. Where the basis carries its
 * contract-order echelon (SelfStressBasis::contractEchelon: each stress with a last equation of its own) that
 * is reduced instead: every row then reduces against unit pivots, without fill.
 * @param[in] basis the self-stresses of the Jacobian (any basis gives the same answer).
 * @param[in] tolerance threshold for a row of Y (stresses scaled to unit largest coefficient) to be
 * independent of the rows after it.
 * @param[in] limited give up when the reduction fills past the budget computeSelfStressBasis holds its own
 * reduction to (a reduction computeSelfStressBasis made is read as it is).
 * @return The ordered rank in contract order (no dependencies), or nothing when the reduction found fewer
 *         pivots than the basis has stresses (a numerically ambiguous basis) or, @p limited, passed its
 *         budget: use computeOrderedRank.
 */
std::optional<OrderedRank> computeOrderedRankFromStresses(const SelfStressBasis& basis, double tolerance,
                                                          bool limited = false);

}  // namespace mobility_analysis
