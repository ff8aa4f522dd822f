/// The reference table of DESIGN.md §5: every bundled mechanism, in every mode the table lists.
#include <gtest/gtest.h>

#include "core/TestModels.hpp"

using namespace mobility_analysis;

namespace {

struct Reference {
  const char* file;
  AnalysisMode mode;
  int dof;
  int grubler;
  int redundant;
  std::vector<std::string> redundantLinks;   ///< Exactly these (DESIGN.md §3 definition).
  std::vector<std::string> redundantJoints;  ///< When non-empty: exactly these carry the redundant equations.
  bool standard = true;                      ///< Standard joint types: coordinates - constraints == Grübler.
  int finite = -1;                           ///< finite_dof (-1: equal to dof, a regular pose).
  int passive = 0;                           ///< passive_dof (Tsai's idle groups).
  int configuration = 0;                     ///< Redundant equations whose cause is the pose.
};

std::ostream& operator<<(std::ostream& out, const Reference& r) {
  return out << r.file << " (" << toString(r.mode) << ")";
}

const std::vector<Reference>& references() {
  static const std::vector<Reference> table = {
      {"four_bar.urdf", AnalysisMode::Planar, 1, 1, 0, {}, {}},
      {"four_bar.urdf", AnalysisMode::Spatial, 1, -2, 3, {}, {"rocker_ground"}},
      {"four_bar.urdf", AnalysisMode::Auto, 1, 1, 0, {}, {}},
      {"puma560.urdf", AnalysisMode::Spatial, 6, 6, 0, {}, {}},
      {"puma560.urdf", AnalysisMode::Auto, 6, 6, 0, {}, {}},
      {"parallelogram_crank.urdf", AnalysisMode::Planar, 1, 0, 1, {"pq"}, {}},
      {"three_sliders.urdf", AnalysisMode::Planar, 1, 0, 1, {}, {}},
      // Not in the design table: in space the whole redundancy falls on the closing slide, as for any single
      // loop (each slide's twist is held by a triple product, see NaturalCoordinates).
      {"three_sliders.urdf", AnalysisMode::Spatial, 1, -3, 4, {}, {"slide_ca"}},
      {"rppr.urdf", AnalysisMode::Planar, 1, 1, 0, {}, {}, true, -1, 1},
      {"bennett.urdf", AnalysisMode::Spatial, 1, -2, 3, {}, {"j4"}},
      {"bennett.urdf", AnalysisMode::Auto, 1, -2, 3, {}, {"j4"}},
      {"door.urdf", AnalysisMode::Spatial, 1, -9, 10, {}, {}},
      {"door.urdf", AnalysisMode::Planar, 1, -3, 4, {}, {}},
      {"door.urdf", AnalysisMode::Auto, 1, -3, 4, {}, {}},
      {"sarrus.urdf", AnalysisMode::Spatial, 1, 0, 1, {}, {}},
      {"bricard.urdf", AnalysisMode::Spatial, 1, 0, 1, {}, {}},
      {"goldberg.urdf", AnalysisMode::Spatial, 1, -1, 2, {}, {}},
      {"rssr.urdf", AnalysisMode::Spatial, 2, 2, 0, {}, {}, true, -1, 1},
      // Singular poses (DESIGN.md §5): the nullity counts a first-order freedom the mechanism does not have.
      {"flattened_four_bar.urdf", AnalysisMode::Planar, 2, 1, 1, {}, {}, true, 1, 0, 1},
      {"flattened_four_bar.urdf", AnalysisMode::Auto, 2, 1, 1, {}, {}, true, 1, 0, 1},
      {"parallelogram_bifurcation.urdf", AnalysisMode::Planar, 2, 1, 1, {}, {}, true, 1, 0, 1},
      {"collinear_bars.urdf", AnalysisMode::Planar, 1, 0, 1, {}, {}, true, 0, 0, 1},
      // In space the planar loop's 3 structural redundancies stay; the pose adds the fourth.
      {"flattened_four_bar.urdf", AnalysisMode::Spatial, 2, -2, 4, {}, {}, true, 1, 0, 1},
      {"collinear_bars.urdf", AnalysisMode::Spatial, 1, -3, 4, {}, {}, true, 0, 0, 1},
      // Passive freedoms (Tsai 1999): each leg or rod spins about its own line.
      {"stewart_6sps.urdf", AnalysisMode::Spatial, 12, 12, 0, {}, {}, true, -1, 6},
      {"delta_robot.urdf", AnalysisMode::Spatial, 9, 9, 0, {}, {}, true, -1, 6},
      {"peaucellier.urdf", AnalysisMode::Planar, 1, 1, 0, {}, {}},
      {"sle_mast.urdf", AnalysisMode::Planar, 1, 1, 0, {}, {}},
      {"hoberman_ring.urdf", AnalysisMode::Planar, 1, -3, 4, {}, {}},
      // Deployable models (issue 12): a slack cable counts nothing, a taut one is a distance constraint.
      {"sle_deployable_folded.urdf", AnalysisMode::Planar, 1, 1, 0, {}, {}},
      {"sle_deployable_partly.urdf", AnalysisMode::Planar, 1, 1, 0, {}, {}},
      {"sle_deployable_deployed.urdf", AnalysisMode::Planar, 0, -3, 3, {}, {}},
      {"ring_pantograph_folded.urdf", AnalysisMode::Planar, 1, -3, 4, {}, {}},
      {"ring_pantograph_deployed.urdf", AnalysisMode::Planar, 0, -7, 7, {}, {}},
  };
  return table;
}

class ReferenceMechanism : public ::testing::TestWithParam<Reference> {};

}  // namespace

TEST_P(ReferenceMechanism, GivesItsDofGrublerCountAndRedundancy) {
  const Reference& ref = GetParam();
  const MobilityAnalysis analysis = analyzeOrFail(urdfPath(ref.file), ref.mode);
  const MobilityReport& report = analysis.report;
  EXPECT_EQ(report.dof, ref.dof);
  EXPECT_EQ(report.grublerKutzbachDof, ref.grubler);
  EXPECT_EQ(report.numRedundant, ref.redundant);
  EXPECT_EQ(report.numRedundant, report.dof - report.grublerKutzbachDof);
  if (ref.standard) {
    EXPECT_EQ(report.numCoordinates - report.numConstraints, report.grublerKutzbachDof)
        << "the model itself adds redundancy";
  }
  EXPECT_TRUE(report.redundantLinksComputed);
  for (const std::string& link : ref.redundantLinks) {
    EXPECT_NE(std::find(report.redundantLinks.begin(), report.redundantLinks.end(), link),
              report.redundantLinks.end())
        << link << " should be a redundant link";
  }
  if (!ref.redundantJoints.empty()) {
    std::vector<std::string> joints;
    for (const RedundantJoint& j : report.redundantJoints)
      joints.push_back(j.name);
    EXPECT_EQ(joints, ref.redundantJoints);
  }
  if (ref.redundant == 0) {
    EXPECT_TRUE(report.redundantLinks.empty());
    for (const ElementStatus& s : report.joints)
      EXPECT_EQ(s.elementClass, ElementClass::Neutral) << s.name;
  }
  // The loops really close at the analysed pose.
  EXPECT_LT(report.closureResidualAfter, 1e-9 * std::max(1.0, report.characteristicLength));
  EXPECT_LT(report.closureResidualBefore, 1e-9 * std::max(1.0, report.characteristicLength))
      << "the bundled file is not written closed";
  EXPECT_FALSE(report.rankMargin.nearTolerance);

  // How it really moves.
  const int finite = ref.finite < 0 ? ref.dof : ref.finite;
  EXPECT_EQ(report.finiteDof, finite);
  EXPECT_EQ(report.singular, finite != ref.dof);
  EXPECT_EQ(report.passiveDof, ref.passive);
  EXPECT_EQ(report.outputDof, finite - ref.passive);
  EXPECT_EQ(report.passiveMotions.size(), static_cast<size_t>(ref.passive));
  int configuration = 0;
  for (const RedundantConstraint& c : report.redundantConstraints)
    configuration += c.cause == "configuration" ? 1 : 0;
  EXPECT_EQ(configuration, ref.configuration);
  if (ref.configuration == ref.redundant) {
    // Only the pose makes anything dependent: no joint, link or ground constraint is called redundant.
    EXPECT_TRUE(report.redundantJoints.empty());
    EXPECT_TRUE(report.redundantLinks.empty());
    EXPECT_TRUE(report.redundantBoundaries.empty());
  }
}

INSTANTIATE_TEST_SUITE_P(DesignTable, ReferenceMechanism, ::testing::ValuesIn(references()),
                         [](const ::testing::TestParamInfo<Reference>& info) {
                           std::string name = info.param.file;
                           name = name.substr(0, name.find('.')) + "_" + toString(info.param.mode);
                           return name;
                         });

TEST(ReferenceMechanisms, SingleLoopRedundancyFallsOnTheLoopJoint) {
  const MobilityReport report = analyzeOrFail(urdfPath("bennett.urdf"), AnalysisMode::Spatial).report;
  ASSERT_EQ(report.redundantJoints.size(), 1u);
  EXPECT_EQ(report.redundantJoints[0].name, "j4");
  EXPECT_EQ(report.redundantJoints[0].redundantEquations, 3);
  EXPECT_EQ(report.redundantJoints[0].equations, 5);
  for (const RedundantConstraint& c : report.redundantConstraints) {
    EXPECT_EQ(c.source, "joint");
    EXPECT_EQ(c.name, "j4");
  }
}

TEST(ReferenceMechanisms, ExactlyConstrainedMechanismsReportNoRedundantEquation) {
  for (const char* file : {"puma560.urdf", "rssr.urdf", "sle_mast.urdf", "rppr.urdf"}) {
    const MobilityReport report = analyzeOrFail(urdfPath(file), AnalysisMode::Auto).report;
    EXPECT_EQ(report.numRedundant, 0) << file;
    EXPECT_TRUE(report.redundantConstraints.empty()) << file;
  }
  const MobilityReport fourBar = analyzeOrFail(urdfPath("four_bar.urdf"), AnalysisMode::Planar).report;
  EXPECT_EQ(fourBar.numRedundant, 0);
}

TEST(ReferenceMechanisms, RssrRodIsNotARedundantLink) {
  const MobilityReport report = analyzeOrFail(urdfPath("rssr.urdf"), AnalysisMode::Spatial).report;
  EXPECT_TRUE(report.redundantLinks.empty());
}

TEST(ReferenceMechanisms, ParallelogramThirdCrankAndEachCrankAreRedundantLinks) {
  const MobilityReport report =
      analyzeOrFail(urdfPath("parallelogram_crank.urdf"), AnalysisMode::Planar).report;
  EXPECT_NE(std::find(report.redundantLinks.begin(), report.redundantLinks.end(), "pq"),
            report.redundantLinks.end());
  // "each crank qualifies": three cranks, and the coupler does not (removing it frees the cranks).
  EXPECT_EQ(report.redundantLinks.size(), 3u);
}

TEST(ReferenceMechanisms, PassiveMotionsNameTheirGroupAndWhatItDoes) {
  const MobilityReport rssr = analyzeOrFail(urdfPath("rssr.urdf"), AnalysisMode::Spatial).report;
  ASSERT_EQ(rssr.passiveMotions.size(), 1u);
  EXPECT_EQ(rssr.passiveMotions[0].links, std::vector<std::string>{"rod"});
  EXPECT_EQ(rssr.passiveMotions[0].description,
            "link rod spins about the line through its ball joints s1 and s2");
  const MobilityReport rppr = analyzeOrFail(urdfPath("rppr.urdf"), AnalysisMode::Planar).report;
  ASSERT_EQ(rppr.passiveMotions.size(), 1u);
  EXPECT_EQ(rppr.passiveMotions[0].links, std::vector<std::string>{"link2"});
  EXPECT_EQ(rppr.passiveMotions[0].description,
            "link link2 slides along the line of its prismatic joints slide_1 and slide_2");
  // A 6-SPS leg is a chain of two links turning together.
  const MobilityReport stewart = analyzeOrFail(urdfPath("stewart_6sps.urdf"), AnalysisMode::Spatial).report;
  for (const PassiveMotion& motion : stewart.passiveMotions)
    EXPECT_EQ(motion.links.size(), 2u) << motion.description;
  // A door on its hinges and a robot's last link turn on one link only: output, not idle.
  EXPECT_EQ(analyzeOrFail(urdfPath("door.urdf"), AnalysisMode::Spatial).report.passiveDof, 0);
  EXPECT_EQ(analyzeOrFail(urdfPath("puma560.urdf"), AnalysisMode::Spatial).report.passiveDof, 0);
}
