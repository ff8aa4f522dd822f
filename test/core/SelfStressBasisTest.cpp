/// The self-stress basis and the ordered redundancy read off it, against the contract-order elimination and
/// the dense Gram–Schmidt reference, on hand-made matrices, every bundled mechanism and the generated
/// families.
#include "mobility_analysis/SelfStressBasis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <random>
#include <set>

#include <gtest/gtest.h>
#include <Eigen/LU>

#include "core/RandomMatrices.hpp"
#include "core/TestModels.hpp"
#include "mobility_analysis/MobilityAnalysis.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/ParametricFamilies.hpp"
#include "mobility_analysis/generators/ScalingFamilies.hpp"
// A private header of the core: its one test is here, beside the reductions that use it.
#include "../../src/core/IntSorter.hpp"
#include "../../src/core/LocalMemo.hpp"
#include "../../src/core/SideTask.hpp"
#include "../../src/core/StressMatrix.hpp"
#include "../../src/core/StressRule.hpp"

using namespace mobility_analysis;

namespace {

Mechanism generated(const MechanismDescription& description) {
  const GeneratorResult<std::string> urdf = toClosedLoopUrdf(description);
  EXPECT_TRUE(std::holds_alternative<std::string>(urdf));
  Result<Mechanism> mechanism =
      loadMechanismFromString(std::get<std::string>(urdf), description.name + ".urdf");
  EXPECT_TRUE(isOk(mechanism)) << diagnosticOf(mechanism).toString();
  return valueOf(std::move(mechanism));
}

/// y in unscaled rows: the basis works with rows scaled to unit norm.
Eigen::VectorXd toDense(const SelfStress& stress, const SparseJacobian& J) {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(J.rows());
  for (const auto& [row, value] : stress)
    y(row) = value / J.row(row).norm();
  return y;
}

/// Every check of the basis and the ordered answer on one model.
void checkModel(const ModelAtTreePose& m, const std::string& name, bool dense, size_t fillBudget = 0) {
  SCOPED_TRACE(name);
  const SelfStressBasis basis =
      computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank, {}, fillBudget);
  const OrderedRank direct = computeOrderedRank(m.J, tolerances::kRank, false);
  ASSERT_EQ(basis.rank, direct.rank);
  ASSERT_EQ(static_cast<int>(basis.stresses.size()), m.J.rows() - direct.rank);

  // Each is a self-stress, and they are independent: each has a last equation of its own in the sweep.
  const EliminationOrder order = basis.sweptBy == SweepOrderKind::MinimumDegree
                                     ? computeMinimumDegreeOrder(m.mechanism, m.assembled.model)
                                     : computeSweepOrder(m.mechanism, m.assembled.model);
  std::vector<int> position(m.J.rows());
  for (size_t i = 0; i < order.rows.size(); ++i)
    position[order.rows[i]] = static_cast<int>(i);
  std::vector<int> lastRows;
  for (const SelfStress& stress : basis.stresses) {
    ASSERT_FALSE(stress.empty());
    const Eigen::VectorXd y = toDense(stress, m.J);
    const Eigen::VectorXd load = m.J.transpose() * y;
    EXPECT_LT(load.norm(), 1e-9 * y.norm() * m.J.norm());
    int last = stress.front().first;
    for (const auto& entry : stress) {
      if (position[entry.first] > position[last])
        last = entry.first;
    }
    lastRows.push_back(last);
  }
  std::sort(lastRows.begin(), lastRows.end());
  EXPECT_EQ(std::adjacent_find(lastRows.begin(), lastRows.end()), lastRows.end());

  const std::optional<OrderedRank> fromStresses = computeOrderedRankFromStresses(basis, tolerances::kRank);
  ASSERT_TRUE(fromStresses.has_value());
  EXPECT_EQ(fromStresses->redundant, direct.redundant);
  EXPECT_EQ(fromStresses->nullityTrace, direct.nullityTrace);
  EXPECT_EQ(fromStresses->dof(), direct.dof());
  if (dense) {
    const OrderedRank reference = computeOrderedRankDense(Eigen::MatrixXd(m.J), tolerances::kRank);
    EXPECT_EQ(fromStresses->redundant, reference.redundant);
    EXPECT_EQ(fromStresses->nullityTrace, reference.nullityTrace);
  }
}

}  // namespace

TEST(SelfStressBasis, OrderedRankFromAnyBasisEqualsTheDenseReferenceOnRandomMatrices) {
  // The echelon argument does not depend on where the basis came from: find one in a random row order.
  std::mt19937 random(11);
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 12, m = 20;
    const Eigen::MatrixXd J = makeRankDeficientMatrix(random, m, n, 4);
    const SparseJacobian sparse = J.sparseView();
    EliminationOptions options;
    options.rowOrder.resize(m);
    std::iota(options.rowOrder.begin(), options.rowOrder.end(), 0);
    std::shuffle(options.rowOrder.begin(), options.rowOrder.end(), random);
    options.computeDependencies = true;
    const OrderedRank shuffled = computeSparseElimination(sparse, 1e-9, options);
    SelfStressBasis basis;
    basis.stresses = shuffled.dependencies;
    basis.numConstraints = m;
    basis.numCoordinates = n;
    basis.rank = shuffled.rank;
    const std::optional<OrderedRank> fromStresses = computeOrderedRankFromStresses(basis, 1e-9);
    ASSERT_TRUE(fromStresses.has_value()) << "trial " << trial;
    const OrderedRank dense = computeOrderedRankDense(J, 1e-9);
    EXPECT_EQ(fromStresses->redundant, dense.redundant) << "trial " << trial;
    EXPECT_EQ(fromStresses->nullityTrace, dense.nullityTrace) << "trial " << trial;
  }
}

TEST(SelfStressBasis, NoStressMeansNothingRedundant) {
  const ModelAtTreePose m = assembleAtTreePose(loadOrFail(urdfPath("puma560.urdf")), AnalysisMode::Spatial);
  const SelfStressBasis basis =
      computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank);
  EXPECT_TRUE(basis.stresses.empty());
  const std::optional<OrderedRank> ranks = computeOrderedRankFromStresses(basis, tolerances::kRank);
  ASSERT_TRUE(ranks.has_value());
  EXPECT_EQ(std::count(ranks->redundant.begin(), ranks->redundant.end(), true), 0);
  EXPECT_EQ(ranks->dof(), 6);
}

TEST(SelfStressBasis, EqualsContractOrderAndDenseOnEveryBundledMechanism) {
  for (const char* file :
       {"four_bar.urdf", "puma560.urdf", "parallelogram_crank.urdf", "three_sliders.urdf", "rppr.urdf",
        "bennett.urdf", "bennett_mm.urdf", "door.urdf", "sarrus.urdf", "bricard.urdf", "goldberg.urdf",
        "rssr.urdf", "sle_mast.urdf", "hoberman_ring.urdf"}) {
    for (AnalysisMode mode : {AnalysisMode::Auto, AnalysisMode::Spatial}) {
      checkModel(assembleAtTreePose(loadOrFail(urdfPath(file)), mode),
                 std::string(file) + " " + toString(mode), true);
    }
  }
}

TEST(SelfStressBasis, EqualsContractOrderAndDenseOnTheGeneratedFamilies) {
  for (int n : {1, 2, 5, 12}) {
    checkModel(assembleAtTreePose(generated(makeSlePlanarMast(n)), AnalysisMode::Planar), "sle_planar planar",
               n <= 5);
    checkModel(assembleAtTreePose(generated(makeSlePlanarMast(n)), AnalysisMode::Spatial),
               "sle_planar spatial", n <= 5);
    checkModel(assembleAtTreePose(generated(makeHobermanRing(n + 3)), AnalysisMode::Planar),
               "hoberman planar", n <= 5);
    checkModel(assembleAtTreePose(generated(makeHobermanRing(n + 3)), AnalysisMode::Spatial),
               "hoberman spatial", n <= 5);
    checkModel(assembleAtTreePose(generated(makeDoor(n + 1)), AnalysisMode::Spatial), "door spatial", true);
  }
  for (int n : {1, 2, 4}) {
    checkModel(assembleAtTreePose(generated(makeSleTriangularMast(n)), AnalysisMode::Spatial),
               "sle_triangular", n <= 2);
    checkModel(assembleAtTreePose(generated(makeParallelogramGrid(n, n + 1)), AnalysisMode::Planar),
               "grid planar", true);
    checkModel(assembleAtTreePose(generated(makeParallelogramGrid(n, n + 1)), AnalysisMode::Spatial),
               "grid spatial", n <= 2);
  }
}

TEST(SelfStressBasis, StressesStayLocalAlongAChainOfLoops) {
  // A mast analysed in space: 3 stresses per unit, each over a few units' equations however tall the mast is
  // (a stress that ran down to the ground would make the total quadratic).
  size_t largest = 0, total[2] = {0, 0};
  int k = 0;
  for (int units : {20, 60}) {
    const ModelAtTreePose m = assembleAtTreePose(generated(makeSleSpatialMast(units)), AnalysisMode::Spatial);
    const SelfStressBasis basis =
        computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank);
    ASSERT_EQ(static_cast<int>(basis.stresses.size()), 3 * units);
    for (const SelfStress& stress : basis.stresses) {
      largest = std::max(largest, stress.size());
      total[k] += stress.size();
    }
    ++k;
  }
  EXPECT_LT(largest, 200u);
  EXPECT_LT(total[1], 3.3 * total[0])
      << "the stresses grow with the mast: " << total[0] << " -> " << total[1];
}

TEST(SelfStressBasis, StressesThatRunDownAChainAreFoundAgainLocally) {
  // In the triangular mast some closing connections lie in the next level's loops too, so the traced stress
  // of each level includes the one below; past the trace limit the local elimination takes over, and the
  // basis is still a basis that gives the contract-order answer.
  const ModelAtTreePose m = assembleAtTreePose(generated(makeSleTriangularMast(30)), AnalysisMode::Spatial);
  const SelfStressBasis basis =
      computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank);
  EXPECT_GT(basis.locallyResolved, 0);
  size_t largest = 0;
  for (const SelfStress& stress : basis.stresses)
    largest = std::max(largest, stress.size());
  EXPECT_LE(largest, 400u);
  checkModel(m, "sle_triangular 30", false);
}

namespace {

/// A regular polygon of @p links revolute joints about z (the ground is one side), closed by a loop joint:
/// planar DOF links - 3, and in space 3 redundant equations (a planar loop).
std::string ringUrdf(int links) {
  const double pi = std::acos(-1.0), step = 2.0 * pi / links, radius = 0.05 * links / pi;
  const double chord = 2.0 * radius * std::sin(step / 2.0);
  auto number = [](double x) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.17g", x);
    return std::string(text);
  };
  std::string text = "<robot name='ring'><link name='l0'/>";
  for (int i = 1; i < links; ++i) {
    const std::string xyz = number(i == 1 ? radius : chord) + " 0 0";
    const std::string yaw = number(i == 1 ? pi / 2.0 + step / 2.0 : step);
    text += "<link name='l" + std::to_string(i) + "'/><joint name='j" + std::to_string(i) +
            "' type='revolute'><parent link='l" + std::to_string(i - 1) + "'/><child link='l" +
            std::to_string(i) + "'/><origin xyz='" + xyz + "' rpy='0 0 " + yaw +
            "'/><axis xyz='0 0 1'/></joint>";
  }
  return text + "<loop_joint name='close' type='revolute'><link1 link='l" + std::to_string(links - 1) +
         "' xyz='" + number(chord) + " 0 0'/><link2 link='l0' xyz='" + number(radius) +
         " 0 0'/><axis xyz='0 0 1'/></loop_joint></robot>";
}

/// A tree of @p links on revolute joints about their z: a star (every link on the first, around it), a
/// binary tree (link i on link (i - 1) / 2) or a random tree (each link on an earlier one drawn at random,
/// anywhere in space and turned any way).
std::string treeUrdf(const std::string& shape, int links) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  auto number = [](double x) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.17g", x);
    return std::string(text);
  };
  std::string text = "<robot name='" + shape + "'><link name='l0'/>";
  for (int i = 1; i <= links; ++i) {
    int parent = i - 1;
    std::string xyz = "0.1 0 0", rpy = "0 0 0";
    if (shape == "star") {
      const double angle = 6.283185307179586 * i / links;
      parent = 0;
      xyz = number(std::cos(angle)) + " " + number(std::sin(angle)) + " 0";
      rpy = "0 0 " + number(angle);
    } else if (shape == "binary") {
      parent = (i - 1) / 2;
      xyz = i % 2 == 0 ? "0.1 0.05 0" : "0.1 -0.05 0";
    } else {
      parent = static_cast<int>((unit(random) + 1.0) / 2.0 * (i - 1));
      xyz = number(unit(random)) + " " + number(unit(random)) + " " + number(unit(random));
      rpy = number(3 * unit(random)) + " " + number(3 * unit(random)) + " " + number(3 * unit(random));
    }
    text += "<link name='l" + std::to_string(i) + "'/><joint name='j" + std::to_string(i) +
            "' type='revolute'><parent link='l" + std::to_string(parent) + "'/><child link='l" +
            std::to_string(i) + "'/><origin xyz='" + xyz + "' rpy='" + rpy + "'/><axis xyz='0 0 1'/></joint>";
  }
  return text + "</robot>";
}

}  // namespace

TEST(SelfStressBasis, ATreeOfAnyShapeIsSweptWithoutFill) {
  // A tree has no stress, and swept from its leaves each link's rows pivot on its own coordinates: the
  // elimination keeps about J's entries whatever the shape. Where a link carries many joints (the hub of a
  // star), its rigid-link equations for them must pivot on the joints' own elements, not its basis: with the
  // order within each link reversed along with the links, a star of 2 000 links kept 227 times J's entries
  // in the plane (8 000 links: 3 GB), and a random tree in space 2.3 times.
  for (const char* shape : {"star", "binary", "random"}) {
    Result<Mechanism> mechanism = loadMechanismFromString(treeUrdf(shape, 2000), "tree.urdf");
    ASSERT_TRUE(isOk(mechanism)) << diagnosticOf(mechanism).toString();
    for (AnalysisMode mode : {AnalysisMode::Planar, AnalysisMode::Spatial}) {
      if (std::string(shape) == "random" && mode == AnalysisMode::Planar)
        continue;  // its axes are not parallel
      const ModelAtTreePose m = assembleAtTreePose(valueOf(mechanism), mode);
      const SelfStressBasis basis =
          computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank);
      const std::string name = std::string(shape) + " " + toString(mode);
      EXPECT_EQ(basis.sweptBy, SweepOrderKind::FromTheLeaves) << name;
      EXPECT_TRUE(basis.stresses.empty()) << name;
      EXPECT_EQ(basis.rank, m.J.rows()) << name;
      EXPECT_LE(basis.storedEntries, 2 * static_cast<size_t>(m.J.nonZeros())) << name;
    }
  }
}

TEST(SelfStressBasis, ALongRingIsTakenFromItsLeavesAndKeepsTheOrderedAnswer) {
  // Swept from the ground, each arc of a ring fills like a chain swept from its root; past the fill budget
  // the basis takes the spanning tree from the far end and the closing joint last. The answer must not
  // change: the ordered redundancy equals the contract-order elimination (and the dense method where it
  // runs), 3 equations in space (a planar loop), none in the plane, links - 3 DOF in both.
  for (int links : {12, 41, 600}) {
    Result<Mechanism> mechanism = loadMechanismFromString(ringUrdf(links), "ring.urdf");
    ASSERT_TRUE(isOk(mechanism)) << diagnosticOf(mechanism).toString();
    for (AnalysisMode mode : {AnalysisMode::Planar, AnalysisMode::Spatial}) {
      const ModelAtTreePose m = assembleAtTreePose(valueOf(mechanism), mode);
      for (size_t budget : {size_t{0}, size_t{1}}) {
        const std::string name = "ring of " + std::to_string(links) + " " + toString(mode) +
                                 (budget == 1 ? " leaves first" : " from the ground");
        checkModel(m, name, links < 50, budget);
        const SelfStressBasis basis =
            computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank, {}, budget);
        EXPECT_EQ(basis.stresses.size(), mode == AnalysisMode::Spatial ? 3u : 0u) << name;
        EXPECT_EQ(m.J.cols() - basis.rank, links - 3) << name;
      }
    }
  }
}

TEST(SelfStressBasis, TheLeavesFirstOrderKeepsTheAnswerOnLoopyMechanisms) {
  // Forced on mechanisms with many loops (where the sweep from the ground is the one kept), the leaves-first
  // order still yields a basis with the contract-order answer.
  for (int n : {1, 3}) {
    checkModel(assembleAtTreePose(generated(makeParallelogramGrid(n, n + 1)), AnalysisMode::Planar),
               "grid leaves first", true, 1);
    checkModel(assembleAtTreePose(generated(makeSleSpatialMast(2 * n)), AnalysisMode::Spatial),
               "mast leaves first", true, 1);
  }
  for (const char* file : {"bricard.urdf", "stewart_6sps.urdf", "hoberman_ring.urdf", "door.urdf"})
    checkModel(assembleAtTreePose(loadOrFail(urdfPath(file)), AnalysisMode::Spatial), file, true, 1);
}

namespace {

/// Entries of all the stresses of a basis, and of its largest one.
std::pair<size_t, size_t> basisSize(const SelfStressBasis& basis) {
  size_t total = 0, largest = 0;
  for (const SelfStress& stress : basis.stresses) {
    total += stress.size();
    largest = std::max(largest, stress.size());
  }
  return {total, largest};
}

}  // namespace

TEST(SelfStressBasis, AGridOfContinuousBarsKeepsTheDenseAnswer) {
  // Every bar runs through all the pins of its line, so a ball of links around any equation is the whole
  // grid at once and the stresses are searched in space. Two adjacent cells over-constrain their shared bar
  // once: 2RC - R - C stresses (the closed form of ParametricFamilies), and the ordered answer must stay the
  // dense method's equation for equation.
  for (const auto& [rows, columns] : {std::pair<int, int>{6, 7}, std::pair<int, int>{8, 8}, {3, 9}}) {
    const ModelAtTreePose m =
        assembleAtTreePose(generated(makeParallelogramGrid(rows, columns)), AnalysisMode::Planar);
    const SelfStressBasis basis =
        computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank);
    EXPECT_EQ(static_cast<int>(basis.stresses.size()), 2 * rows * columns - rows - columns);
    checkModel(m, "grid " + std::to_string(rows) + " x " + std::to_string(columns), true);
  }
}

TEST(SelfStressBasis, ALongStripOfAGridIsTakenInMinimumDegreeOrder) {
  // A strip's three long bars are pinned to every short one, so the sweep from the ground and the tree from
  // its leaves both fill past their budgets (2 x 5 000 cells ran the sweep to the end: 9.7 s, 2.1 GB). The
  // basis then takes the links in minimum degree order; the stresses must still be the closed form's
  // 2RC - R - C and give the contract-order elimination's answer equation for equation.
  const int rows = 2, columns = 1250;
  const ModelAtTreePose m =
      assembleAtTreePose(generated(makeParallelogramGrid(rows, columns)), AnalysisMode::Planar);
  const SelfStressBasis basis =
      computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank);
  EXPECT_EQ(basis.sweptBy, SweepOrderKind::MinimumDegree);
  EXPECT_EQ(static_cast<int>(basis.stresses.size()), 2 * rows * columns - rows - columns);
  checkModel(m, "strip 2 x 1250", false);
  // In contract order its stresses share last equations, and reducing them to echelon form fills with the
  // strip's length (2 x 5 000: 0.9 s and 240 MB). Within the budget computeSelfStressBasis gives its own
  // reduction the reduction gives up, and the report's redundant equations are those of J's contract-order
  // elimination (2.3 times J's entries there), the same equation for equation.
  EXPECT_FALSE(computeOrderedRankFromStresses(basis, tolerances::kRank, true).has_value());
  AnalysisOptions options;
  options.mode = AnalysisMode::Planar;
  const Result<MobilityAnalysis> analysis = analyzeMechanism(m.mechanism, options);
  ASSERT_TRUE(isOk(analysis));
  const OrderedRank direct = computeOrderedRank(m.J, tolerances::kRank, false);
  std::vector<int> redundant;
  for (int r = 0; r < static_cast<int>(direct.redundant.size()); ++r) {
    if (direct.redundant[r])
      redundant.push_back(r);
  }
  std::vector<int> reported;
  for (const RedundantConstraint& constraint : valueOf(analysis).report.redundantConstraints)
    reported.push_back(constraint.index);
  EXPECT_EQ(reported, redundant);
  // A square grid keeps the sweep from the ground, a ring the tree from its leaves (a budget of 1 abandons
  // the sweep from the ground at once).
  const ModelAtTreePose square =
      assembleAtTreePose(generated(makeParallelogramGrid(8, 8)), AnalysisMode::Planar);
  EXPECT_EQ(
      computeSelfStressBasis(square.mechanism, square.assembled.model, square.J, tolerances::kRank).sweptBy,
      SweepOrderKind::FromTheGround);
  Result<Mechanism> ring = loadMechanismFromString(ringUrdf(41), "ring.urdf");
  ASSERT_TRUE(isOk(ring));
  const ModelAtTreePose swept = assembleAtTreePose(valueOf(ring), AnalysisMode::Spatial);
  EXPECT_EQ(computeSelfStressBasis(swept.mechanism, swept.assembled.model, swept.J, tolerances::kRank, {}, 1)
                .sweptBy,
            SweepOrderKind::FromTheLeaves);
}

TEST(SelfStressBasis, ARandomlyDisplacedGridKeepsTheDenseAnswer) {
  // The same bars and pins with every pin moved at random in the plane: no cell is a parallelogram any more
  // and the stresses are those of a generic framework; the ordered answer must be the dense method's.
  // (From about 18 x 19 on, such a grid's basis is numerically ambiguous for computeOrderedRankFromStresses,
  // with the old traced stresses as with the balls in space, and the analysis falls back on the
  // contract-order elimination.)
  std::mt19937 random(5);
  std::uniform_real_distribution<double> shift(-0.08, 0.08);
  for (int size : {5, 6, 7, 8}) {
    MechanismDescription description = makeParallelogramGrid(size, size + 1);
    for (Connection& connection : description.connections)
      connection.frame.translation() += Eigen::Vector3d(shift(random), shift(random), 0.0);
    checkModel(assembleAtTreePose(generated(description), AnalysisMode::Planar),
               "displaced grid " + std::to_string(size), true);
  }
}

TEST(SelfStressBasis, TheStressesOfAGridOfContinuousBarsStayLocal) {
  // Traced along the sweep, a grid's stresses ran along whole rows of cells (about 2N equations each, 8 10^5
  // entries at 100 x 100, and the ordered answer filled in with them; from 10 x 10 to 20 x 20 the entries
  // grew 7.4 times). Found in space, each is a few cells': the largest does not grow with the grid, and four
  // times the cells hold at most 4.5 times the entries. In space the grid has three more stresses per cell,
  // between its four pins' axes; while the rows between axes had no place, those were traced along whole
  // bars (10 x 10 to 20 x 20: 6.3 times the entries, the largest 151 -> 397).
  for (AnalysisMode mode : {AnalysisMode::Planar, AnalysisMode::Spatial}) {
    const ModelAtTreePose small = assembleAtTreePose(generated(makeParallelogramGrid(10, 10)), mode);
    const ModelAtTreePose large = assembleAtTreePose(generated(makeParallelogramGrid(20, 20)), mode);
    const auto [smallTotal, smallLargest] =
        basisSize(computeSelfStressBasis(small.mechanism, small.assembled.model, small.J, tolerances::kRank));
    const auto [largeTotal, largeLargest] =
        basisSize(computeSelfStressBasis(large.mechanism, large.assembled.model, large.J, tolerances::kRank));
    EXPECT_LE(largeLargest, smallLargest + 10) << toString(mode);
    EXPECT_LE(static_cast<double>(largeTotal), 4.5 * static_cast<double>(smallTotal))
        << toString(mode) << ": " << smallTotal << " -> " << largeTotal;
    checkModel(large, std::string("grid 20 x 20 ") + toString(mode), false);
  }
}

TEST(SparseElimination, ReducingOverTheFirstPivotsGivesTheReductionTheRowHadThen) {
  // The sweep traces a dependent row after the elimination has gone past it (FindsAhead.hpp): reduced again
  // over the pivot rows kept when it came, its multipliers and its trace must be those it had, to the bit.
  std::mt19937 random(11);
  const Eigen::MatrixXd dense = makeRankDeficientMatrix(random, 300, 120, 40);
  const SparseJacobian J = dense.sparseView();
  SparseElimination elimination(static_cast<int>(J.cols()), {}, tolerances::kRank, true);
  struct Then {
    int row, pivots;
    std::vector<std::pair<int, double>> multipliers;
    std::optional<SelfStress> trace;
  };
  std::vector<Then> dependent;
  for (int r = 0; r < J.rows(); ++r) {
    const double norm = J.row(r).norm();
    if (elimination.addRow(J, r, 1.0 / norm).dependent) {
      dependent.push_back(Then{r, elimination.rank(), elimination.multipliers(),
                               elimination.traceDependency(r, elimination.multipliers())});
    }
  }
  ASSERT_GT(dependent.size(), 50u);
  ASSERT_GT(elimination.rank(), dependent.front().pivots);  // pivots came after the first dependent rows
  for (const Then& then : dependent) {
    elimination.reduceOver(J, then.row, 1.0 / J.row(then.row).norm(), then.pivots);
    EXPECT_EQ(elimination.multipliers(), then.multipliers) << then.row;
    EXPECT_EQ(elimination.traceDependency(then.row, elimination.multipliers()), then.trace) << then.row;
  }
}

TEST(SparseElimination, TheNullSpaceIsTheDenseNullSpace) {
  // nullSpace back-substitutes only the pivot rows a free column reaches. Checked against a dense LU of the
  // same matrix: as many vectors as its nullity, each in its null space, together of full rank.
  std::mt19937 random(5);
  const ModelAtTreePose lattice = assembleAtTreePose(generated(makeBarLattice(8, 8)), AnalysisMode::Planar);
  const std::vector<std::pair<std::string, SparseJacobian>> matrices = {
      {"random", SparseJacobian(makeRankDeficientMatrix(random, 80, 120, 30).sparseView())},
      {"bar lattice 8 x 8", lattice.J}};
  for (const auto& [name, J] : matrices) {
    const Eigen::MatrixXd dense(J);
    SparseElimination elimination(static_cast<int>(J.cols()), {}, tolerances::kRank, false);
    for (int r = 0; r < J.rows(); ++r)
      elimination.addRow(J, r, 1.0 / J.row(r).norm());
    const auto nullity = static_cast<size_t>(J.cols() - Eigen::FullPivLU<Eigen::MatrixXd>(dense).rank());
    ASSERT_GE(nullity, 15u) << name;
    EXPECT_FALSE(elimination.nullSpace(nullity - 1).has_value()) << name;
    const std::optional<std::vector<Eigen::VectorXd>> basis = elimination.nullSpace(nullity);
    ASSERT_TRUE(basis.has_value()) << name;
    ASSERT_EQ(basis->size(), nullity) << name;
    Eigen::MatrixXd N(J.cols(), static_cast<Eigen::Index>(nullity));
    for (size_t k = 0; k < nullity; ++k) {
      N.col(static_cast<Eigen::Index>(k)) = (*basis)[k];
      EXPECT_LT((dense * (*basis)[k]).cwiseAbs().maxCoeff(),
                1e-12 * dense.cwiseAbs().maxCoeff() * (*basis)[k].cwiseAbs().maxCoeff())
          << name << " vector " << k;
    }
    EXPECT_EQ(static_cast<size_t>(Eigen::FullPivLU<Eigen::MatrixXd>(N).rank()), nullity) << name;
  }
}

TEST(SelfStressBasis, FindsMadeAheadGiveTheOneThreadBasisToTheBit) {
  // Above 2 10^4 equations a sweep allowed a second thread finds its local stresses ahead on it: a grid of
  // continuous bars (balls in space first), a braced lattice (a trace, then a ball of links) and a ring
  // pantograph with a cable net (some of each, some finds made from a state the sweep was not in, some
  // traces made again at a higher limit). The basis must be the one-thread basis, entry for entry.
  const std::vector<std::pair<std::string, MechanismDescription>> models = {
      {"grid 60 x 60", makeParallelogramGrid(60, 60)},
      {"braced 32 x 32", makeBarLattice(32, 32, true)},
      // From 36 x 36 cells the rule finds some rows first that it used to trace (StressRule's futile traces).
      {"braced 36 x 36", makeBarLattice(36, 36, true)},
      {"net 1000", makeRingPantographNet(1000, 60.0)}};
  for (const auto& [name, description] : models) {
    SCOPED_TRACE(name);
    const ModelAtTreePose m = assembleAtTreePose(generated(description), AnalysisMode::Planar);
    ASSERT_GE(m.J.rows(), core_detail::kSecondThreadEquations);
    const SelfStressBasis one =
        computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank, {}, 0, false);
    const SelfStressBasis two =
        computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank, {}, 0, true);
    ASSERT_GT(one.stresses.size(), 1000u);
    EXPECT_EQ(one.rank, two.rank);
    EXPECT_EQ(one.locallyResolved, two.locallyResolved);
    EXPECT_TRUE(one.stresses == two.stresses);
    EXPECT_EQ(one.smallestKeptPivot, two.smallestKeptPivot);
  }
}

namespace {

/// Sweep positions of the rows of @p order.
std::vector<int> positionsOf(const EliminationOrder& order) {
  std::vector<int> position(order.rows.size());
  for (size_t i = 0; i < order.rows.size(); ++i)
    position[order.rows[i]] = static_cast<int>(i);
  return position;
}

/// A four-bar's sweep and a finder over it, for the rule's tests (stand-ins do the finding; the rule reads
/// only the finder's state). Built in place and not copied: the finder refers to the members before it.
struct FourBarSweep {
  ModelAtTreePose m = assembleAtTreePose(loadOrFail(urdfPath("four_bar.urdf")), AnalysisMode::Planar);
  EliminationOrder order = computeSweepOrder(m.mechanism, m.assembled.model);
  std::vector<int> position = positionsOf(order);
  core_detail::LocalStressFinder finder{m.mechanism, m.assembled.model, m.J,
                                        order,       position,          tolerances::kRank};
};

}  // namespace

TEST(SelfStressBasis, TheRuleFindsFirstOnceTracesKeepRunningPastTheirLimit) {
  // The sweep's rule for a dependent row (StressRule), with stand-ins for the local find and the traces: a
  // trace that runs past its limit costs its limit's pivots and is dropped for the find, so after
  // kFutileTraces such rows in a row the find goes first, until a find fails.
  FourBarSweep sweep;
  const core_detail::LocalStressFinder& finder = sweep.finder;
  ASSERT_FALSE(finder.inSpaceFirst());
  const SelfStress local = {{0, 1.0}, {3, -0.5}}, traced = {{1, 1.0}, {2, 0.25}};
  bool findSucceeds = true, traceSucceeds = false;
  int finds = 0, traces = 0, locallyResolved = 0;
  auto find = [&]() -> std::optional<SelfStress> {
    ++finds;
    return findSucceeds ? std::optional<SelfStress>(local) : std::nullopt;
  };
  auto cappedTrace = [&](size_t) -> std::optional<SelfStress> {
    ++traces;
    return traceSucceeds ? std::optional<SelfStress>(traced) : std::nullopt;
  };
  auto fullTrace = [&] { return traced; };
  core_detail::StressRule rule;
  auto resolve = [&] { return rule.resolve(finder, find, cappedTrace, fullTrace, locallyResolved); };
  const int k = core_detail::kFutileTraces;
  for (int row = 0; row < k; ++row) {
    EXPECT_FALSE(rule.findsFirst(finder)) << row;
    EXPECT_EQ(resolve(), local);
  }
  EXPECT_EQ(traces, k);  // each row traced, then found
  EXPECT_EQ(finds, k);
  EXPECT_TRUE(rule.findsFirst(finder));
  for (int row = 0; row < 10; ++row)
    EXPECT_EQ(resolve(), local);
  EXPECT_EQ(traces, k);  // found, not traced
  EXPECT_EQ(finds, k + 10);
  // A find that fails: the trace decides, and a trace that succeeds puts it first again.
  findSucceeds = false;
  traceSucceeds = true;
  EXPECT_EQ(resolve(), traced);
  EXPECT_EQ(traces, k + 1);
  EXPECT_FALSE(rule.findsFirst(finder));
  findSucceeds = true;
  EXPECT_EQ(resolve(), traced);
  EXPECT_EQ(finds, k + 11);  // traced first, no find
  EXPECT_EQ(locallyResolved, k + 10);
  // Traces failing again count afresh from zero; a failing find also stops the count.
  traceSucceeds = false;
  for (int row = 0; row < k - 1; ++row)
    resolve();
  EXPECT_FALSE(rule.findsFirst(finder));
  findSucceeds = false;
  resolve();  // trace fails, find fails: the full trace
  findSucceeds = true;
  resolve();
  EXPECT_FALSE(rule.findsFirst(finder));
}

TEST(SelfStressBasis, TheRuleKeepsFindingFirstPastScatteredFailures) {
  // Where the balls in space have taken over, the find goes first until kFutileFinds searches have failed in
  // a row. A failed row costs two (before and after its capped trace); a find that succeeds ends the run.
  // Counted over the whole sweep instead, four failing rows anywhere among thousands of local ones stopped
  // the search for every row after them, and those were traced in full (a grid of continuous bars in space).
  FourBarSweep sweep;
  core_detail::LocalStressFinder& finder = sweep.finder;
  finder.setState(core_detail::LocalStressFinder::State{1, 0.0, true});
  ASSERT_TRUE(finder.inSpaceFirst());
  const SelfStress local = {{0, 1.0}, {3, -0.5}}, traced = {{1, 1.0}, {2, 0.25}};
  bool findSucceeds = true;
  int traces = 0, locallyResolved = 0;
  auto find = [&]() -> std::optional<SelfStress> {
    return findSucceeds ? std::optional<SelfStress>(local) : std::nullopt;
  };
  auto cappedTrace = [&](size_t) -> std::optional<SelfStress> {
    ++traces;
    return std::nullopt;
  };
  auto fullTrace = [&] { return traced; };
  core_detail::StressRule rule;
  auto resolve = [&] { return rule.resolve(finder, find, cappedTrace, fullTrace, locallyResolved); };
  for (int round = 0; round < 2 * core_detail::kFutileFinds; ++round) {
    for (int row = 0; row < 3; ++row) {
      ASSERT_TRUE(rule.findsFirst(finder)) << "round " << round;
      EXPECT_EQ(resolve(), local);
    }
    findSucceeds = false;
    EXPECT_EQ(resolve(), traced);  // found first, traced, found again: the full trace
    findSucceeds = true;
  }
  EXPECT_TRUE(rule.findsFirst(finder));
  EXPECT_EQ(traces, 2 * core_detail::kFutileFinds);  // the failing rows only
  // Failures in a row still stop it.
  findSucceeds = false;
  for (int row = 0; row < core_detail::kFutileFinds / 2; ++row)
    resolve();
  EXPECT_FALSE(rule.findsFirst(finder));
}

TEST(SelfStressBasis, BracedLatticeWhereTheRuleFindsFirstGivesTheContractOrderAnswer) {
  // 36 x 36 cells: past the futile traces some rows are found first (the basis differs from the traced one),
  // and it must still be a basis with the contract-order elimination's answer. Closed form: 2RC - R - C + 1.
  const ModelAtTreePose m = assembleAtTreePose(generated(makeBarLattice(36, 36, true)), AnalysisMode::Planar);
  checkModel(m, "braced 36 x 36", false);
  const SelfStressBasis basis =
      computeSelfStressBasis(m.mechanism, m.assembled.model, m.J, tolerances::kRank);
  EXPECT_EQ(static_cast<int>(basis.stresses.size()), 2 * 36 * 36 - 36 - 36 + 1);
}

TEST(IntSorter, SortsAsStdSortDoes) {
  // The bitmap path (distinct values in a narrow span, as a ball's rows and columns are) and every case it
  // leaves to std::sort: short lists, wide spans, repeated values, negative values, the extremes of int.
  std::mt19937 rng(5);
  core_detail::IntSorter sorter;
  auto check = [&](std::vector<int> values, const std::string& what) {
    std::vector<int> expected = values;
    std::sort(expected.begin(), expected.end());
    sorter.sort(values);
    EXPECT_EQ(values, expected) << what;
  };
  for (int trial = 0; trial < 200; ++trial) {
    const int n = std::uniform_int_distribution<int>(0, 400)(rng);
    const int base = std::uniform_int_distribution<int>(-1000, 900000)(rng);
    const int span = std::uniform_int_distribution<int>(1, 80)(rng) * std::max(n, 1);
    std::set<int> distinct;
    std::uniform_int_distribution<int> value(base, base + span);
    while (static_cast<int>(distinct.size()) < std::min(n, span + 1))
      distinct.insert(value(rng));
    std::vector<int> values(distinct.begin(), distinct.end());
    std::shuffle(values.begin(), values.end(), rng);
    check(values, "distinct, trial " + std::to_string(trial));
    if (!values.empty()) {
      values.push_back(values[values.size() / 2]);  // one value twice
      std::shuffle(values.begin(), values.end(), rng);
      check(values, "repeated, trial " + std::to_string(trial));
    }
  }
  std::vector<int> extremes = {std::numeric_limits<int>::max(), std::numeric_limits<int>::min(), 0};
  for (int i = 0; i < 60; ++i)
    extremes.push_back(i * 7 - 100);
  check(extremes, "extremes");
  // The bitmap is left all zero for the next list: one value in each of 100 words, a short list with a value
  // twice (given back to std::sort after the marking), then values beside the first list's in every word.
  std::vector<int> spread, repeated(40), beside = {0};
  for (int k = 0; k < 100; ++k) {
    spread.push_back(64 * (99 - k));
    beside.push_back(64 * k + 1);
  }
  std::iota(repeated.begin(), repeated.end(), 0);
  repeated.push_back(5);
  check(spread, "one value a word");
  check(repeated, "a value twice");
  check(beside, "beside the first list's values");
}

TEST(LocalMemo, AKeyIsItsInputsBitForBit) {
  // The local eliminations' memo finds a result only under the same inputs to the bit. Keys are built in a
  // buffer kept from key to key: a longer key of other words is built before each, so a padding word (after
  // an odd count of ints) left unwritten would differ from the stored key's.
  core_detail::LocalMemo<int> memo;
  uint64_t filler = 0x0123456789abcdefull;
  auto dirty = [&] {
    memo.clearKey();
    filler = filler * 6364136223846793005ull + 1442695040888963407ull;
    for (int i = 0; i < 200; ++i)
      memo.appendKey(filler + static_cast<uint64_t>(i));
    EXPECT_EQ(memo.find(), nullptr);
  };
  std::vector<Eigen::Triplet<double>> entries = {{0, 0, 1.5}, {1, 2, -0.25}};  // 3 row starts + 2 indices
  SparseJacobian local(2, 3);
  local.setFromTriplets(entries.begin(), entries.end());
  local.makeCompressed();
  const int odd[3] = {4, 5, 6};
  auto build = [&](double value, int last) {
    memo.clearKey();
    memo.appendKey(local);
    const int ints[3] = {odd[0], odd[1], last};
    memo.appendKey(ints, 3);
    memo.appendKey(value);
    memo.appendKey(uint64_t{7});
  };
  dirty();
  build(0.5, 6);
  ASSERT_EQ(memo.find(), nullptr);
  memo.insert(42, sizeof(int));
  dirty();
  build(0.5, 6);
  const int* found = memo.find();
  ASSERT_NE(found, nullptr);
  EXPECT_EQ(*found, 42);
  dirty();
  build(std::nextafter(0.5, 1.0), 6);  // one bit of a value
  EXPECT_EQ(memo.find(), nullptr);
  dirty();
  build(0.5, 7);  // one int
  EXPECT_EQ(memo.find(), nullptr);
  local.coeffRef(1, 2) = -0.125;  // one entry of the matrix
  dirty();
  build(0.5, 6);
  EXPECT_EQ(memo.find(), nullptr);
}

TEST(StressMatrix, EqualsTheTripletMatrixEntryForEntry) {
  // Counting into compressed rows must give what setFromTriplets gives: random stresses with increasing
  // equations (the counting path), then one listing an equation twice and out of order (setFromTriplets).
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> row(0, 59);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<SelfStress> stresses(25);
  for (SelfStress& stress : stresses) {
    std::set<int> rows;
    while (rows.size() < 6)
      rows.insert(row(rng));
    for (int r : rows)
      stress.emplace_back(r, value(rng));
  }
  auto keepEven = [](int r) { return r % 2 == 0; };
  auto triplets = [&](const std::vector<SelfStress>& given) {
    std::vector<Eigen::Triplet<double>> list;
    for (int s = 0; s < static_cast<int>(given.size()); ++s) {
      for (const auto& [r, v] : given[static_cast<size_t>(s)]) {
        if (keepEven(r))
          list.emplace_back(r, s, v);
      }
    }
    SparseJacobian Y(60, static_cast<int>(given.size()));
    Y.setFromTriplets(list.begin(), list.end());
    return Y;
  };
  auto same = [](const SparseJacobian& a, const SparseJacobian& b) {
    ASSERT_EQ(a.nonZeros(), b.nonZeros());
    for (int r = 0; r < a.rows(); ++r) {
      SparseJacobian::InnerIterator x(a, r), y(b, r);
      for (; x && y; ++x, ++y) {
        EXPECT_EQ(x.col(), y.col());
        EXPECT_EQ(x.value(), y.value());
      }
      EXPECT_FALSE(x || y);
    }
  };
  same(core_detail::stressMatrix(stresses, 60, keepEven), triplets(stresses));
  stresses[3].emplace_back(stresses[3].front().first, 0.25);  // twice, and out of order
  same(core_detail::stressMatrix(stresses, 60, keepEven), triplets(stresses));
}
