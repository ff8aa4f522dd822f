/// States of self-stress and prestress (`self_stress`): counts against the redundancy of every bundled model,
/// equilibrium of every state, and the deployable models' closed forms (virtual work along their one mode).
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "core/TestModels.hpp"
#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/SelfStressBasis.hpp"
#include "mobility_analysis/Tolerances.hpp"
#include "mobility_analysis/analysis/Prestress.hpp"
#include "mobility_analysis/analysis/SelfStressReport.hpp"
// A private header of the core: how the report compares forces.
#include "../../src/core/SignificantBits.hpp"

using namespace mobility_analysis;

namespace {

MobilityAnalysis analyze(const Mechanism& mechanism, bool lock = false) {
  AnalysisOptions options;
  options.lockActiveCables = lock;
  Result<MobilityAnalysis> analysis = analyzeMechanism(mechanism, options);
  if (!isOk(analysis)) {
    ADD_FAILURE() << diagnosticOf(analysis).toString();
    return MobilityAnalysis{};
  }
  return valueOf(std::move(analysis));
}

MobilityAnalysis analyzeFile(const std::string& file, bool lock = false) {
  return analyze(loadOrFail(urdfPath(file)), lock);
}

double forceOf(const std::vector<ElementForce>& forces, const std::string& name) {
  for (const ElementForce& f : forces) {
    if (f.name == name)
      return f.force;
  }
  return 0.0;
}

int countCables(const SelfStressState& state) {
  int n = 0;
  for (const ElementForce& f : state.elements)
    n += f.kind == "cable" ? 1 : 0;
  return n;
}

/// Recomputes the basis at the analysed pose: the multipliers the report's states are made of.
std::vector<SelfStress> basisOf(const MobilityAnalysis& analysis, const Mechanism& mechanism,
                                SparseJacobian& J) {
  J = computeConstraintJacobian(analysis.assembled.model, analysis.assembled.q);
  return toEquilibriumStresses(
      computeSelfStressBasis(mechanism, analysis.assembled.model, J, tolerances::kRank).stresses, J);
}

/// A straight chain ground pin - bar - pin - bar - taut cable - ground, stretched 1 + 1 + 1 = 3 between its
/// anchors: first-order mobile (both inner points move across the line) but rigid, and the one state of
/// self-stress pulls everything in tension, which stiffens both modes (a string in tension). With
/// @p freeCrank a pinned crank adds a real motion that no stress touches.
std::string stretchedChain(bool freeCrank) {
  std::string text = R"(<robot name="stretched_chain">
  <link name="ground"/><link name="bar1"/><link name="bar2"/>)";
  if (freeCrank)
    text += R"(<link name="crank"/>)";
  text += R"(
  <joint name="pin0" type="continuous"><parent link="ground"/><child link="bar1"/><origin xyz="0 0 0"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="pin1" type="continuous"><parent link="bar1"/><child link="bar2"/><origin xyz="1 0 0"/>
    <axis xyz="0 0 1"/></joint>)";
  if (freeCrank) {
    text += R"(
  <joint name="crank_pin" type="continuous"><parent link="ground"/><child link="crank"/><origin xyz="0 -1 0"/>
    <axis xyz="0 0 1"/></joint>)";
  }
  text += R"(
  <cable name="tie" type="passive" length="1"><link1 link="bar2" xyz="1 0 0"/><link2 link="ground" xyz="3 0 0"/></cable>
</robot>)";
  return text;
}

}  // namespace

TEST(SelfStressReport, CountsEqualRedundancyAndEveryStateIsInEquilibriumOnEveryBundledModel) {
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(MA_URDF_DIR)) {
    if (entry.path().extension() != ".urdf")
      continue;
    ++files;
    SCOPED_TRACE(entry.path().filename().string());
    const Mechanism mechanism = loadOrFail(entry.path().string());
    const MobilityAnalysis analysis = analyze(mechanism);
    const MobilityReport& report = analysis.report;
    EXPECT_EQ(report.selfStress.count, report.numRedundant);
    EXPECT_EQ(report.selfStress.count, report.numConstraints - report.rank);
    EXPECT_EQ(report.selfStress.mechanismModes, report.numCoordinates - report.rank);
    EXPECT_EQ(report.selfStress.mechanismModes, report.dof);
    EXPECT_EQ(static_cast<int>(report.selfStress.states.size()), report.selfStress.count);
    SparseJacobian J;
    const std::vector<SelfStress> stresses = basisOf(analysis, mechanism, J);
    ASSERT_EQ(static_cast<int>(stresses.size()), report.selfStress.count);
    for (size_t k = 0; k < stresses.size(); ++k) {
      const Eigen::VectorXd y = toMultipliers(stresses[k], J.rows());
      // J^T y = 0: the constraint forces of the state balance with nothing applied.
      EXPECT_LT((J.transpose() * y).cwiseAbs().maxCoeff(), 1e-9) << "state " << k;
      EXPECT_FALSE(report.selfStress.states[k].elements.empty());
      double largest = 0.0;
      for (const ElementForce& f : report.selfStress.states[k].elements) {
        EXPECT_TRUE(std::isfinite(f.force));
        largest = std::max(largest, std::abs(f.force));
      }
      EXPECT_DOUBLE_EQ(largest, 1.0) << "forces are relative to the largest";
    }
  }
  EXPECT_GE(files, 19);
}

TEST(SelfStressReport, FoldedMastIsAOneDofMechanismWithSlackCables) {
  const MobilityReport report = analyzeFile("sle_deployable_folded.urdf").report;
  EXPECT_EQ(report.dof, 1);
  EXPECT_EQ(report.selfStress.count, 0);
  EXPECT_EQ(report.selfStress.tautCables, 0);
  EXPECT_FALSE(report.selfStress.prestressable);
  for (const CableState& c : report.cables)
    EXPECT_EQ(c.state, c.type == "passive" ? "slack" : "driving") << c.name;
}

TEST(SelfStressReport, DeployedMastWithPassiveCablesHasThreeStatesAndCannotBePrestressed) {
  const MobilityReport report = analyzeFile("sle_deployable_deployed.urdf").report;
  EXPECT_EQ(report.dof, 0);
  EXPECT_EQ(report.selfStress.count, 3);
  EXPECT_EQ(report.selfStress.mechanismModes, 0);
  EXPECT_EQ(report.selfStress.tautCables, 4);
  EXPECT_FALSE(report.selfStress.prestressable);
  EXPECT_FALSE(report.selfStress.prestressStable);
  // Every passive cable lengthens at the same rate (sin beta)' along the one mode, so virtual work pairs them
  // with equal and opposite forces: each local state holds two cables, +T and -T.
  for (const SelfStressState& state : report.selfStress.states) {
    ASSERT_EQ(countCables(state), 2);
    double sum = 0.0, largest = 0.0;
    for (const ElementForce& f : state.elements) {
      if (f.kind != "cable")
        continue;
      sum += f.force;
      largest = std::max(largest, std::abs(f.force));
    }
    EXPECT_NEAR(sum, 0.0, 1e-9 * largest);
  }
}

TEST(SelfStressReport, DeployedMastWithTheActiveCableLockedIsPrestressable) {
  const MobilityReport report = analyzeFile("sle_deployable_deployed.urdf", true).report;
  EXPECT_EQ(report.dof, 0);
  EXPECT_EQ(report.selfStress.count, 4);
  EXPECT_EQ(report.selfStress.tautCables, 5);
  EXPECT_TRUE(report.selfStress.prestressable);
  EXPECT_TRUE(report.selfStress.prestressStable);
  for (const CableState& c : report.cables)
    EXPECT_EQ(c.state, c.type == "passive" ? "taut" : "locked") << c.name;
  // Virtual work along beta at 45 deg: T_base d(cos beta) + sum_k T_k d(sin beta) = 0, so
  // T_base = sum_k T_k, every tension positive.
  double passive = 0.0;
  for (int k = 1; k <= 4; ++k) {
    const double t = forceOf(report.selfStress.prestress, "passive_" + std::to_string(k));
    EXPECT_GT(t, 0.0) << k;
    passive += t;
  }
  EXPECT_NEAR(forceOf(report.selfStress.prestress, "active_base"), passive, 1e-9);
}

TEST(SelfStressReport, PrestressFromTheLinearProgramIsASelfStressWithTautCablesInTension) {
  const Mechanism mechanism = loadOrFail(urdfPath("ring_pantograph_deployed.urdf"));
  std::vector<bool> locked;
  AnalysisOptions options;
  options.lockActiveCables = true;
  const MobilityAnalysis analysis = analyze(mechanism, true);
  const Mechanism lockedMechanism = lockActiveCables(mechanism, analysis.assembled.poses, locked);
  SparseJacobian J;
  const std::vector<SelfStress> stresses = basisOf(analysis, lockedMechanism, J);
  const std::vector<int> cableRows = findTautCableRows(lockedMechanism, analysis.assembled.model);
  ASSERT_EQ(cableRows.size(), 5u);
  const CablePrestress prestress = findCablePrestress(stresses, J.rows(), cableRows);
  ASSERT_TRUE(prestress.feasible);
  EXPECT_LT((J.transpose() * prestress.multipliers).cwiseAbs().maxCoeff(), 1e-9);
  for (int row : cableRows)
    EXPECT_GT(prestress.multipliers(row), 0.0);
  // Without the locked cable the same LP finds nothing.
  const MobilityAnalysis passiveOnly = analyze(mechanism);
  SparseJacobian J2;
  const std::vector<SelfStress> stresses2 = basisOf(passiveOnly, mechanism, J2);
  const std::vector<int> rows2 = findTautCableRows(mechanism, passiveOnly.assembled.model);
  ASSERT_EQ(rows2.size(), 4u);
  EXPECT_FALSE(findCablePrestress(stresses2, J2.rows(), rows2).feasible);
}

// Locked where the free mast closes at its written pose, it is analysed from that pose, where nothing moved:
// its joint values are the written 0 exactly, as the free analysis reports them (read back off the free
// poses they were +-1e-47 rad).
TEST(SelfStressReport, LockedAtTheWrittenPoseTheJointsAreAtTheirWrittenZero) {
  const Mechanism mechanism = loadOrFail(urdfPath("sle_deployable_deployed.urdf"));
  const MobilityReport free = analyze(mechanism).report;
  const MobilityReport locked = analyze(mechanism, true).report;
  ASSERT_FALSE(locked.positions.empty());
  ASSERT_EQ(locked.positions.size(), free.positions.size());
  for (size_t j = 0; j < locked.positions.size(); ++j) {
    EXPECT_EQ(locked.positions[j].name, free.positions[j].name);
    EXPECT_EQ(locked.positions[j].value, 0.0) << locked.positions[j].name;
    EXPECT_EQ(free.positions[j].value, 0.0) << free.positions[j].name;
  }
  EXPECT_EQ(locked.assembly.iterations, 0);
  EXPECT_EQ(locked.selfStress.count, free.selfStress.count + 1);  // the locked base cable closes one more
}

// What the report compares forces by: neighbours of a power of two round together (1 and 1 - 2^-53, which a
// rounded mantissa would put a binade apart), magnitudes that differ in the digits kept keep their order, and
// the grid rounding of the prestress program's coefficients is exact on multiples of its step.
TEST(SelfStressReport, SignificantBitsRoundNeighboursTogetherAndKeepTheOrder) {
  using core_detail::roundedMagnitudeBits;
  using core_detail::roundToGrid;
  const double justBelowOne = std::nextafter(1.0, 0.0);
  EXPECT_EQ(roundedMagnitudeBits(1.0, 23), roundedMagnitudeBits(justBelowOne, 23));
  EXPECT_EQ(roundedMagnitudeBits(-0.894427191, 23), roundedMagnitudeBits(0.894427191 * (1 + 1e-15), 23));
  EXPECT_LT(roundedMagnitudeBits(0.894427191, 23), roundedMagnitudeBits(0.894427192, 23));
  EXPECT_LT(roundedMagnitudeBits(0.5, 23), roundedMagnitudeBits(1.0, 23));
  EXPECT_EQ(roundToGrid(0.75, 40), 0.75);
  EXPECT_EQ(roundToGrid(-0.3 + 1e-16, 40), roundToGrid(-0.3, 40));
  EXPECT_NEAR(roundToGrid(0.3, 40), 0.3, std::ldexp(1.0, -41));
  EXPECT_EQ(roundToGrid(std::ldexp(1.0, -50), 40), 0.0);
}

TEST(SelfStressReport, RingPantographMatchesTheMast) {
  const MobilityReport folded = analyzeFile("ring_pantograph_folded.urdf").report;
  EXPECT_EQ(folded.dof, 1);
  EXPECT_EQ(folded.selfStress.count, 4);  // the ring's own planar redundancy
  EXPECT_EQ(folded.selfStress.tautCables, 0);
  const MobilityReport deployed = analyzeFile("ring_pantograph_deployed.urdf").report;
  EXPECT_EQ(deployed.dof, 0);
  EXPECT_EQ(deployed.selfStress.count, 4 + 3);
  EXPECT_FALSE(deployed.selfStress.prestressable);
  const MobilityReport locked = analyzeFile("ring_pantograph_deployed.urdf", true).report;
  EXPECT_EQ(locked.dof, 0);
  EXPECT_EQ(locked.selfStress.count, 4 + 4);
  EXPECT_TRUE(locked.selfStress.prestressable);
  EXPECT_TRUE(locked.selfStress.prestressStable);
  // Symmetry of the ring: the four hoops carry equal tension in the prestress found.
  const double hoop = forceOf(locked.selfStress.prestress, "hoop_0");
  EXPECT_GT(hoop, 0.0);
  for (int j = 1; j < 4; ++j)
    EXPECT_NEAR(forceOf(locked.selfStress.prestress, "hoop_" + std::to_string(j)), hoop, 1e-6);
}

TEST(SelfStressReport, TensionInAStretchedChainStiffensItsFirstOrderModes) {
  Result<Mechanism> chain = loadMechanismFromString(stretchedChain(false), "stretched_chain.urdf");
  ASSERT_TRUE(isOk(chain)) << diagnosticOf(chain).toString();
  const MobilityReport report = analyze(valueOf(chain)).report;
  EXPECT_EQ(report.dof, 2);  // both inner points move across the line to first order
  EXPECT_EQ(report.selfStress.count, 1);
  EXPECT_EQ(report.selfStress.tautCables, 1);
  EXPECT_TRUE(report.selfStress.prestressable);
  EXPECT_TRUE(report.selfStress.prestressStable) << report.selfStress.stability;
  EXPECT_GT(forceOf(report.selfStress.prestress, "tie"), 0.0);

  Result<Mechanism> withCrank = loadMechanismFromString(stretchedChain(true), "stretched_chain.urdf");
  ASSERT_TRUE(isOk(withCrank)) << diagnosticOf(withCrank).toString();
  const MobilityReport crank = analyze(valueOf(withCrank)).report;
  EXPECT_EQ(crank.dof, 3);
  EXPECT_TRUE(crank.selfStress.prestressable);
  EXPECT_FALSE(crank.selfStress.prestressStable)
      << "the free crank's rotation is not stiffened by any stress";
}

TEST(SelfStressReport, JsonCarriesTheStatesAndThePrestress) {
  const std::string json = toJson(analyzeFile("sle_deployable_deployed.urdf", true).report);
  EXPECT_NE(json.find("\"self_stress\": {\"count\": 4, \"mechanism_modes\": 0"), std::string::npos) << json;
  EXPECT_NE(json.find("\"prestressable\": true"), std::string::npos);
  EXPECT_NE(json.find("\"prestress_stable\": true"), std::string::npos);
  EXPECT_EQ(json.find("nan"), std::string::npos);
  EXPECT_EQ(json.find("inf"), std::string::npos);
  const std::string text = toText(analyzeFile("sle_deployable_deployed.urdf").report);
  EXPECT_NE(text.find("s = num_constraints - rank = 75 - 72 = 3"), std::string::npos) << text;
}
