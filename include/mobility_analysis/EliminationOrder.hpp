#pragma once

#include <vector>

#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"

namespace mobility_analysis {

/**
 * @brief An order of the equations and a pivot priority of the coordinates for a sparse elimination.
 *
 * Not the contract order: an order in which the elimination of the constraint Jacobian stays local, used to
 * find a basis of its left null space (the self-stresses), which does not depend on the order.
 */
struct EliminationOrder {
  std::vector<int> rows;            ///< Every equation once, in the order to take them (dim num_constraints).
  std::vector<int> columnPriority;  ///< Position of each coordinate in the sweep (dim num_coordinates).
  /// Whether each equation is one of a connection that closes a loop (joins a link to an earlier one that it
  /// does not attach to) rather than one of a link or of the connection attaching it (dim num_constraints).
  std::vector<char> closing;
};

/**
 * @brief Sweeps the mechanism from the ground over every connection with equations, tree or loop, by maximum
 *        cardinality search: the next link is the one with the most neighbours already swept.
 *
 * A link's rigid-link equations are taken when the sweep reaches it (the ground's boundary equations right
 * after its own), a connection's equations when the sweep has reached both its links, and coordinates are
 * preferred as pivots in the order their links are reached. The front of the sweep is then all the
 * elimination ever couples: a mast or ring is done in time linear in its length, a grid in its number of
 * cells times its width — whatever the URDF's joint tree, whose paths can be as long as the mechanism.
 *
 * Why this and not a fill-reducing order of the mechanism's graph (issue 13): SuiteSparse AMD's order of the
 * link graph, eliminated the same way (`mobility_benchmark --method orders`, bench/RESULTS.md), stores about
 * as much where the sweep holds (200 x 200 bar lattice 1.45 against 1.42 times J's entries, spatial SLE mast
 * and truss mast of 10^4 units 1.05 / 1.16 against 1.10 / 1.21, ring pantograph net 1.18 both) and more where
 * it is best (100 x 100 continuous-bar grid 1.06 against 0.74, braced lattice 2.6 against 1.3, 2.4 times the
 * time); where the sweep from the ground fills (a chain or a long ring: past 60 times J's entries) AMD stores
 * 1.3-1.8 times J's entries, which is what the leaves-first order the basis then takes stores as well
 * (computeSelfStressBasis). The sweep also keeps each stress as local as the loops (the attachment rule
 * below), which AMD's order does not aim at.
 * @param[in] mechanism the mechanism.
 * @param[in] model its natural-coordinate model.
 */
EliminationOrder computeSweepOrder(const Mechanism& mechanism, const CoordinateModel& model);

/**
 * @brief The same construction over the links in SuiteSparse AMD's approximate minimum degree order of the
 * link graph (links as vertices, every connection with equations as an edge).
 *
 * Where both the sweep from the ground and the spanning tree from its leaves fill (a long strip of a grid of
 * continuous bars: its few long bars are each pinned to every short one, so every link is within two of
 * every other and a front from anywhere is the whole strip), minimum degree takes the short bars first, each
 * coupling only the long bars it crosses: on a strip of 2 x 1 250 cells it stores 1.1 times J's entries
 * where the sweep from the ground stores 86 times (`mobility_benchmark --method orders`).
 */
EliminationOrder computeMinimumDegreeOrder(const Mechanism& mechanism, const CoordinateModel& model);

/**
 * @brief The same construction over another order of the links: each link's coordinates preferred as pivots
 *        and its rigid-link and boundary equations taken in the order of @p links, each connection's when
 *        both its links are reached. For measuring other orders against the sweep (bench: `--method orders`).
 * @param[in] links every link once.
 */
EliminationOrder computeOrderOfLinks(const Mechanism& mechanism, const CoordinateModel& model,
                                     const std::vector<int>& links);

}  // namespace mobility_analysis
