#include "mobility_analysis/ContractEchelon.hpp"

#include <algorithm>
#include <cmath>

#include "EquationGraph.hpp"
#include "IntSorter.hpp"
#include "LocalMemo.hpp"
#include "LocalRows.hpp"
#include "StressScaling.hpp"

namespace mobility_analysis {

namespace {

/// A patch stops growing before it holds more equations than this.
constexpr size_t kPatchLimit = 3000;

/// A stress proves its last equation redundant when its coefficient there is at least this fraction of its
/// largest: with a smaller one, the rounding of the others (about 1e-15 of the largest) divided by it could
/// pass the rank tolerance, and the dense method might call the equation independent.
constexpr double kFirmLast = 1e-4;

/// Patches: seeds every `cover` links, each patch the links within `radius` of its seed. Measured on braced
/// lattices: patches of radius 5 every 4 links prove every redundancy of the square lattice and of randomly
/// displaced ones (up to 40 x 40 cells, whose stresses are larger) in one round; of radius 3 every 2 links,
/// only the square one's, over 1.5 times the equations. The second size is for larger stresses.
struct PatchSize {
  int cover;
  int radius;
};
constexpr PatchSize kPatchSizes[] = {{4, 5}, {4, 8}};

/// The patches stop (nothing found) once they have taken this many times the mechanism's equations: a
/// mechanism whose links each reach most others (a grid of continuous bars) is not covered by small balls.
constexpr size_t kPatchRowsFactor = 24;

bool isFirm(const SelfStress& stress) {
  return !stress.empty() && std::abs(stress.back().second) >= kFirmLast;
}

/// A stress scaled to unit largest coefficient, rounding noise dropped, by increasing equation; in place, as
/// the patches find tens of thousands (a 200 x 200 braced lattice: 79 601), mostly sorted already (a traced
/// dependency is sorted by local row, and a patch's rows are in contract order).
void normalise(SelfStress& stress) {
  if (!std::is_sorted(stress.begin(), stress.end()))
    std::sort(stress.begin(), stress.end());
  core_detail::scaleToUnitLargest(stress);
}

/// Balls of links and the contract-order elimination of their equations; workspaces kept across patches.
class Patches {
 public:
  Patches(const Mechanism& mechanism, const SparseJacobian& J, const core_detail::EquationGraph& graph,
          double tolerance)
      : mechanism_(mechanism),
        J_(J),
        graph_(graph),
        tolerance_(tolerance),
        distance_(mechanism.links.size(), -1),
        jointTaken_(mechanism.joints.size(), 0),
        columnMap_(J.cols(), -1) {}

  /// Links within @p radius connections of @p seed (fewer where the equations would pass kPatchLimit).
  std::vector<int> ball(int seed, int radius) {
    std::vector<int> links = {seed};
    distance_[seed] = 0;
    size_t rows = graph_.linkRows[seed].size();
    size_t levelStart = 0;
    for (int level = 0; level < radius; ++level) {
      const size_t levelEnd = links.size();
      size_t added = 0;
      for (size_t i = levelStart; i < levelEnd; ++i) {
        for (int j : graph_.incident[links[i]]) {
          const Joint& joint = mechanism_.joints[j];
          added += graph_.jointRows[j].size();
          for (int other : {joint.link1, joint.link2}) {
            if (distance_[other] < 0) {
              distance_[other] = level + 1;
              links.push_back(other);
              added += graph_.linkRows[other].size();
            }
          }
        }
      }
      if (rows + added > kPatchLimit && level > 0) {
        // Drop the level that made the patch too large.
        for (size_t i = levelEnd; i < links.size(); ++i)
          distance_[links[i]] = -1;
        links.resize(levelEnd);
        break;
      }
      rows += added;
      levelStart = levelEnd;
      if (levelStart == links.size())
        break;
    }
    for (int link : links)
      distance_[link] = -1;
    return links;
  }

  /// Marks the links within @p radius of @p seed in @p covered.
  void cover(int seed, int radius, std::vector<char>& covered) {
    for (int link : ball(seed, radius))
      covered[link] = 1;
  }

  /// The equations of @p links and of the connections between them, in contract order.
  std::vector<int> rowsOf(const std::vector<int>& links) {
    std::vector<int> rows, joints;
    for (int link : links)
      distance_[link] = 0;
    for (int link : links) {
      rows.insert(rows.end(), graph_.linkRows[link].begin(), graph_.linkRows[link].end());
      for (int j : graph_.incident[link]) {
        const Joint& joint = mechanism_.joints[j];
        if (jointTaken_[j] != 0 || distance_[joint.link1] < 0 || distance_[joint.link2] < 0)
          continue;
        jointTaken_[j] = 1;
        joints.push_back(j);
        rows.insert(rows.end(), graph_.jointRows[j].begin(), graph_.jointRows[j].end());
      }
    }
    for (int j : joints)
      jointTaken_[j] = 0;
    for (int link : links)
      distance_[link] = -1;
    sorter_.sort(rows);
    return rows;
  }

  /**
   * Eliminates @p rows in their order; for every dependent one that @p wanted accepts, @p found gets its
   * dependency (global rows, coefficients of the rows scaled to unit norm, 1 at the row).
   */
  template <class Wanted, class Found>
  void eliminate(const std::vector<int>& rows, Wanted&& wanted, Found&& found) {
    std::vector<int> columns;
    for (int r : rows) {
      for (SparseJacobian::InnerIterator it(J_, r); it; ++it) {
        if (columnMap_[it.col()] < 0) {
          columnMap_[it.col()] = 0;
          columns.push_back(static_cast<int>(it.col()));
        }
      }
    }
    // Coordinates of later elements first: in document order a child link comes after its parent, so each
    // tree joint's equations pivot on the child's coordinates and leave the parent's free for its other
    // children (measured on the braced lattice: 40% less fill than the other way round).
    sorter_.sort(columns);
    std::reverse(columns.begin(), columns.end());
    SparseJacobian& local = local_;
    core_detail::copyRowsOver(J_, rows, columns, columnMap_, local);

    // The same patch elsewhere (a regular structure) has the same dependencies to the bit (LocalMemo): the
    // elimination reads the local matrix and nothing else. What a patch wants is fixed before it is
    // eliminated (found sets the proof of its own row only), so a known patch serves when it holds the
    // dependency of every row wanted now; otherwise the patch is eliminated again, tracing what is wanted
    // now and what was traced before, and that outcome replaces the known one.
    PatchOutcome* known = nullptr;
    const bool keyed = memo_.active();
    if (keyed) {
      memo_.clearKey();
      memo_.appendKey(local);
      known = memo_.find();
    }
    const bool serves =
        known && std::all_of(known->dependencies.begin(), known->dependencies.end(),
                             [&](const auto& d) { return !d.second.empty() || !wanted(rows[d.first]); });
    PatchOutcome fresh;
    if (!serves) {
      std::vector<char> traced(static_cast<size_t>(local.rows()), 0);
      if (known) {
        for (const auto& [i, dependency] : known->dependencies)
          traced[static_cast<size_t>(i)] = dependency.empty() ? 0 : 1;
      }
      fresh = eliminateTracing(local,
                               [&](int i) { return traced[static_cast<size_t>(i)] != 0 || wanted(rows[i]); });
    }
    const PatchOutcome& outcome = serves ? *known : fresh;
    for (const auto& [i, dependency] : outcome.dependencies) {
      if (!wanted(rows[i]))
        continue;
      SelfStress stress = dependency;
      for (auto& entry : stress)
        entry.first = rows[entry.first];
      found(rows[i], std::move(stress));
    }
    storedEntries += outcome.storedEntries;
    if (known && !serves) {
      *known = std::move(fresh);
    } else if (keyed && !known) {
      const size_t bytes = fresh.bytes();
      memo_.insert(std::move(fresh), bytes);
    }
  }

  size_t storedEntries = 0;

 private:
  /// What eliminating a patch gave: each dependent row (local number) with its dependency (local rows), or
  /// nothing (empty) where it was not traced.
  struct PatchOutcome {
    std::vector<std::pair<int, SelfStress>> dependencies;
    size_t storedEntries = 0;

    size_t bytes() const {
      size_t bytes = sizeof(PatchOutcome);
      for (const auto& dependency : dependencies)
        bytes += sizeof(dependency) + dependency.second.size() * sizeof(SelfStress::value_type);
      return bytes;
    }
  };

  /// @p local's rows eliminated in order, the dependent rows that @p traced accepts traced.
  template <class Traced>
  PatchOutcome eliminateTracing(const SparseJacobian& local, Traced&& traced) const {
    PatchOutcome outcome;
    SparseElimination elimination(static_cast<int>(local.cols()), {}, tolerance_, true);
    for (int i = 0; i < local.rows(); ++i) {
      const double norm = local.row(i).norm();
      if (!elimination.addRow(local, i, norm > 0.0 ? 1.0 / norm : 0.0).dependent)
        continue;
      outcome.dependencies.emplace_back(
          i, traced(i) ? *elimination.traceDependency(i, elimination.multipliers()) : SelfStress{});
    }
    outcome.storedEntries = elimination.storedEntries();
    return outcome;
  }

  const Mechanism& mechanism_;
  const SparseJacobian& J_;
  const core_detail::EquationGraph& graph_;
  double tolerance_;
  std::vector<int> distance_;
  std::vector<char> jointTaken_;
  std::vector<int> columnMap_;
  core_detail::IntSorter sorter_;  ///< A patch's rows and columns.
  SparseJacobian local_;           ///< The patch's rows, storage kept from patch to patch.
  // A patch's key is its whole matrix (about 130 kB at radius 5): the 200 x 200 braced lattice's 4 394
  // patches have 1 127 distinct ones, 138 MB, of which the default budget held 550.
  core_detail::LocalMemo<PatchOutcome> memo_{size_t{160} << 20};
};

}  // namespace

std::optional<std::vector<SelfStress>> findContractEchelon(const Mechanism& mechanism,
                                                           const CoordinateModel& model,
                                                           const SparseJacobian& J,
                                                           const std::vector<SelfStress>& basis,
                                                           double tolerance, ContractEchelonStats* stats) {
  ContractEchelonStats unused;
  ContractEchelonStats& done = stats ? *stats : unused;
  done = ContractEchelonStats{};
  const int m = static_cast<int>(J.rows());
  const size_t k = basis.size();
  // The stress proving each equation redundant, by its last equation: first the basis's own, the shortest
  // where several share one.
  std::vector<int> proof(m, -1);
  std::vector<SelfStress> result;
  result.reserve(k);
  for (const SelfStress& stress : basis) {
    if (stress.empty() || !isFirm(stress))
      continue;
    const int last = stress.back().first;
    if (proof[last] < 0) {
      proof[last] = static_cast<int>(result.size());
      result.push_back(stress);
    } else if (stress.size() < result[proof[last]].size()) {
      result[proof[last]] = stress;
    }
  }
  done.fromBasis = static_cast<int>(result.size());
  if (result.size() == k)
    return result;

  const core_detail::EquationGraph graph(mechanism, model);
  Patches patches(mechanism, J, graph, tolerance);
  // The patches cover every link with an equation in some stress (the redundant equations are among
  // those). Rows first, then their links in one pass: the stresses' entries are many and the equations large.
  std::vector<char> stressed(m, 0), target(mechanism.links.size(), 0);
  for (const SelfStress& stress : basis) {
    for (const auto& entry : stress)
      stressed[entry.first] = 1;
  }
  for (int r = 0; r < m; ++r) {
    if (stressed[r] == 0)
      continue;
    const ConstraintEquation& eq = model.equations[r];
    if (eq.source == EquationSource::Joint) {
      target[mechanism.joints[eq.element].link1] = 1;
      target[mechanism.joints[eq.element].link2] = 1;
    } else {
      target[eq.element] = 1;
    }
  }
  const size_t rowLimit = kPatchRowsFactor * static_cast<size_t>(m);
  for (const PatchSize& size : kPatchSizes) {
    done.radius = size.radius;
    std::vector<char> covered(mechanism.links.size(), 0);
    for (size_t seed = 0; seed < mechanism.links.size() && result.size() < k; ++seed) {
      if (target[seed] == 0 || covered[seed] != 0)
        continue;
      patches.cover(static_cast<int>(seed), size.cover, covered);
      const std::vector<int> rows = patches.rowsOf(patches.ball(static_cast<int>(seed), size.radius));
      ++done.patches;
      done.patchRows += rows.size();
      if (done.patchRows > rowLimit) {
        return std::nullopt;
      }
      patches.eliminate(
          rows, [&](int row) { return proof[row] < 0; },
          [&](int row, SelfStress stress) {
            normalise(stress);
            if (!isFirm(stress))
              return;
            proof[row] = static_cast<int>(result.size());
            result.push_back(std::move(stress));
            ++done.fromPatches;
          });
    }
    if (result.size() == k)
      return result;
  }
  return std::nullopt;
}

}  // namespace mobility_analysis
