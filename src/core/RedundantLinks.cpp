#include "mobility_analysis/RedundantLinks.hpp"

#include <algorithm>

#include "Buckets.hpp"
#include "LocalRows.hpp"
#include "StressMatrix.hpp"

namespace mobility_analysis {

namespace {

/// The connection equations of each link, in contract order (pooled: a vector per link cost a braced
/// lattice's report more than the eliminations).
core_detail::Buckets connectionRowsOfLinks(const Mechanism& mechanism, const CoordinateModel& model) {
  core_detail::Buckets rowsOfLink(static_cast<int>(mechanism.links.size()));
  for (int pass = 0; pass < 2; ++pass) {
    for (int r = 0; r < model.numConstraints(); ++r) {
      const ConstraintEquation& eq = model.equations[r];
      if (eq.source != EquationSource::Joint)
        continue;
      const Joint& joint = mechanism.joints[eq.element];
      const int ends = joint.link2 != joint.link1 ? 2 : 1;  // a link joined to itself lists the row once
      for (int end = 0; end < ends; ++end) {
        const int link = end == 0 ? joint.link1 : joint.link2;
        if (pass == 0)
          rowsOfLink.count(link);
        else
          rowsOfLink.add(link, r);
      }
    }
    if (pass == 0)
      rowsOfLink.allocate();
  }
  return rowsOfLink;
}

}  // namespace

std::vector<bool> findRedundantLinks(const Mechanism& mechanism, const CoordinateModel& model,
                                     const std::vector<SelfStress>& stresses, double tolerance) {
  const int numLinks = static_cast<int>(mechanism.links.size());
  std::vector<bool> redundant(numLinks, false);
  if (stresses.empty())
    return redundant;

  // The stresses by connection equation: Y(r, s) = stress s at joint row r.
  const SparseJacobian Y = core_detail::stressMatrix(stresses, model.numConstraints(), [&](int row) {
    return model.equations[static_cast<size_t>(row)].source == EquationSource::Joint;
  });
  const core_detail::Buckets rowsOfLink = connectionRowsOfLinks(mechanism, model);
  auto stressesAt = [&](int r) { return Y.outerIndexPtr()[r + 1] - Y.outerIndexPtr()[r]; };
  // Reused from link to link.
  std::vector<int> columnOf(stresses.size(), -1), columns, rows;
  SparseJacobian Yl;
  SparseElimination elimination(0, {}, tolerance, false);
  for (int l = 0; l < numLinks; ++l) {
    const core_detail::BucketRange linkRows = rowsOfLink[l];
    const int k = static_cast<int>(linkRows.size());
    if (l == mechanism.rootLink || k <= model.lambda)
      continue;
    columns.clear();
    for (int r : linkRows) {
      for (SparseJacobian::InnerIterator it(Y, r); it; ++it) {
        if (columnOf[it.col()] < 0) {
          columnOf[it.col()] = static_cast<int>(columns.size());
          columns.push_back(static_cast<int>(it.col()));
        }
      }
    }
    const int needed = k - model.lambda;
    const int numColumns = static_cast<int>(columns.size());
    if (numColumns >= needed) {
      // rank(Y_l) by the sparse elimination, its rows (each scaled to unit norm, which leaves the rank alone)
      // taken sparsest first: a connection that every stress of the link shares (the first hinge of a door)
      // comes last and is reduced by the few-entry rows, instead of filling each of them. Once every column
      // holds a pivot the remaining rows are dependent.
      rows.assign(linkRows.begin(), linkRows.end());
      std::stable_sort(rows.begin(), rows.end(), [&](int a, int b) { return stressesAt(a) < stressesAt(b); });
      core_detail::copyRows(
          Y, rows, [&](int column) { return columnOf[column]; }, numColumns, Yl);
      elimination.reset(numColumns);
      for (int i = 0; i < k && elimination.rank() < numColumns; ++i) {
        const double norm = core_detail::rowNorm(Yl, i);
        elimination.addRow(Yl, i, norm > 0.0 ? 1.0 / norm : 0.0);
      }
      redundant[l] = elimination.rank() == needed;
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
  // The equations some stress reaches first, a byte each, then their elements in one pass in equation
  // order: reading an equation (96 bytes) and its joint (hundreds) for every stress entry missed the cache
  // on each of the 1.1 10^6 entries of a 200 x 200 braced lattice.
  std::vector<char> inStress(model.equations.size(), 0);
  for (const SelfStress& stress : stresses) {
    for (const auto& entry : stress)
      inStress[static_cast<size_t>(entry.first)] = 1;
  }
  for (size_t r = 0; r < model.equations.size(); ++r) {
    if (inStress[r] == 0)
      continue;
    const ConstraintEquation& eq = model.equations[r];
    if (eq.source == EquationSource::Joint) {
      jointInLoop[eq.element] = true;
      linkInLoop[mechanism.joints[eq.element].link1] = true;
      linkInLoop[mechanism.joints[eq.element].link2] = true;
    } else {
      linkInLoop[eq.element] = true;
    }
  }
}

}  // namespace mobility_analysis
