#include "mobility_analysis/RedundantLinks.hpp"

#include <algorithm>
#include <numeric>

namespace mobility_analysis {

std::vector<bool> findRedundantLinks(const Mechanism& mechanism, const CoordinateModel& model,
                                     const std::vector<SelfStress>& stresses, double tolerance) {
  const int numLinks = static_cast<int>(mechanism.links.size());
  std::vector<bool> redundant(numLinks, false);
  if (stresses.empty())
    return redundant;

  // The basis by equation: which stresses each connection equation takes part in.
  std::vector<std::vector<std::pair<int, double>>> stressesOfRow(model.numConstraints());
  for (int s = 0; s < static_cast<int>(stresses.size()); ++s) {
    for (const auto& [row, value] : stresses[s]) {
      if (model.equations[row].source == EquationSource::Joint)
        stressesOfRow[row].emplace_back(s, value);
    }
  }
  std::vector<std::vector<int>> rowsOfLink(numLinks);
  for (int r = 0; r < model.numConstraints(); ++r) {
    const ConstraintEquation& eq = model.equations[r];
    if (eq.source != EquationSource::Joint)
      continue;
    const Joint& joint = mechanism.joints[eq.element];
    rowsOfLink[joint.link1].push_back(r);
    if (joint.link2 != joint.link1)
      rowsOfLink[joint.link2].push_back(r);
  }

  std::vector<int> columnOf(stresses.size(), -1), columns;
  for (int l = 0; l < numLinks; ++l) {
    const int k = static_cast<int>(rowsOfLink[l].size());
    if (l == mechanism.rootLink || k <= model.lambda)
      continue;
    columns.clear();
    for (int r : rowsOfLink[l]) {
      for (const auto& entry : stressesOfRow[r]) {
        if (columnOf[entry.first] < 0) {
          columnOf[entry.first] = static_cast<int>(columns.size());
          columns.push_back(entry.first);
        }
      }
    }
    const int needed = k - model.lambda;
    if (static_cast<int>(columns.size()) >= needed) {
      // rank(Y_l) by the sparse elimination, its rows (each scaled to unit norm, which leaves the rank alone)
      // taken sparsest first: a connection that every stress of the link shares (the first hinge of a door)
      // comes last and is reduced by the few-entry rows, instead of filling each of them.
      std::vector<Eigen::Triplet<double>> triplets;
      for (int i = 0; i < k; ++i) {
        for (const auto& [stress, value] : stressesOfRow[rowsOfLink[l][i]]) {
          triplets.emplace_back(i, columnOf[stress], value);
        }
      }
      SparseJacobian Yl(k, static_cast<int>(columns.size()));
      Yl.setFromTriplets(triplets.begin(), triplets.end());
      EliminationOptions options;
      options.rowOrder.resize(k);
      std::iota(options.rowOrder.begin(), options.rowOrder.end(), 0);
      std::stable_sort(options.rowOrder.begin(), options.rowOrder.end(),
                       [&](int a, int b) { return Yl.row(a).nonZeros() < Yl.row(b).nonZeros(); });
      options.stopAtFullRank = true;
      redundant[l] = computeSparseElimination(Yl, tolerance, options).rank == needed;
    }
    for (int s : columns)
      columnOf[s] = -1;
  }
  return redundant;
}

void findOverConstrainedLoops(const Mechanism& mechanism, const CoordinateModel& model,
                              const std::vector<SelfStress>& stresses, std::vector<bool>& linkInLoop,
                              std::vector<bool>& jointInLoop) {
  linkInLoop.assign(mechanism.links.size(), false);
  jointInLoop.assign(mechanism.joints.size(), false);
  for (const SelfStress& stress : stresses) {
    for (const auto& entry : stress) {
      const ConstraintEquation& eq = model.equations[entry.first];
      if (eq.source == EquationSource::Joint) {
        jointInLoop[eq.element] = true;
        linkInLoop[mechanism.joints[eq.element].link1] = true;
        linkInLoop[mechanism.joints[eq.element].link2] = true;
      } else {
        linkInLoop[eq.element] = true;
      }
    }
  }
}

}  // namespace mobility_analysis
