/// The self-stresses found local in contract order (findContractEchelon), and the ordered redundancy read off
/// them, against the contract-order elimination and the dense Gram–Schmidt reference: on braced lattices
/// (square and randomly displaced), on every bundled mechanism and the generated families, and in the report.
#include "mobility_analysis/ContractEchelon.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "core/TestModels.hpp"
#include "mobility_analysis/SelfStressBasis.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/ParametricFamilies.hpp"
#include "mobility_analysis/generators/ScalingFamilies.hpp"

using namespace mobility_analysis;

namespace {

Mechanism generated(const MechanismDescription& description) {
  const GeneratorResult<std::string> urdf = toClosedLoopUrdf(description, UrdfWriterOptions{false, ""});
  EXPECT_TRUE(std::holds_alternative<std::string>(urdf));
  Result<Mechanism> mechanism =
      loadMechanismFromString(std::get<std::string>(urdf), description.name + ".urdf");
  EXPECT_TRUE(isOk(mechanism)) << diagnosticOf(mechanism).toString();
  return valueOf(std::move(mechanism));
}

/// The braced lattice of R x C cells with every node moved at random in the plane (by up to a fifth of a
/// cell), the cables written taut at their new lengths: a generic framework, no cell a square.
MechanismDescription displacedBracedLattice(int rows, int columns, std::mt19937& random) {
  MechanismDescription description = makeBarLattice(rows, columns, true);
  std::uniform_real_distribution<double> shift(-0.1, 0.1);
  std::map<std::pair<long, long>, Eigen::Vector3d> moved;  // by node, in units of the 0.5 m cell
  auto move = [&](const Eigen::Vector3d& x) {
    const std::pair<long, long> node{std::lround(2.0 * x.x()), std::lround(2.0 * x.y())};
    auto found = moved.find(node);
    if (found == moved.end())
      found = moved.emplace(node, Eigen::Vector3d(shift(random), shift(random), 0.0)).first;
    return Eigen::Vector3d(x + found->second);
  };
  for (LinkDescription& link : description.links) {
    for (Eigen::Vector3d& x : link.visualPath)
      x = move(x);
  }
  for (Connection& connection : description.connections)
    connection.frame.translation() = move(connection.frame.translation());
  for (CableDescription& cable : description.cables) {
    cable.point1 = move(cable.point1);
    cable.point2 = move(cable.point2);
    cable.length = (cable.point2 - cable.point1).norm();
  }
  return description;
}

/// y in unscaled rows: the stresses work with rows scaled to unit norm.
Eigen::VectorXd toDense(const SelfStress& stress, const SparseJacobian& J) {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(J.rows());
  for (const auto& [row, value] : stress)
    y(row) = value / J.row(row).norm();
  return y;
}

/**
 * Finds the contract-order echelon of @p m's sweep basis and checks it: one stress per redundancy, each a
 * self-stress, no two with the same last equation, and the ordered answer read off them equal to the
 * contract-order elimination (and to the dense reference when @p dense).
 * @return The echelon's statistics.
 */
ContractEchelonStats checkEchelon(const ModelAtTreePose& m, const std::string& name, bool dense) {
  SCOPED_TRACE(name);
  SelfStressBasis basis = computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank);
  ContractEchelonStats stats;
  const std::optional<std::vector<SelfStress>> echelon =
      findContractEchelon(m.mechanism, m.assembled.model, m.J, basis.stresses, tolerances::kRank, &stats);
  EXPECT_TRUE(echelon.has_value()) << stats.fromBasis << " + " << stats.fromPatches << " of "
                                   << basis.stresses.size() << ", radius " << stats.radius;
  if (!echelon)
    return stats;
  EXPECT_EQ(echelon->size(), basis.stresses.size());
  std::vector<int> lastRows;
  for (const SelfStress& stress : *echelon) {
    EXPECT_FALSE(stress.empty());
    if (stress.empty())
      continue;
    const Eigen::VectorXd y = toDense(stress, m.J);
    EXPECT_LT((m.J.transpose() * y).norm(), 1e-9 * y.norm() * m.J.norm());
    lastRows.push_back(stress.back().first);
  }
  std::sort(lastRows.begin(), lastRows.end());
  EXPECT_EQ(std::adjacent_find(lastRows.begin(), lastRows.end()), lastRows.end());

  basis.contractEchelon = *echelon;
  const std::optional<OrderedRank> fromStresses = computeOrderedRankFromStresses(basis, tolerances::kRank);
  const OrderedRank direct = computeOrderedRank(m.J, tolerances::kRank, false);
  EXPECT_TRUE(fromStresses.has_value());
  if (!fromStresses)
    return stats;
  EXPECT_EQ(fromStresses->redundant, direct.redundant);
  EXPECT_EQ(fromStresses->nullityTrace, direct.nullityTrace);
  // The redundant equations are exactly the last equations of the echelon.
  std::vector<int> redundant;
  for (int r = 0; r < m.J.rows(); ++r) {
    if (fromStresses->redundant[r])
      redundant.push_back(r);
  }
  EXPECT_EQ(redundant, lastRows);
  if (dense) {
    const OrderedRank reference = computeOrderedRankDense(Eigen::MatrixXd(m.J), tolerances::kRank);
    EXPECT_EQ(fromStresses->redundant, reference.redundant);
  }
  return stats;
}

/// Entries of all the stresses, and of the largest one.
std::pair<size_t, size_t> sizeOf(const std::vector<SelfStress>& stresses) {
  size_t total = 0, largest = 0;
  for (const SelfStress& stress : stresses) {
    total += stress.size();
    largest = std::max(largest, stress.size());
  }
  return {total, largest};
}

}  // namespace

TEST(ContractEchelon, BracedLatticesGiveTheDenseOrderedAnswer) {
  // Closed form (ScalingFamilies.hpp, Bolker & Crapo): 2RC - R - C + 1 self-stresses. From 6 x 6 cells on
  // some of the sweep's stresses share last equations in contract order, and the patches find the rest.
  for (const auto& [rows, columns] :
       {std::pair<int, int>{1, 1}, {1, 4}, {2, 2}, {2, 3}, {3, 3}, {4, 5}, {6, 6}, {8, 7}, {12, 12}}) {
    const ModelAtTreePose m =
        assembleAtTreePose(generated(makeBarLattice(rows, columns, true)), AnalysisMode::Planar);
    const int stresses =
        static_cast<int>(m.J.rows()) - computeOrderedRank(m.J, tolerances::kRank, false).rank;
    EXPECT_EQ(stresses, 2 * rows * columns - rows - columns + 1);
    const std::string name = "braced " + std::to_string(rows) + " x " + std::to_string(columns);
    const ContractEchelonStats stats = checkEchelon(m, name, rows * columns <= 30);
    if (rows >= 6 && columns >= 6) {
      EXPECT_GT(stats.fromPatches, 0) << name;
    }
  }
}

TEST(ContractEchelon, RandomlyDisplacedBracedLatticesGiveTheDenseOrderedAnswer) {
  // Every node moved: no cell is a square, the stresses are those of a generic framework, and the ordered
  // answer must still be the dense method's equation for equation.
  std::mt19937 random(13);
  for (int trial = 0; trial < 6; ++trial) {
    const int rows = 2 + trial % 3, columns = 3 + trial / 2;
    const ModelAtTreePose m =
        assembleAtTreePose(generated(displacedBracedLattice(rows, columns, random)), AnalysisMode::Planar);
    const int stresses =
        static_cast<int>(m.J.rows()) - computeOrderedRank(m.J, tolerances::kRank, false).rank;
    EXPECT_EQ(stresses, 2 * rows * columns - rows - columns + 1);
    checkEchelon(m, "displaced braced " + std::to_string(rows) + " x " + std::to_string(columns), true);
  }
  const ModelAtTreePose large =
      assembleAtTreePose(generated(displacedBracedLattice(10, 11, random)), AnalysisMode::Planar);
  checkEchelon(large, "displaced braced 10 x 11", false);
}

TEST(ContractEchelon, WhatItFindsOnOtherMechanismsIsTheContractOrderAnswer) {
  // Where the sweep's stresses already have last equations of their own they are returned as they are;
  // otherwise the patches either prove every redundancy or give up. Either way no answer may differ.
  auto check = [](const ModelAtTreePose& m, const std::string& name) {
    SCOPED_TRACE(name);
    SelfStressBasis basis = computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank);
    const std::optional<std::vector<SelfStress>> echelon =
        findContractEchelon(m.mechanism, m.assembled.model, m.J, basis.stresses, tolerances::kRank);
    if (!echelon)
      return;
    basis.contractEchelon = *echelon;
    const std::optional<OrderedRank> fromStresses = computeOrderedRankFromStresses(basis, tolerances::kRank);
    ASSERT_TRUE(fromStresses.has_value());
    const OrderedRank direct = computeOrderedRank(m.J, tolerances::kRank, false);
    EXPECT_EQ(fromStresses->redundant, direct.redundant);
    EXPECT_EQ(fromStresses->nullityTrace, direct.nullityTrace);
  };
  for (const char* file : {"four_bar.urdf", "parallelogram_crank.urdf", "three_sliders.urdf", "bennett.urdf",
                           "door.urdf", "sarrus.urdf", "bricard.urdf", "goldberg.urdf", "sle_mast.urdf",
                           "hoberman_ring.urdf", "stewart_6sps.urdf"}) {
    for (AnalysisMode mode : {AnalysisMode::Auto, AnalysisMode::Spatial})
      check(assembleAtTreePose(loadOrFail(urdfPath(file)), mode), std::string(file) + " " + toString(mode));
  }
  for (int n : {2, 5}) {
    check(assembleAtTreePose(generated(makeSleTriangularMast(n)), AnalysisMode::Spatial), "sle_triangular");
    check(assembleAtTreePose(generated(makeSleSpatialMast(n)), AnalysisMode::Spatial), "sle_spatial");
    check(assembleAtTreePose(generated(makeHobermanRing(n + 3)), AnalysisMode::Spatial), "hoberman spatial");
    check(assembleAtTreePose(generated(makeParallelogramGrid(n, n + 2)), AnalysisMode::Planar), "grid");
    check(assembleAtTreePose(generated(makeTrussMast(4 * n)), AnalysisMode::Spatial), "truss mast");
    check(assembleAtTreePose(generated(makeRing(40 * n)), AnalysisMode::Spatial), "ring in space");
    check(assembleAtTreePose(generated(makeBarLattice(n, n + 1)), AnalysisMode::Planar), "bar lattice");
  }
}

TEST(ContractEchelon, AStressAsLargeAsTheMechanismIsNotFoundInPatches) {
  // A ring of 120 links in space: its three out-of-plane stresses run round the whole ring, and two of the
  // sweep's end on the same equation of the closing joint. No patch holds the ring, so nothing can prove the
  // third redundancy locally: the answer is "not found" (the report then reduces the sweep's stresses), never
  // a made-up stress.
  const ModelAtTreePose m = assembleAtTreePose(generated(makeRing(120)), AnalysisMode::Spatial);
  const SelfStressBasis basis =
      computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank);
  ASSERT_EQ(basis.stresses.size(), 3u);
  ContractEchelonStats stats;
  const std::optional<std::vector<SelfStress>> echelon =
      findContractEchelon(m.mechanism, m.assembled.model, m.J, basis.stresses, tolerances::kRank, &stats);
  EXPECT_FALSE(echelon.has_value());
  EXPECT_EQ(stats.fromBasis, 2);
  EXPECT_EQ(stats.fromPatches, 0);
  EXPECT_GT(stats.patches, 0);
  // The ordered answer from the sweep's stresses is still the contract order's.
  const std::optional<OrderedRank> fromStresses = computeOrderedRankFromStresses(basis, tolerances::kRank);
  ASSERT_TRUE(fromStresses.has_value());
  EXPECT_EQ(fromStresses->redundant, computeOrderedRank(m.J, tolerances::kRank, false).redundant);
}

TEST(ContractEchelon, TheReportOfALargeBracedLatticeReadsLocalStresses) {
  // From about 40 x 40 cells the sweep's stresses fill their reduction past its budget and the basis carries
  // the contract-order echelon; its stresses stay as local as a few cells (the largest does not grow with
  // the lattice, four times the cells hold at most 4.5 times the entries) and the answer is the
  // contract-order elimination's, with the closed-form count.
  std::pair<size_t, size_t> sizes[2];
  int k = 0;
  for (int n : {40, 80}) {
    const ModelAtTreePose m = assembleAtTreePose(generated(makeBarLattice(n, n, true)), AnalysisMode::Planar);
    const SelfStressBasis basis =
        computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank);
    ASSERT_EQ(static_cast<int>(basis.stresses.size()), 2 * n * n - 2 * n + 1);
    ASSERT_EQ(basis.contractEchelon.size(), basis.stresses.size()) << n;
    sizes[k++] = sizeOf(basis.contractEchelon);
    const std::optional<OrderedRank> fromStresses = computeOrderedRankFromStresses(basis, tolerances::kRank);
    ASSERT_TRUE(fromStresses.has_value());
    EXPECT_EQ(std::count(fromStresses->redundant.begin(), fromStresses->redundant.end(), true),
              2 * n * n - 2 * n + 1);
    if (n == 40) {
      const OrderedRank direct = computeOrderedRank(m.J, tolerances::kRank, false);
      EXPECT_EQ(fromStresses->redundant, direct.redundant);
      EXPECT_EQ(fromStresses->nullityTrace, direct.nullityTrace);
    }
  }
  EXPECT_LE(sizes[1].second, sizes[0].second);
  EXPECT_LE(static_cast<double>(sizes[1].first), 4.5 * static_cast<double>(sizes[0].first))
      << sizes[0].first << " -> " << sizes[1].first;
}
