/// Redundant links and over-constrained loops read off the self-stresses, against the definition as written.
#include "mobility_analysis/RedundantLinks.hpp"

#include <gtest/gtest.h>

#include "core/ReferenceMethods.hpp"
#include "core/TestModels.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/ParametricFamilies.hpp"

using namespace mobility_analysis;

namespace {

std::vector<std::string> namesOf(const Mechanism& mechanism, const std::vector<bool>& flags) {
  std::vector<std::string> names;
  for (size_t l = 0; l < flags.size(); ++l) {
    if (flags[l])
      names.push_back(mechanism.links[l].name);
  }
  return names;
}

void expectSameAsRemoval(const Mechanism& mechanism, AnalysisMode mode, const std::string& name) {
  SCOPED_TRACE(name + " " + toString(mode));
  Result<AssembledMechanism> assembled = assembleMechanism(mechanism, computeTreePoses(mechanism, {}), mode);
  ASSERT_TRUE(isOk(assembled)) << diagnosticOf(assembled).toString();
  const CoordinateModel& model = valueOf(assembled).model;
  const SparseJacobian J = computeConstraintJacobian(model, valueOf(assembled).q);
  const SelfStressBasis basis = computeSelfStressBasis(mechanism, model, J, tolerances::kRank);
  EXPECT_EQ(namesOf(mechanism, findRedundantLinks(mechanism, model, basis.stresses, tolerances::kRank)),
            namesOf(mechanism, findRedundantLinksByRemoval(mechanism, model, J, tolerances::kRank)));
}

Mechanism generated(const MechanismDescription& description) {
  const GeneratorResult<std::string> urdf = toClosedLoopUrdf(description);
  Result<Mechanism> mechanism =
      loadMechanismFromString(std::get<std::string>(urdf), description.name + ".urdf");
  EXPECT_TRUE(isOk(mechanism));
  return valueOf(std::move(mechanism));
}

}  // namespace

TEST(RedundantLinks, ParallelogramWithThirdCrankHasThreeRedundantCranks) {
  // The lecture's example: any one of the three parallel cranks can go, the DOF stays 1 and the redundancy
  // drops.
  const Mechanism mechanism = loadOrFail(urdfPath("parallelogram_crank.urdf"));
  const MobilityReport report =
      analyzeOrFail(urdfPath("parallelogram_crank.urdf"), AnalysisMode::Planar).report;
  EXPECT_EQ(report.redundantLinks, (std::vector<std::string>{"crank_a", "crank_b", "pq"}));
}

TEST(RedundantLinks, RodOfAnRssrIsNotRedundant) {
  const MobilityReport report = analyzeOrFail(urdfPath("rssr.urdf"), AnalysisMode::Spatial).report;
  EXPECT_TRUE(report.redundantLinks.empty());
}

TEST(RedundantLinks, EqualTheDefinitionOnEveryBundledMechanism) {
  for (const char* file : {"four_bar.urdf", "puma560.urdf", "parallelogram_crank.urdf", "three_sliders.urdf",
                           "rppr.urdf", "bennett.urdf", "door.urdf", "sarrus.urdf", "bricard.urdf",
                           "goldberg.urdf", "rssr.urdf", "sle_mast.urdf", "hoberman_ring.urdf"}) {
    for (AnalysisMode mode : {AnalysisMode::Auto, AnalysisMode::Spatial}) {
      expectSameAsRemoval(loadOrFail(urdfPath(file)), mode, file);
    }
  }
}

TEST(RedundantLinks, EqualTheDefinitionOnTheGeneratedFamilies) {
  for (int n : {1, 3}) {
    for (AnalysisMode mode : {AnalysisMode::Planar, AnalysisMode::Spatial}) {
      expectSameAsRemoval(generated(makeSlePlanarMast(n)), mode, "sle_planar");
      expectSameAsRemoval(generated(makeHobermanRing(n + 3)), mode, "hoberman");
      expectSameAsRemoval(generated(makeParallelogramGrid(n, n + 1)), mode, "grid");
    }
    expectSameAsRemoval(generated(makeDoor(n + 1)), AnalysisMode::Spatial, "door");
    expectSameAsRemoval(generated(makeSleTriangularMast(n)), AnalysisMode::Spatial, "sle_triangular");
  }
}

TEST(RedundantLinks, LoopMembersAreTheElementsOfSomeSelfStress) {
  // Bennett: one loop, every link and joint in it; PUMA: no loop at all.
  std::vector<bool> links, joints;
  for (const char* file : {"bennett.urdf", "puma560.urdf"}) {
    const Mechanism mechanism = loadOrFail(urdfPath(file));
    Result<AssembledMechanism> assembled =
        assembleMechanism(mechanism, computeTreePoses(mechanism, {}), AnalysisMode::Spatial);
    ASSERT_TRUE(isOk(assembled));
    const CoordinateModel& model = valueOf(assembled).model;
    const SparseJacobian J = computeConstraintJacobian(model, valueOf(assembled).q);
    const SelfStressBasis basis = computeSelfStressBasis(mechanism, model, J, tolerances::kRank);
    findOverConstrainedLoops(mechanism, model, basis.stresses, links, joints);
    const bool bennett = std::string(file) == "bennett.urdf";
    for (size_t l = 0; l < links.size(); ++l)
      EXPECT_EQ(links[l], bennett) << file << " " << mechanism.links[l].name;
    for (size_t j = 0; j < joints.size(); ++j) {
      if (mechanism.joints[j].kind == ConnectionKind::TreeJoint &&
          mechanism.joints[j].type == JointType::Floating) {
        continue;
      }
      EXPECT_EQ(joints[j], bennett) << file << " " << mechanism.joints[j].name;
    }
  }
}
