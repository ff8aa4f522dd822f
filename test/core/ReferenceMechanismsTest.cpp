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
      {"rppr.urdf", AnalysisMode::Planar, 1, 1, 0, {}, {}},
      {"bennett.urdf", AnalysisMode::Spatial, 1, -2, 3, {}, {"j4"}},
      {"bennett.urdf", AnalysisMode::Auto, 1, -2, 3, {}, {"j4"}},
      {"door.urdf", AnalysisMode::Spatial, 1, -9, 10, {}, {}},
      {"door.urdf", AnalysisMode::Planar, 1, -3, 4, {}, {}},
      {"door.urdf", AnalysisMode::Auto, 1, -3, 4, {}, {}},
      {"sarrus.urdf", AnalysisMode::Spatial, 1, 0, 1, {}, {}},
      {"bricard.urdf", AnalysisMode::Spatial, 1, 0, 1, {}, {}},
      {"goldberg.urdf", AnalysisMode::Spatial, 1, -1, 2, {}, {}},
      {"rssr.urdf", AnalysisMode::Spatial, 2, 2, 0, {}, {}},
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
