/// Issue "scale": every generated family gives its closed-form DOF, Grübler count and redundancy, and the
/// ordered answer of the report equals the contract-order sparse elimination and dense Gram-Schmidt where
/// they run.
#include <functional>

#include <gtest/gtest.h>

#include "core/TestModels.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/ParametricFamilies.hpp"
#include "mobility_analysis/generators/ScalingFamilies.hpp"

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
  // Issue 13's families at N = 3..6, with closed forms written here from the counts (not the generators'
  // expect* functions): Grübler from links and joints, DOF from the literature's argument for each.
  auto planar = [](int dof, int grubler) {
    return FamilyExpectation{"planar", 3, dof, grubler, dof - grubler};
  };
  auto spatial = [](int dof, int grubler) {
    return FamilyExpectation{"spatial", 6, dof, grubler, dof - grubler};
  };
  for (int n = 3; n <= 6; ++n) {
    const std::string tag = std::to_string(n);
    // Open chain, N + 1 links, N revolutes: 3(N + 1 − N − 1) + N = N in the plane, 6·0 + N in space.
    list.push_back({"chain_" + tag, [n] { return makeChain(n); },
                    [=] {
                      return std::vector<FamilyExpectation>{planar(n, n), spatial(n, n)};
                    }});
    list.push_back({"chain_zigzag_leaf_first_" + tag,
                    [n] { return makeChain(n, ChainShape::Zigzag, ChainOrder::LeafFirst); },
                    [=] {
                      return std::vector<FamilyExpectation>{planar(n, n), spatial(n, n)};
                    }});
    // Star: the ground, a hub and N arms, N + 1 revolutes, no loop: 3(N + 2 − (N + 1) − 1) + N + 1 = N + 1 in
    // the plane, 6·0 + N + 1 in space.
    list.push_back({"star_" + tag, [n] { return makeStar(n); },
                    [=] {
                      return std::vector<FamilyExpectation>{planar(n + 1, n + 1), spatial(n + 1, n + 1)};
                    }});
    // Ring: N links, N revolutes, one loop: 3(N − N − 1) + N = N − 3; in space 6(−1) + N = N − 6, but every
    // axis is parallel, so the loop's 3 out-of-plane equations are dependent and the DOF stays N − 3.
    list.push_back({"ring_" + tag, [n] { return makeRing(n); },
                    [=] {
                      return std::vector<FamilyExpectation>{planar(n - 3, n - 3), spatial(n - 3, n - 6)};
                    }});
    // Braced truss mast: N triangles (6 each) held by 9N struts: 6N − 9N; rigid, so 3N self-stresses.
    list.push_back({"truss_mast_" + tag, [n] { return makeTrussMast(n); },
                    [=] { return std::vector<FamilyExpectation>{spatial(0, -3 * n)}; }});
    // Ring pantograph with 2N net cables: the ring's −3 with every cable slack (folded); deployed, every
    // cable taut (−1 each) and the ring's one motion stopped.
    list.push_back({"ring_pantograph_net_folded_" + tag, [n] { return makeRingPantographNet(n, 150); },
                    [=] { return std::vector<FamilyExpectation>{planar(1, -3)}; }});
    list.push_back({"ring_pantograph_net_deployed_" + tag, [n] { return makeRingPantographNet(n, 60); },
                    [=] { return std::vector<FamilyExpectation>{planar(0, -3 - 2 * n)}; }});
  }
  for (auto [r, c] : {std::pair{3, 3}, std::pair{3, 5}, std::pair{4, 6}, std::pair{6, 4}}) {
    const std::string tag = std::to_string(r) + "x" + std::to_string(c);
    // Bar framework: n nodes, b bars, DOF 2n − b − 3 (no self-stress); as links b − 1 moving bars and 2b − n
    // pins: 3(b − 1) − 2(2b − n) = 2n − b − 3.
    const int nodes = (r + 1) * (c + 1), bars = r * (c + 1) + c * (r + 1);
    const int mechanisms = 2 * nodes - bars - 3;
    EXPECT_EQ(mechanisms, r + c - 1);  // Bolker & Crapo
    list.push_back({"bar_lattice_" + tag, [r = r, c = c] { return makeBarLattice(r, c); },
                    [=] { return std::vector<FamilyExpectation>{planar(mechanisms, mechanisms)}; }});
    // Both diagonals braced by taut cables: rigid, 2rc more distance equations.
    list.push_back({"braced_lattice_" + tag, [r = r, c = c] { return makeBarLattice(r, c, true); },
                    [=] { return std::vector<FamilyExpectation>{planar(0, mechanisms - 2 * r * c)}; }});
  }
  return list;
}

}  // namespace

TEST(ScalingFamilies, GeneratorsStateTheSameClosedForms) {
  // What the generated file says it expects (its header comment, the registry's line) is what is tested.
  for (int n = 3; n <= 6; ++n) {
    for (const auto& [m, planar, spatialG] :
         {std::tuple{makeChain(n), n, n}, std::tuple{makeStar(n), n + 1, n + 1},
          std::tuple{makeRing(n), n - 3, n - 6}}) {
      ASSERT_EQ(m.expectations.size(), 2u);
      EXPECT_EQ(m.expectations[0].grubler, planar);
      EXPECT_EQ(m.expectations[1].grubler, spatialG);
    }
    EXPECT_EQ(makeTrussMast(n).expectations.at(0).redundant, 3 * n);
    EXPECT_EQ(makeRingPantographNet(n, 60).expectations.at(0).redundant, 2 * n + 3);
    EXPECT_EQ(makeBarLattice(n, n + 1).expectations.at(0).dof, 2 * n);
    EXPECT_EQ(makeBarLattice(n, n + 1, true).expectations.at(0).redundant, 2 * n * (n + 1) - 2 * n);
  }
}

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
      // Calladine–Maxwell: the states of self-stress are the redundant equations, the modes the DOF.
      EXPECT_EQ(report.selfStress.count, expected.redundant);
      EXPECT_EQ(report.selfStress.mechanismModes, expected.dof);

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

TEST(ScalingFamilies, ClosedFormsHoldAtAThousandUnits) {
  // 10^3 links / cells / bays: every family loads and analyses, with the closed forms of the small sizes.
  struct Case {
    std::string name;
    MechanismDescription mechanism;
    AnalysisMode mode;
    int dof, grubler;
  };
  const int n = 1000;
  const std::vector<Case> cases = {
      {"chain", makeChain(n), AnalysisMode::Planar, n, n},
      {"chain zigzag leaf-first", makeChain(n, ChainShape::Zigzag, ChainOrder::LeafFirst),
       AnalysisMode::Planar, n, n},
      {"star", makeStar(n), AnalysisMode::Planar, n + 1, n + 1},
      {"star in space", makeStar(n), AnalysisMode::Spatial, n + 1, n + 1},
      {"ring", makeRing(n), AnalysisMode::Planar, n - 3, n - 3},
      {"ring in space", makeRing(n), AnalysisMode::Spatial, n - 3, n - 6},
      {"bar lattice 32x32", makeBarLattice(32, 32), AnalysisMode::Planar, 63, 63},
      {"braced lattice 32x32", makeBarLattice(32, 32, true), AnalysisMode::Planar, 0, 63 - 2 * 32 * 32},
      {"truss mast", makeTrussMast(n), AnalysisMode::Spatial, 0, -3 * n},
      {"ring pantograph net folded", makeRingPantographNet(n, 150), AnalysisMode::Planar, 1, -3},
      {"ring pantograph net deployed (200)", makeRingPantographNet(200, 60), AnalysisMode::Planar, 0,
       -3 - 400},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const GeneratorResult<std::string> urdf = toClosedLoopUrdf(c.mechanism, UrdfWriterOptions{false, ""});
    ASSERT_TRUE(std::holds_alternative<std::string>(urdf));
    const Result<Mechanism> mechanism =
        loadMechanismFromString(std::get<std::string>(urdf), c.name + ".urdf");
    ASSERT_TRUE(isOk(mechanism)) << diagnosticOf(mechanism).toString();
    AnalysisOptions options;
    options.mode = c.mode;
    const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), options);
    ASSERT_TRUE(isOk(analysis)) << diagnosticOf(analysis).toString();
    const MobilityReport& report = valueOf(analysis).report;
    EXPECT_EQ(report.dof, c.dof);
    EXPECT_EQ(report.grublerKutzbachDof, c.grubler);
    EXPECT_EQ(report.numRedundant, c.dof - c.grubler);
    EXPECT_EQ(report.selfStress.count, c.dof - c.grubler);
  }
}

TEST(ScalingFamilies, AutoModeSeesATrussMastOfDistanceConstraintsAsSpatial) {
  // The truss mast has no joint axis at all, so only its distance constraints can tell the plane test that its
  // longerons leave every plane; the braced lattice's cables lie in the plane and stay planar.
  const auto modeOf = [](const MechanismDescription& description) {
    const GeneratorResult<std::string> urdf = toClosedLoopUrdf(description);
    EXPECT_TRUE(std::holds_alternative<std::string>(urdf));
    const Result<Mechanism> mechanism = loadMechanismFromString(std::get<std::string>(urdf), "auto.urdf");
    EXPECT_TRUE(isOk(mechanism));
    const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), AnalysisOptions{});
    EXPECT_TRUE(isOk(analysis));
    return std::pair{valueOf(analysis).report.mode, valueOf(analysis).report.dof};
  };
  const auto truss = modeOf(makeTrussMast(3));
  EXPECT_EQ(truss.first, "spatial");
  EXPECT_EQ(truss.second, 0);
  const auto braced = modeOf(makeBarLattice(3, 4, true));
  EXPECT_EQ(braced.first, "planar");
  EXPECT_EQ(braced.second, 0);
}
