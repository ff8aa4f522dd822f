#pragma once

/// The definitions as written, computed the slow way, for tests to hold the fast methods against.

#include <vector>

#include "mobility_analysis/mobility_analysis.hpp"

namespace mobility_analysis {

/// The Jacobian without @p link: its coordinates, its rigid-link equations and the equations of its
/// connections.
inline SparseJacobian removeLinkFromJacobian(const Mechanism& mechanism, const CoordinateModel& model,
                                             const SparseJacobian& J, int link) {
  std::vector<int> columnMap(model.numCoordinates(), 0);
  for (int e : model.bodyElements[link]) {
    for (int i = 0; i < model.dim; ++i)
      columnMap[model.elements[e].offset + i] = -1;
  }
  int columns = 0;
  for (int& c : columnMap)
    c = c < 0 ? -1 : columns++;
  std::vector<Eigen::Triplet<double>> triplets;
  int rows = 0;
  for (int r = 0; r < J.rows(); ++r) {
    const ConstraintEquation& eq = model.equations[r];
    const bool removed = ((eq.source == EquationSource::Link || eq.source == EquationSource::Boundary) &&
                          eq.element == link) ||
                         (eq.source == EquationSource::Joint && (mechanism.joints[eq.element].link1 == link ||
                                                                 mechanism.joints[eq.element].link2 == link));
    if (removed)
      continue;
    for (SparseJacobian::InnerIterator it(J, r); it; ++it) {
      if (columnMap[it.col()] >= 0)
        triplets.emplace_back(rows, columnMap[it.col()], it.value());
    }
    ++rows;
  }
  SparseJacobian reduced(rows, columns);
  reduced.setFromTriplets(triplets.begin(), triplets.end());
  return reduced;
}

/// DESIGN.md §3 as written: remove each non-root link with its connections, re-count DOF and redundancy.
inline std::vector<bool> findRedundantLinksByRemoval(const Mechanism& mechanism, const CoordinateModel& model,
                                                     const SparseJacobian& J, double tolerance) {
  const OrderedRank full = computeOrderedRank(J, tolerance, false);
  const int redundant = static_cast<int>(J.rows()) - full.rank;
  std::vector<bool> result(mechanism.links.size(), false);
  for (int l = 0; l < static_cast<int>(mechanism.links.size()); ++l) {
    if (l == mechanism.rootLink)
      continue;
    const SparseJacobian reduced = removeLinkFromJacobian(mechanism, model, J, l);
    const OrderedRank without = computeOrderedRank(reduced, tolerance, false);
    result[l] = without.dof() == full.dof() && static_cast<int>(reduced.rows()) - without.rank < redundant;
  }
  return result;
}

}  // namespace mobility_analysis
