#pragma once

#include <string>

#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"
#include "mobility_analysis/SparseElimination.hpp"

namespace mobility_analysis {

/**
 * @brief Issue 13, item 2: the fill and time of eliminating the constraint Jacobian's rows in the sweep's
 * order against orders from a fill-reducing method on the mechanism's graph (SuiteSparse AMD of the link
 *        graph) and the contract order, each with the same incremental elimination the self-stress basis
 * uses.
 *
 * Prints one line per order: `method=orders order=NAME ... stored=ENTRIES stored_per_nnz=X seconds=S
 * status=ok|over_budget` (an order gives up past 60 times J's entries plus 2 10^6).
 * @return 0.
 */
int printEliminationOrders(const Mechanism& mechanism, const CoordinateModel& model, const SparseJacobian& J,
                           const std::string& file);

}  // namespace mobility_analysis
