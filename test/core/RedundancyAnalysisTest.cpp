#include "mobility_analysis/RedundancyAnalysis.hpp"

#include <random>

#include <gtest/gtest.h>

#include "core/RandomMatrices.hpp"
#include "core/TestModels.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/ParametricFamilies.hpp"
#include "mobility_analysis/generators/ScalingFamilies.hpp"

using namespace mobility_analysis;

namespace {

SparseJacobian toSparse(const Eigen::MatrixXd& dense) {
  return dense.sparseView();
}

/// A generated mechanism, assembled in the plane at its written pose.
struct Assembled {
  Mechanism mechanism;
  CoordinateModel model;
  SparseJacobian J;
};

Assembled assembleIn(const MechanismDescription& description, AnalysisMode mode) {
  Assembled result;
  const GeneratorResult<std::string> urdf = toClosedLoopUrdf(description);
  if (!std::holds_alternative<std::string>(urdf)) {
    ADD_FAILURE() << description.name << " does not generate";
    return result;
  }
  Result<Mechanism> mechanism =
      loadMechanismFromString(std::get<std::string>(urdf), description.name + ".urdf");
  if (!isOk(mechanism)) {
    ADD_FAILURE() << diagnosticOf(mechanism).toString();
    return result;
  }
  result.mechanism = valueOf(std::move(mechanism));
  const Result<AssembledMechanism> assembled =
      assembleMechanism(result.mechanism, computeTreePoses(result.mechanism, {}), mode);
  if (!isOk(assembled)) {
    ADD_FAILURE() << diagnosticOf(assembled).toString();
    return result;
  }
  result.model = valueOf(assembled).model;
  result.J = computeConstraintJacobian(result.model, valueOf(assembled).q);
  return result;
}

Assembled assemblePlanar(const MechanismDescription& description) {
  return assembleIn(description, AnalysisMode::Planar);
}

std::vector<std::string> redundantEquations(const Assembled& a, const std::vector<bool>& redundant) {
  std::vector<std::string> names;
  for (int r = 0; r < a.model.numConstraints(); ++r) {
    if (redundant[r])
      names.push_back(describeEquation(a.model, r));
  }
  return names;
}

/**
 * The redundant equations of the deployed ring pantograph net of @p units units in contract order, by its
 * structure: after the rigid bars, the tree (two chains of pins around the ring from bar_0_a) and the 2N taut
 * cables, the first and last diagonal cables repeat what the hoops and the other diagonals fix; every kink
 * but kink_0 (a tree joint) closes a loop whose shape the cables have fixed (both rows, but kink_(N-1)'s x,
 * which is the one freedom the cables leave the last unit), and the two pins that close the ring are
 * redundant in full. 2 + 2(N - 1) - 1 + 4 = 2N + 3, the closed form. The dense method gives this set at 10
 * units.
 */
std::vector<std::string> ringNetRedundancy(const Assembled& a, int units) {
  std::vector<std::string> names;
  const std::string last = std::to_string(units - 1);
  for (int r = 0; r < a.model.numConstraints(); ++r) {
    const ConstraintEquation& eq = a.model.equations[r];
    if (eq.source != EquationSource::Joint)
      continue;
    const std::string& name = a.mechanism.joints[eq.element].name;
    const std::string text = describeEquation(a.model, r);
    const bool isX = text.size() > 3 && text.compare(text.size() - 3, 3, "(x)") == 0;
    if (name == "diagonal_0" || name == "diagonal_" + last || name == "pin_ab_" + last ||
        name == "pin_ba_" + last ||
        (name.rfind("kink_", 0) == 0 && name != "kink_0" && !(name == "kink_" + last && isX)))
      names.push_back(text);
  }
  return names;
}

}  // namespace

TEST(RedundancyAnalysis, RedundantRowIsTheOneThatDependsOnRowsBeforeIt) {
  // Row 2 = row 0 + row 1: the later row is redundant, never an earlier one; row 3 is new.
  Eigen::MatrixXd J(4, 4);
  J << 1, 0, 2, 0,  //
      0, 1, 0, 0,   //
      1, 1, 2, 0,   //
      0, 0, 0, 3;
  const OrderedRank ranks = computeOrderedRank(toSparse(J), tolerances::kRank);
  EXPECT_EQ(ranks.rank, 3);
  EXPECT_EQ(ranks.dof(), 1);
  EXPECT_EQ(ranks.redundant, (std::vector<bool>{false, false, true, false}));
  EXPECT_EQ(ranks.nullityTrace, (std::vector<int>{3, 2, 2, 1}));
  ASSERT_EQ(ranks.dependencies.size(), 1u);
  EXPECT_EQ(supportOf(ranks.dependencies[0]), (std::vector<int>{0, 1, 2}));
}

TEST(RedundancyAnalysis, DependencyLeavesOutRowsWithZeroCoefficient) {
  // Row 3 = 2 row 1: rows 0 and 2 are not part of its dependency even though they share its columns.
  Eigen::MatrixXd J(4, 3);
  J << 1, 1, 0,  //
      0, 1, 0,   //
      1, 0, 1,   //
      0, 2, 0;
  const OrderedRank ranks = computeOrderedRank(toSparse(J), tolerances::kRank);
  ASSERT_EQ(ranks.dependencies.size(), 1u);
  EXPECT_EQ(supportOf(ranks.dependencies[0]), (std::vector<int>{1, 3}));
}

TEST(RedundancyAnalysis, SparseEliminationEqualsDenseGramSchmidtOnRandomRankDeficientMatrices) {
  std::mt19937 random(7);
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 12, m = 18;
    const Eigen::MatrixXd J = makeRankDeficientMatrix(random, m, n, 6);
    const OrderedRank sparse = computeOrderedRank(toSparse(J), 1e-9);
    const OrderedRank dense = computeOrderedRankDense(J, 1e-9);
    EXPECT_EQ(sparse.redundant, dense.redundant) << "trial " << trial;
    EXPECT_EQ(sparse.nullityTrace, dense.nullityTrace) << "trial " << trial;
    ASSERT_EQ(sparse.dependencies.size(), dense.dependencies.size()) << "trial " << trial;
    for (size_t k = 0; k < sparse.dependencies.size(); ++k) {
      EXPECT_EQ(supportOf(sparse.dependencies[k]), supportOf(dense.dependencies[k])) << "trial " << trial;
      // Both are the same left null vector (y_r = 1): equal coefficients, and y^T J = 0.
      Eigen::VectorXd ySparse = Eigen::VectorXd::Zero(m), yDense = Eigen::VectorXd::Zero(m);
      for (const auto& [row, value] : sparse.dependencies[k])
        ySparse(row) = value / J.row(row).norm();
      for (const auto& [row, value] : dense.dependencies[k])
        yDense(row) = value / J.row(row).norm();
      EXPECT_LT((ySparse - yDense).norm(), 1e-9 * yDense.norm()) << "trial " << trial;
      EXPECT_LT((ySparse.transpose() * J).norm(), 1e-9 * ySparse.norm() * J.norm()) << "trial " << trial;
    }
    EXPECT_EQ(sparse.nullityTrace, computeNullityTraceLiteral(J, 1e-9)) << "trial " << trial;
  }
}

TEST(RedundancyAnalysis, MarginSeparatesKeptFromDropped) {
  const MobilityAnalysis spatial = analyzeOrFail(fixturePath("four_bar_closed.urdf"), AnalysisMode::Spatial);
  EXPECT_GT(spatial.report.rankMargin.smallestKeptPivot, 1e-3);
  EXPECT_LT(spatial.report.rankMargin.largestDroppedResidual, 1e-12);
  EXPECT_FALSE(spatial.report.rankMargin.nearTolerance);
}

TEST(RedundancyAnalysis, DistanceFromPivotRowsIsTheOrthogonalResidual) {
  // The re-check's residual is what dense Gram-Schmidt compares: the distance of the unit row from the span
  // of the rows kept before it, here against a least-squares solve of the same rows.
  std::mt19937 random(11);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 10, m = 14;
    const Eigen::MatrixXd J = makeRankDeficientMatrix(random, m, n, 4);
    const SparseJacobian sparse = toSparse(J);
    SparseElimination elimination(n, {}, 1e-9, false, 1.0);
    std::vector<int> kept;
    for (int r = 0; r < m; ++r) {
      const double scale = 1.0 / J.row(r).norm();
      if (!kept.empty()) {
        Eigen::MatrixXd A(n, static_cast<Eigen::Index>(kept.size()));
        for (size_t k = 0; k < kept.size(); ++k)
          A.col(static_cast<Eigen::Index>(k)) = J.row(kept[k]).transpose();
        const Eigen::VectorXd x = J.row(r).transpose() * scale;
        const Eigen::VectorXd fit = A * A.completeOrthogonalDecomposition().solve(x);
        const std::optional<double> distance = elimination.distanceFromPivotRows(sparse, r, scale, 64);
        ASSERT_TRUE(distance.has_value());
        EXPECT_NEAR(*distance, (x - fit).norm(), 1e-10) << "trial " << trial << " row " << r;
      }
      if (!elimination.addRow(sparse, r, scale).dependent)
        kept.push_back(r);
    }
  }
}

TEST(RedundancyAnalysis, NearToleranceDecisionIsRecheckedOrCounted) {
  // Row 1 leaves 5e-8 of itself after row 0: within kNearDecisionFactor of the threshold 1e-8.
  Eigen::MatrixXd J(2, 2);
  J << 1, 0,  //
      1, 5e-8;
  EliminationOptions options;
  options.recheckNearTolerance = true;
  const OrderedRank checked = computeSparseElimination(toSparse(J), tolerances::kRank, options);
  EXPECT_EQ(checked.redundant, (std::vector<bool>{false, false}));
  EXPECT_NEAR(checked.smallestKeptPivot, 5e-8, 1e-12);
  EXPECT_EQ(checked.uncheckedNearDecisions, 0);
  options.maxRecheckNullity = 0;  // one free column: too many for this re-check
  const OrderedRank unchecked = computeSparseElimination(toSparse(J), tolerances::kRank, options);
  EXPECT_EQ(unchecked.redundant, checked.redundant);
  EXPECT_EQ(unchecked.uncheckedNearDecisions, 1);
}

TEST(RedundancyAnalysis, ContractOrderGivesTheClosedFormOfTheHundredSquaredGrid) {
  // The report's fallback (the contract order) on the 100 x 100 grid of continuous bars: closed form DOF 1
  // and 2RC - R - C = 19 800 redundant. With threshold pivoting it kept a dependent row whose rounding had
  // grown to 1.0e-8 (DOF 0, 19 799); with the largest entry as pivot the margins are wide.
  const int size = 100;
  const Assembled grid = assemblePlanar(makeParallelogramGrid(size, size));
  const OrderedRank ranks = computeOrderedRank(grid.J, tolerances::kRank, false);
  EXPECT_EQ(ranks.dof(), 1);
  EXPECT_EQ(static_cast<int>(grid.J.rows()) - ranks.rank, 2 * size * size - 2 * size);
  EXPECT_GT(ranks.smallestKeptPivot, tolerances::kRank * tolerances::kNearDecisionFactor);
  EXPECT_LT(ranks.largestDroppedResidual, tolerances::kRank / tolerances::kNearDecisionFactor);
  EXPECT_EQ(ranks.uncheckedNearDecisions, 0);
}

TEST(RedundancyAnalysis, ContractOrderOnTheDeployedRingPantographNet) {
  // 10 units: the structural set is the dense method's.
  const Assembled small = assemblePlanar(makeRingPantographNet(10, 60));
  const OrderedRank dense = computeOrderedRankDense(Eigen::MatrixXd(small.J), tolerances::kRank);
  EXPECT_EQ(redundantEquations(small, dense.redundant), ringNetRedundancy(small, 10));
  EXPECT_EQ(computeOrderedRank(small.J, tolerances::kRank, false).redundant, dense.redundant);
  // 500 units (the report falls back to the contract order here: the sweep's basis is ambiguous). Threshold
  // pivoting got 8 equations wrong at 250 units; strict pivoting alone swaps pin_ba_499's x with the last
  // boundary row at 500 (a dependent row's reduced norm is 1.3e-8 of rounding), which the re-check by
  // orthogonal distance puts right. SuiteSparse QR of J^T in contract column order (SPQR_ORDERING_FIXED,
  // Heath's rank test, the dense method's residual) gave this set at 120, 250, 500 and 1 000 units.
  const int units = 500;
  const Assembled large = assemblePlanar(makeRingPantographNet(units, 60));
  const OrderedRank ranks = computeOrderedRank(large.J, tolerances::kRank, false);
  EXPECT_EQ(ranks.dof(), 0);
  EXPECT_EQ(redundantEquations(large, ranks.redundant), ringNetRedundancy(large, units));
  EXPECT_EQ(ranks.uncheckedNearDecisions, 0);
}

TEST(RedundancyAnalysis, ContractOrderReducesAStripInSpaceInLinearWork) {
  // A strip of the continuous-bar grid analysed in space: its pins' axis and coincidence rows come in exact
  // ties (+-1), and where the earlier coordinate won them every third-row pin's reduced row pivoted on a long
  // bar's basis, each pivot row led to the previous pin's, and each later row was reduced along the whole
  // strip: from 2 x 1 250 to 2 x 2 500 cells the pivot rows subtracted grew 3.9 times (7.4 10^6 -> 2.9 10^7;
  // 2 x 5 000: 4.7 s). With the later coordinate they grow as the strip (2 x 400 -> 2 x 1 600: 3.7 times;
  // 2 x 3 200: 3.3 10^5). The answer is the dense method's.
  const Assembled small = assembleIn(makeParallelogramGrid(2, 20), AnalysisMode::Spatial);
  EXPECT_EQ(computeOrderedRank(small.J, tolerances::kRank, false).redundant,
            computeOrderedRankDense(Eigen::MatrixXd(small.J), tolerances::kRank).redundant);
  const Assembled shorter = assembleIn(makeParallelogramGrid(2, 400), AnalysisMode::Spatial);
  const Assembled longer = assembleIn(makeParallelogramGrid(2, 1600), AnalysisMode::Spatial);
  const OrderedRank a = computeOrderedRank(shorter.J, tolerances::kRank, false);
  const OrderedRank b = computeOrderedRank(longer.J, tolerances::kRank, false);
  EXPECT_LE(static_cast<double>(b.reductionSteps), 4.5 * static_cast<double>(a.reductionSteps))
      << a.reductionSteps << " -> " << b.reductionSteps;
}
