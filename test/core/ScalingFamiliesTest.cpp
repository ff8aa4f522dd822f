/// Issue "scale": every generated family gives its closed-form DOF, Grübler count and redundancy, and the
/// ordered answer of the report equals the contract-order sparse elimination and dense Gram-Schmidt where
/// they run.
#include <functional>

#include <gtest/gtest.h>

#include "core/TestModels.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/ParametricFamilies.hpp"

using namespace mobility_analysis;

namespace {

struct Family {
  std::string name;
  std::function<MechanismDescription()> make;
  std::function<std::vector<FamilyExpectation>()> expect;
};

std::vector<Family> families() {
  std::vector<Family> list;
  for (int n : {1, 3, 8}) {
    list.push_back({"sle_planar_" + std::to_string(n), [n] { return makeSlePlanarMast(n); },
                    [n] { return expectSlePlanarMast(n); }});
    list.push_back({"hoberman_" + std::to_string(n + 3), [n] { return makeHobermanRing(n + 3); },
                    [n] { return expectHobermanRing(n + 3); }});
    list.push_back({"door_" + std::to_string(n + 1), [n] { return makeDoor(n + 1); },
                    [n] { return expectDoor(n + 1); }});
  }
  for (int n : {1, 2, 4}) {
    list.push_back({"sle_triangular_" + std::to_string(n), [n] { return makeSleTriangularMast(n); },
                    [n] { return expectSleTriangularMast(n); }});
    list.push_back({"sle_spatial_" + std::to_string(n), [n] { return makeSleSpatialMast(n); },
                    [n] { return expectSleSpatialMast(n); }});
    list.push_back({"grid_" + std::to_string(n) + "x" + std::to_string(n + 1),
                    [n] { return makeParallelogramGrid(n, n + 1); },
                    [n] { return expectParallelogramGrid(n, n + 1); }});
  }
  return list;
}

}  // namespace

TEST(ScalingFamilies, ClosedFormsHoldAndEveryMethodAgrees) {
  for (const Family& family : families()) {
    const GeneratorResult<std::string> urdf = toClosedLoopUrdf(family.make());
    ASSERT_TRUE(std::holds_alternative<std::string>(urdf)) << family.name;
    const Result<Mechanism> mechanism =
        loadMechanismFromString(std::get<std::string>(urdf), family.name + ".urdf");
    ASSERT_TRUE(isOk(mechanism)) << diagnosticOf(mechanism).toString();
    for (const FamilyExpectation& expected : family.expect()) {
      SCOPED_TRACE(family.name + " " + expected.mode);
      AnalysisOptions options;
      options.mode = expected.mode == "planar" ? AnalysisMode::Planar : AnalysisMode::Spatial;
      const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), options);
      ASSERT_TRUE(isOk(analysis)) << diagnosticOf(analysis).toString();
      const MobilityReport& report = valueOf(analysis).report;
      EXPECT_EQ(report.lambda, expected.lambda);
      EXPECT_EQ(report.dof, expected.dof);
      EXPECT_EQ(report.grublerKutzbachDof, expected.grubler);
      EXPECT_EQ(report.numRedundant, expected.redundant);
      EXPECT_EQ(report.numCoordinates - report.numConstraints, report.grublerKutzbachDof);

      // The report (self-stress basis) against the lecture's order as written: contract-order elimination,
      // and dense Gram-Schmidt where it fits.
      const AssembledMechanism& assembled = valueOf(analysis).assembled;
      const SparseJacobian J = computeConstraintJacobian(assembled.model, assembled.q);
      const OrderedRank direct = computeOrderedRank(J, tolerances::kRank, false);
      EXPECT_EQ(report.nullityTrace, direct.nullityTrace);
      std::vector<int> redundantRows;
      for (int r = 0; r < J.rows(); ++r) {
        if (direct.redundant[r])
          redundantRows.push_back(r);
      }
      std::vector<int> reported;
      for (const RedundantConstraint& c : report.redundantConstraints)
        reported.push_back(c.index);
      EXPECT_EQ(reported, redundantRows);
      if (J.rows() <= 1500) {
        const OrderedRank dense = computeOrderedRankDense(Eigen::MatrixXd(J), tolerances::kRank);
        EXPECT_EQ(direct.redundant, dense.redundant);
        EXPECT_EQ(direct.nullityTrace, dense.nullityTrace);
      }
    }
  }
}
