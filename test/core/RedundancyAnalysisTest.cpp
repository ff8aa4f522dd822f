#include "mobility_analysis/RedundancyAnalysis.hpp"

#include <random>

#include <gtest/gtest.h>

#include "core/RandomMatrices.hpp"
#include "core/TestModels.hpp"

using namespace mobility_analysis;

namespace {

SparseJacobian toSparse(const Eigen::MatrixXd& dense) {
  return dense.sparseView();
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
