#pragma once

#include <vector>

#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"
#include "mobility_analysis/RedundancyAnalysis.hpp"

namespace mobility_analysis {

/**
 * @brief Redundant links (DESIGN.md §3) read off the self-stresses, without removing anything.
 *
 * Removing link l takes away its lambda freedoms, its rigid-link equations and the k_l equations of its
 * connections. The self-stresses that survive are exactly those zero on those k_l equations, so the
 * redundancy drops by rho_l = rank(Y_l), Y_l being the rows of the stress basis at l's connection equations,
 * and the DOF changes by k_l - rho_l - lambda. Hence l is redundant iff rho_l = k_l - lambda > 0: one small
 * rank per link.
 * @param[in] mechanism the mechanism (the root link is never redundant: it carries the boundary).
 * @param[in] model its natural-coordinate model.
 * @param[in] stresses a basis of the self-stresses.
 * @param[in] tolerance relative rank threshold for rank(Y_l).
 * @return Per link, whether it is redundant (dim links).
 */
std::vector<bool> findRedundantLinks(const Mechanism& mechanism, const CoordinateModel& model,
                                     const std::vector<SelfStress>& stresses, double tolerance);

/**
 * @brief Every link and connection that takes part in some self-stress: the members of the over-constrained
 * loops.
 *
 * The union of the supports of a basis is the union over the whole left null space, so any basis gives the
 * same.
 * @param[out] linkInLoop per link (dim links).
 * @param[out] jointInLoop per connection (dim joints).
 */
void findOverConstrainedLoops(const Mechanism& mechanism, const CoordinateModel& model,
                              const std::vector<SelfStress>& stresses, std::vector<bool>& linkInLoop,
                              std::vector<bool>& jointInLoop);

}  // namespace mobility_analysis
