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
 * @param[in] mechanism the mechanism.
 * @param[in] model its natural-coordinate model.
 */
EliminationOrder computeSweepOrder(const Mechanism& mechanism, const CoordinateModel& model);

}  // namespace mobility_analysis
