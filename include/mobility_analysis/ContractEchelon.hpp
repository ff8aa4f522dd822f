#pragma once

#include <optional>
#include <vector>

#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"
#include "mobility_analysis/SparseElimination.hpp"

namespace mobility_analysis {

/// What findContractEchelon did, for benchmarks and tests.
struct ContractEchelonStats {
  int fromBasis = 0;     ///< Stresses of the given basis kept (their last equation was their own).
  int fromPatches = 0;   ///< Stresses found by the eliminations over patches.
  int patches = 0;       ///< Patches eliminated.
  size_t patchRows = 0;  ///< Equations over all the patches eliminated.
  int radius = 0;        ///< Link radius of the last round of patches.
};

/**
 * @brief A basis of the self-stresses in which each stress has a last equation of its own in contract order,
 * found locally: the ordered redundancy is then read off it without fill.
 *
 * Equation r depends on the equations before it exactly when some self-stress has r as its last equation,
 * so k stresses with k different last equations prove those k equations redundant; when k is the number of
 * self-stresses (num_constraints − rank), no other equation can be, and the stresses are a basis (each is
 * independent of those with earlier last equations). The stresses of @p basis whose last equation is their
 * own are kept; the others are found by eliminating, in contract order, the equations of patches of links
 * (balls of a few links around seeds that cover the mechanism): an equation dependent on the patch's earlier
 * equations is dependent on all the earlier ones, and its dependency, traced inside the patch, is as local
 * as the patch.
 *
 * Why: the sweep's stresses are local in the sweep's order, and in contract order many share a last
 * equation; reducing them to echelon form then fills (on a lattice of bars braced by cables the stresses
 * combine along whole rows of cells). A stress local in contract order needs no reduction.
 * @param[in] mechanism the mechanism (its links and connections make the patches).
 * @param[in] model its natural-coordinate model.
 * @param[in] J the constraint Jacobian, rows in contract order.
 * @param[in] basis a basis of the self-stresses (coefficients of the rows scaled to unit norm).
 * @param[in] tolerance relative rank threshold (as the elimination that found @p basis).
 * @param[out] stats what was done; may be null.
 * @return One stress per redundant equation, each scaled to unit largest coefficient, with distinct last
 * equations; nothing when the patches did not prove as many equations redundant as @p basis has stresses
 * (a stress as large as the mechanism: a ring's).
 */
std::optional<std::vector<SelfStress>> findContractEchelon(
    const Mechanism& mechanism, const CoordinateModel& model, const SparseJacobian& J,
    const std::vector<SelfStress>& basis, double tolerance, ContractEchelonStats* stats = nullptr);

}  // namespace mobility_analysis
