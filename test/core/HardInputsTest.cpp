/// Hard inputs (issue 14): the documented ranges of lengths, positions and joint values, each at its edge and
/// beyond, and the regressions found by the structured mutations and the fuzzer (test/fixtures/hard/).
///
/// The ranges (README, "Reliability"):
///   - every number read is finite and |x| <= 1e12 (m or rad) (tolerances::kMaxCoordinate);
///   - every length of a model (joint offset, anchor, cable length, a sliding coupling's offset) is at most
///   1e6
///     times the model's typical length, the median of its nonzero lengths (tolerances::kMaxRelativeLength);
///   - a driven prismatic value is at most 1e3 characteristic lengths (tolerances::kMaxDrivenTravel); a
///   driven
///     revolute value is only bounded by 1e12 rad.

#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "core/CliRun.hpp"
#include "core/JsonCheck.hpp"
#include "core/TestModels.hpp"
#include "TextFile.hpp"

namespace mobility_analysis {
namespace {

/// The error lines of a failed run (warnings, "warning: ...", aside).
int errorLines(const std::string& err) {
  std::istringstream lines(err);
  int n = 0;
  for (std::string line; std::getline(lines, line);)
    n += line.rfind("warning: ", 0) == 0 ? 0 : 1;
  return n;
}

/// Analyses @p text (read through the front door) with @p positions; the report, or the diagnostic's line.
std::string analyse(const std::string& text, const JointPositions& positions,
                    MobilityReport* report = nullptr) {
  const Result<Mechanism> m = readMechanismFromString(text, "model.urdf");
  if (!isOk(m))
    return diagnosticOf(m).toString();
  AnalysisOptions options;
  options.positions = positions;
  const Result<MobilityAnalysis> a = analyzeMechanism(valueOf(m), options);
  if (!isOk(a))
    return diagnosticOf(a).toString();
  if (report != nullptr)
    *report = valueOf(a).report;
  return "";
}

/// The parallelogram of test/fixtures/hard/far_link.urdf without its far link, plus @p extra before </robot>.
std::string parallelogramWith(const std::string& extra) {
  const std::string text = readTextFile(fixturePath("hard/far_link.urdf"));
  const size_t far = text.find("  <link name=\"far\"/>");
  return text.substr(0, far) + extra + "\n</robot>\n";
}

// --- regressions found by the structured mutations
// --------------------------------------------------------------

TEST(HardInputs, aNameThatIsNotUtf8GivesValidJson) {
  // The mutations renamed a link "\xff\xfe": the bytes went into the JSON as they were, which no parser
  // accepts.
  const CliRun run = runReport(fixturePath("hard/invalid_utf8_name.urdf") + " --json");
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_EQ(JsonCheck::check(run.out), "");
  EXPECT_NE(run.out.find("\"rocker\\ufffd\\ufffd\""), std::string::npos);
  // The parallelogram's DOF is not changed by a name.
  EXPECT_EQ(run.out.find("\"dof\": 1,") != std::string::npos, true);
}

TEST(HardInputs, aDiagnosticNamingSomethingThatIsNotUtf8IsOneLineOfText) {
  std::string text = readTextFile(fixturePath("hard/invalid_utf8_name.urdf"));
  text = std::regex_replace(text, std::regex("<link2 link=\"ground\""), "<link2 link=\"gr\xc3\x28ound\"");
  const Result<Mechanism> m = readMechanismFromString(text, "bad\xe2\x82.urdf");
  ASSERT_FALSE(isOk(m));
  const std::string line = diagnosticOf(m).toString();
  EXPECT_NE(line.find("gr\\xc3(ound"), std::string::npos) << line;
  EXPECT_NE(line.find("bad\\xe2\\x82.urdf"), std::string::npos) << line;
  // Valid UTF-8 passes unchanged.
  EXPECT_EQ(escapeForLine("\xc3\xa9l\xc3\xa9ment \xe2\x82\xac \xf0\x9f\x94\xa7"),
            "\xc3\xa9l\xc3\xa9ment \xe2\x82\xac \xf0\x9f\x94\xa7");
  // Overlong forms, surrogates and code points past U+10FFFF are not UTF-8.
  EXPECT_EQ(utf8SequenceLength("\xc0\xaf", 0), 0);
  EXPECT_EQ(utf8SequenceLength("\xed\xa0\x80", 0), 0);
  EXPECT_EQ(utf8SequenceLength("\xf4\x90\x80\x80", 0), 0);
  EXPECT_EQ(utf8SequenceLength("\xf4\x8f\xbf\xbf", 0), 4);
  EXPECT_EQ(utf8SequenceLength("\xe2\x82", 0), 0);  // cut short
}

// --- every length against the model's typical length
// -----------------------------------------------------------

TEST(LengthRange, theTypicalLengthIsTheMedianOfTheModelsNonzeroLengths) {
  // urdf/four_bar.urdf: crank 0.35, coupler 1.1, rocker 0.8, ground 1 [m]; the crank's pin is at the origin
  // (offset 0, left out). Nonzero offsets 0.35 (crank_coupler), 1.1 (coupler_rocker), 0.8 and 1 (the loop
  // joint's anchors): the lower median is 0.8.
  EXPECT_NEAR(typicalLength(loadOrFail(urdfPath("four_bar.urdf"))), 0.8, 1e-12);
  // The straight chain: every offset 0.1, however long the chain (its extent is not a length of the model).
  EXPECT_NEAR(typicalLength(valueOf(readMechanismFromString(straightChainUrdf(1000), "chain.urdf"))), 0.1,
              1e-15);
}

TEST(LengthRange, aLinkFarBeyondTheRestOfTheModelIsRefusedWithOneLine) {
  // Before: exit 0 and DOF 3 for a parallelogram (DOF 1), every number below 1e12.
  const CliRun run = runReport(fixturePath("hard/far_link.urdf") + " --json");
  EXPECT_EQ(run.status, 2);
  EXPECT_TRUE(run.out.empty());
  EXPECT_EQ(errorLines(run.err), 1) << run.err;
  EXPECT_NE(run.err.find("joint 'to_far': origin of 1e+09 m"), std::string::npos) << run.err;
  // Its offsets 0.1, 0.1 (crank, rocker), 0.3, 0.3 (coupler, ground) and the weld's: the lower median is 0.3.
  EXPECT_NE(run.err.find("typical length 0.3 m"), std::string::npos) << run.err;
}

TEST(LengthRange, theRelativeEdgeIsAcceptedWithTheRightAnswerAndJustBeyondItRefused) {
  // Offsets of the parallelogram: 0.1 (crank_coupler, the loop anchor on the rocker), 0.3 (coupler_rocker,
  // the ground anchor); with the far weld's, sorted 0.1 0.1 0.3 0.3 far, the lower median is 0.3.
  auto weld = [](const std::string& x) {
    return parallelogramWith(
        "  <link name=\"far\"/>\n  <joint name=\"to_far\" type=\"fixed\"><parent link=\"ground\"/>"
        "<child link=\"far\"/><origin xyz=\"" +
        x + " 0 0\"/></joint>");
  };
  MobilityReport report;
  ASSERT_EQ(analyse(weld("2.9e5"), {}, &report), "");  // 9.7e5 times 0.3: accepted
  EXPECT_EQ(report.dof, 1);                            // and still the parallelogram's answer
  EXPECT_EQ(report.numRedundant, 0);
  const std::string refused = analyse(weld("3.1e5"), {});  // 1.03e6 times: refused
  EXPECT_NE(refused.find("to_far"), std::string::npos) << refused;
  EXPECT_NE(refused.find("accepted up to 1e+06 times"), std::string::npos) << refused;
  // The same weld in the other direction, and as a loop joint's anchor, a distance constraint's, a cable
  // length.
  EXPECT_NE(analyse(weld("-3.1e5"), {}).find("to_far"), std::string::npos);
  const std::string anchor =
      analyse(parallelogramWith("  <distance_constraint name=\"tie\"><link1 link=\"crank\" xyz=\"0 0 0\"/>"
                                "<link2 link=\"coupler\" xyz=\"0 4e6 0\"/></distance_constraint>"),
              {});
  EXPECT_NE(anchor.find("distance_constraint 'tie': anchor on link2 of 4e+06 m"), std::string::npos)
      << anchor;
  const std::string cable = analyse(
      parallelogramWith(
          "  <cable name=\"stay\" type=\"passive\" length=\"5e6\"><link1 link=\"crank\" xyz=\"0 0 0\"/>"
          "<link2 link=\"coupler\" xyz=\"0.1 0 0\"/></cable>"),
      {});
  EXPECT_NE(cable.find("cable 'stay': length of 5e+06 m"), std::string::npos) << cable;
}

TEST(LengthRange, anMjcfBodyFarBeyondTheRestIsRefusedToo) {
  const std::string far = R"(<mujoco model="far"><worldbody>
  <body name="a"><joint name="ja" type="hinge" axis="0 0 1"/><geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.01"/>
    <body name="b" pos="0.5 0 0"><joint name="jb" type="hinge" axis="0 0 1"/><geom type="sphere" size="0.01"/></body>
  </body>
  <body name="c" pos="1e8 0 0"><joint name="jc" type="hinge" axis="0 0 1"/><geom type="sphere" size="0.01"/></body>
</worldbody></mujoco>)";
  const Result<Mechanism> m = readMechanismFromString(far, "far.xml");
  ASSERT_FALSE(isOk(m));
  EXPECT_NE(diagnosticOf(m).toString().find("1e+08 m"), std::string::npos) << diagnosticOf(m).toString();
  const Result<Mechanism> near =
      readMechanismFromString(std::regex_replace(far, std::regex("1e8"), "1e5"), "n.xml");
  EXPECT_TRUE(isOk(near)) << diagnosticOf(near).toString();
}

TEST(LengthRange, theAbsoluteEdgeHoldsForAModelThatIsAllThatBig) {
  // A two-link chain whose only length is 1e12 m: relative ratio 1, the absolute edge accepted; beyond
  // refused.
  auto chain = [](const std::string& x) {
    return "<robot name='big'><link name='a'/><link name='b'/><link name='c'/><joint name='j1' "
           "type='revolute'>"
           "<parent link='a'/><child link='b'/><origin xyz='" +
           x +
           " 0 0'/><axis xyz='0 0 1'/></joint><joint name='j2' type='revolute'><parent link='b'/>"
           "<child link='c'/><origin xyz='" +
           x + " 0 0'/><axis xyz='0 0 1'/></joint></robot>";
  };
  MobilityReport report;
  ASSERT_EQ(analyse(chain("1e12"), {}, &report), "");
  EXPECT_EQ(report.dof, 2);
  const std::string beyond = analyse(chain("1.000001e12"), {});
  EXPECT_NE(beyond.find("outside the accepted range |x| <= 1e12"), std::string::npos) << beyond;
}

// --- driven values
// ---------------------------------------------------------------------------------------------

TEST(DrivenRange, aPrismaticValueBeyondAThousandCharacteristicLengthsIsRefusedAtOnce) {
  // urdf/rppr.urdf: link2 slides along AD; slide_1 = 1e5 m ran the continuation out of steps (3 s) and was
  // reported as "stops at 1845.6 m (a dead point ...)", which it is not.
  const std::string text = readTextFile(urdfPath("rppr.urdf"));
  MobilityReport report;
  ASSERT_EQ(analyse(text, {}, &report), "");
  const double lc = report.characteristicLength;
  ASSERT_GT(lc, 0.1);
  const std::string refused = analyse(text, {{"slide_1", 1.001e3 * lc}});
  EXPECT_NE(refused.find("positions 'slide_1': value"), std::string::npos) << refused;
  EXPECT_NE(refused.find("|x| <= 1000 Lc"), std::string::npos) << refused;
  EXPECT_NE(analyse(text, {{"slide_1", -1e5}}).find("1000 Lc"), std::string::npos);
  // Inside the range the slide is reached exactly and the DOF stays 1.
  ASSERT_EQ(analyse(text, {{"slide_1", 10.0}}, &report), "");
  EXPECT_EQ(report.dof, 1);
  for (const JointValue& v : report.positions)
    if (v.name == "slide_1")
      EXPECT_EQ(v.value, 10.0);
  // Through the CLI: exit 2, one line, at once.
  const CliRun run = runReport(urdfPath("rppr.urdf") + " --positions slide_1=1e5 --json");
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(errorLines(run.err), 1) << run.err;
  EXPECT_NE(run.err.find("1000 Lc"), std::string::npos) << run.err;
}

TEST(DrivenRange, aRevoluteValueIsBoundedByTheAbsoluteRangeOnly) {
  // An angle is reduced to its representative: 1e12 rad is a valid (if odd) crank angle of the four-bar.
  MobilityReport report;
  const std::string text = readTextFile(urdfPath("four_bar.urdf"));
  ASSERT_EQ(analyse(text, {{"ground_crank", 1e12}}, &report), "");
  EXPECT_EQ(report.dof, 1);
  const Mechanism four = loadOrFail(urdfPath("four_bar.urdf"));
  const Result<JointPositions> beyond = makeJointPositions({"ground_crank"}, {1.5e12}, four);
  ASSERT_FALSE(isOk(beyond));
  EXPECT_NE(diagnosticOf(beyond).what.find("|x| <= 1e12"), std::string::npos);
}

}  // namespace
}  // namespace mobility_analysis
