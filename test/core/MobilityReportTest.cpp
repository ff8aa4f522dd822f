#include "mobility_analysis/MobilityReport.hpp"

#include <limits>
#include <regex>
#include <sstream>
#include <string>
#include <variant>

#include <gtest/gtest.h>

#include "core/TestModels.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/ParametricFamilies.hpp"
// A private header of the core: toJson with its threshold for the second thread.
#include "../../src/core/JsonHalves.hpp"

using namespace mobility_analysis;

namespace {

/// The JSON without the fields that carry the unit or the file name.
std::string unitFree(std::string json) {
  // assembly.residual is in metres, the closure residuals and the rank margin's are rounding. The positions
  // stay: at the written pose they are its values exactly, in either unit.
  for (const char* key :
       {"robot", "file", "characteristic_length", "closure_residual", "rank_margin", "assembly"}) {
    json = std::regex_replace(json, std::regex(std::string("\\n  \"") + key + "\": [^\\n]*"), "");
  }
  return json;
}

}  // namespace

TEST(MobilityReport, JsonCarriesEveryDocumentedKey) {
  const MobilityReport report =
      analyzeOrFail(fixturePath("four_bar_closed.urdf"), AnalysisMode::Spatial).report;
  const std::string json = toJson(report);
  for (const char* key :
       {"\"robot\": \"four_bar\"", "\"mode\": \"spatial\"", "\"lambda\": 6", "\"dof\": 1",
        "\"grubler_kutzbach_dof\": -2",
        "\"num_coordinates\": ", "\"num_constraints\": ", "\"rank\": ", "\"nullity_trace\": [",
        "\"redundant_constraints\": [{\"index\": ", "\"source\": \"joint\", \"name\": \"j4\"",
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
  const std::string text =
      toText(analyzeOrFail(fixturePath("four_bar_closed.urdf"), AnalysisMode::Spatial).report);
  EXPECT_NE(text.find("degrees of freedom (nullity of the constraint Jacobian): 1"), std::string::npos)
      << text;
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

// A continuous-bar grid's states hold forces that agree to the last few bits (0.894427191 twice, 1 and
// 1 - 2^-53): listed in the order of those bits, the same grid written in millimetres listed them in another
// order than in metres. Forces that agree to the nine digits printed keep the order of their elements.
TEST(MobilityReport, ParallelogramGridInMillimetresAndMetresGiveTheSameReport) {
  UrdfWriterOptions noVisuals;
  noVisuals.visuals = false;
  const GeneratorResult<std::string> generated = toClosedLoopUrdf(makeParallelogramGrid(3, 4), noVisuals);
  ASSERT_TRUE(std::holds_alternative<std::string>(generated));
  const std::string metresText = std::get<std::string>(generated);
  // Every xyz in millimetres (the grid has no other length).
  std::string millimetresText;
  const std::regex xyz("xyz=\"([^\"]*)\"");
  auto from = metresText.cbegin();
  for (std::sregex_iterator it(metresText.begin(), metresText.end(), xyz), end; it != end; ++it) {
    millimetresText.append(from, (*it)[0].first);
    std::istringstream values((*it)[1].str());
    std::ostringstream scaled;
    scaled.precision(17);
    for (double v; values >> v;)
      scaled << (scaled.tellp() > 0 ? " " : "") << 1000.0 * v;
    millimetresText += "xyz=\"" + scaled.str() + "\"";
    from = (*it)[0].second;
  }
  millimetresText.append(from, metresText.cend());
  ASSERT_EQ(metresText.find("length="), std::string::npos);
  const Result<Mechanism> metres = loadMechanismFromString(metresText, "grid.urdf");
  const Result<Mechanism> millimetres = loadMechanismFromString(millimetresText, "grid_mm.urdf");
  ASSERT_TRUE(isOk(metres) && isOk(millimetres));
  const MobilityReport m = analyzeOrFail(valueOf(metres), AnalysisMode::Auto).report;
  const MobilityReport mm = analyzeOrFail(valueOf(millimetres), AnalysisMode::Auto).report;
  ASSERT_EQ(m.selfStress.count, 17);  // DOF 1 against the planar count R + C + 1 - 2RC = -16
  EXPECT_EQ(unitFree(toJson(m)), unitFree(toJson(mm)));
  EXPECT_NEAR(mm.characteristicLength / m.characteristicLength, 1000.0, 1e-6);
}

TEST(MobilityReport, ElementClassesMarkTheLoopJointRedAndTheLoopOrange) {
  const MobilityReport report =
      analyzeOrFail(fixturePath("four_bar_closed.urdf"), AnalysisMode::Spatial).report;
  for (const ElementStatus& s : report.joints) {
    EXPECT_EQ(s.elementClass, s.name == "j4" ? ElementClass::Redundant : ElementClass::OverConstrainedLoop)
        << s.name;
  }
  for (const ElementStatus& s : report.links)
    EXPECT_EQ(s.elementClass, ElementClass::OverConstrainedLoop) << s.name;
  const MobilityReport planar =
      analyzeOrFail(fixturePath("four_bar_closed.urdf"), AnalysisMode::Planar).report;
  for (const ElementStatus& s : planar.joints)
    EXPECT_EQ(s.elementClass, ElementClass::Neutral) << s.name;
}

namespace {

/// A report whose one list @p which holds @p n items and whose others are short (or empty).
MobilityReport reportWithLong(const std::string& which, size_t n) {
  MobilityReport r = analyzeOrFail(urdfPath("ring_pantograph_deployed.urdf"), AnalysisMode::Planar).report;
  for (size_t i = 0; i < n; ++i) {
    const std::string name = "e\"" + std::to_string(i);  // escaped, of growing length
    if (which == "nullity_trace")
      r.nullityTrace.push_back(static_cast<int>(i));
    if (which == "redundant_constraints")
      r.redundantConstraints.push_back(
          RedundantConstraint{static_cast<int>(i), "joint", name, "x", "x_a = x_b"});
    if (which == "links")
      r.links.push_back(ElementStatus{name, "link", "link", ElementClass::Neutral});
    if (which == "joints")
      r.joints.push_back(ElementStatus{name, "joint", "revolute", ElementClass::Redundant});
    if (which == "positions")
      r.positions.push_back(JointValue{name, 0.1 * static_cast<double>(i)});
    if (which == "states")
      r.selfStress.states.push_back(
          SelfStressState{{ElementForce{name, "link", 1.0}, ElementForce{name, "cable", -0.5}}});
    if (which == "prestress")
      r.selfStress.prestress.push_back(ElementForce{name, "cable", 1.0 / static_cast<double>(i + 1)});
  }
  return r;
}

}  // namespace

TEST(MobilityReport, JsonInTwoHalvesIsTheSameText) {
  // A large report is written in two halves on two threads (core_detail::toJson), cut at about half its
  // estimated bytes: inside whichever list holds them, or between parts. Every place the cut can fall must
  // give the one-thread text: each list made long in turn, at sizes that move the cut along it, and the
  // bundled models as they are (their cut falls between small parts).
  for (const char* which : {"nullity_trace", "redundant_constraints", "links", "joints", "positions",
                            "states", "prestress", "none"}) {
    for (size_t n : {0, 1, 2, 7, 100, 5000}) {
      SCOPED_TRACE(std::string(which) + " " + std::to_string(n));
      const MobilityReport r = reportWithLong(which, n);
      const std::string one = core_detail::toJson(r, std::numeric_limits<size_t>::max());
      EXPECT_EQ(core_detail::toJson(r, 0), one);
      EXPECT_EQ(toJson(r), one);
    }
  }
  for (const char* file : {"bennett.urdf", "sle_deployable_deployed.urdf", "door.urdf"}) {
    const MobilityReport r = analyzeOrFail(urdfPath(file), AnalysisMode::Auto).report;
    EXPECT_EQ(core_detail::toJson(r, 0), core_detail::toJson(r, std::numeric_limits<size_t>::max())) << file;
  }
}

TEST(MobilityReport, JsonWrittenToAStreamIsTheSameText) {
  // writeJson to a stream passes the text on a chunk (1 MB) at a time as it is written, on one thread or
  // with the second half made on another: the stream must receive toJson's text whatever the size, and
  // wherever a chunk ends (the 60 000 links and states here are several chunks).
  for (const char* which : {"links", "states", "positions", "none"}) {
    for (size_t n : {0, 5, 60000}) {
      SCOPED_TRACE(std::string(which) + " " + std::to_string(n));
      const MobilityReport r = reportWithLong(which, n);
      const std::string expected = core_detail::toJson(r, std::numeric_limits<size_t>::max());
      for (size_t secondThreadFrom : {size_t{0}, std::numeric_limits<size_t>::max()}) {
        std::ostringstream out;
        core_detail::writeJson(r, out, secondThreadFrom);
        EXPECT_EQ(out.str(), expected);
      }
      std::ostringstream out;
      EXPECT_FALSE(writeJson(r, out).has_value());
      EXPECT_EQ(out.str(), expected);
    }
  }
  // A report writeJson refuses: its Diagnostic, and not a byte written.
  MobilityReport bad = reportWithLong("links", 100);
  bad.characteristicLength = std::numeric_limits<double>::quiet_NaN();
  std::ostringstream out;
  const std::optional<Diagnostic> refused = writeJson(bad, out);
  ASSERT_TRUE(refused.has_value());
  EXPECT_NE(refused->what.find("characteristic_length"), std::string::npos) << refused->toString();
  EXPECT_TRUE(out.str().empty());
}
