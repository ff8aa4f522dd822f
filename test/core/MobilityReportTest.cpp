#include "mobility_analysis/MobilityReport.hpp"

#include <regex>

#include <gtest/gtest.h>

#include "core/TestModels.hpp"

using namespace mobility_analysis;

namespace {

/// The JSON without the fields that carry the unit or the file name.
std::string unitFree(std::string json) {
  // positions carry rounding noise of the pose (1e-16 rad) and assembly.residual is in metres.
  for (const char* key :
       {"robot", "file", "characteristic_length", "closure_residual", "rank_margin", "positions", "assembly"}) {
    json = std::regex_replace(json, std::regex(std::string("\\n  \"") + key + "\": [^\\n]*"), "");
  }
  return json;
}

}  // namespace

TEST(MobilityReport, JsonCarriesEveryDocumentedKey) {
  const MobilityReport report = analyzeOrFail(fixturePath("four_bar_closed.urdf"), AnalysisMode::Spatial).report;
  const std::string json = toJson(report);
  for (const char* key :
       {"\"robot\": \"four_bar\"", "\"mode\": \"spatial\"", "\"lambda\": 6", "\"dof\": 1",
        "\"grubler_kutzbach_dof\": -2", "\"num_coordinates\": ", "\"num_constraints\": ", "\"rank\": ",
        "\"nullity_trace\": [", "\"redundant_constraints\": [{\"index\": ", "\"source\": \"joint\", \"name\": \"j4\"",
        "\"redundant_joints\": [{\"name\": \"j4\", \"redundant_equations\": 3, \"equations\": 5}]",
        "\"redundant_links\": []", "\"redundant_boundaries\": []", "\"rank_margin\": {"}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << "\n" << json;
  }
  EXPECT_EQ(report.nullityTrace.size(), static_cast<size_t>(report.numConstraints));
  EXPECT_EQ(report.nullityTrace.back(), report.dof);
  EXPECT_EQ(report.rank, report.numConstraints - report.numRedundant);
}

TEST(MobilityReport, JsonEscapesNames) {
  MobilityReport report;
  report.robot = "a\"b\\c\n";
  EXPECT_NE(toJson(report).find("\"robot\": \"a\\\"b\\\\c\\n\""), std::string::npos);
}

TEST(MobilityReport, TextSaysDofGrublerAndTheRedundantJoint) {
  const std::string text = toText(analyzeOrFail(fixturePath("four_bar_closed.urdf"), AnalysisMode::Spatial).report);
  EXPECT_NE(text.find("degrees of freedom (nullity of the constraint Jacobian): 1"), std::string::npos) << text;
  EXPECT_NE(text.find("joint j4: 3 of 5 equations redundant"), std::string::npos) << text;
}

TEST(MobilityReport, BennettInMillimetresAndMetresGiveTheSameReport) {
  const MobilityReport metres = analyzeOrFail(urdfPath("bennett.urdf"), AnalysisMode::Auto).report;
  const MobilityReport millimetres = analyzeOrFail(urdfPath("bennett_mm.urdf"), AnalysisMode::Auto).report;
  EXPECT_EQ(unitFree(toJson(metres)), unitFree(toJson(millimetres)));
  EXPECT_NEAR(millimetres.characteristicLength / metres.characteristicLength, 1000.0, 1e-6);
  EXPECT_EQ(metres.dof, 1);
  EXPECT_EQ(metres.numRedundant, 3);
}

TEST(MobilityReport, ElementClassesMarkTheLoopJointRedAndTheLoopOrange) {
  const MobilityReport report = analyzeOrFail(fixturePath("four_bar_closed.urdf"), AnalysisMode::Spatial).report;
  for (const ElementStatus& s : report.joints) {
    EXPECT_EQ(s.elementClass, s.name == "j4" ? ElementClass::Redundant : ElementClass::OverConstrainedLoop) << s.name;
  }
  for (const ElementStatus& s : report.links) EXPECT_EQ(s.elementClass, ElementClass::OverConstrainedLoop) << s.name;
  const MobilityReport planar = analyzeOrFail(fixturePath("four_bar_closed.urdf"), AnalysisMode::Planar).report;
  for (const ElementStatus& s : planar.joints) EXPECT_EQ(s.elementClass, ElementClass::Neutral) << s.name;
}
