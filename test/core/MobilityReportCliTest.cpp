/// The CLI as a user runs it: exit codes, stdout only on success, one line on stderr on bad input.
#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <regex>

#include <gtest/gtest.h>
#include <sys/wait.h>

#include "core/CliRun.hpp"
#include "core/TestModels.hpp"
#include "TextFile.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/ScalingFamilies.hpp"

using namespace mobility_analysis;

TEST(MobilityReportCli, JsonEqualsTheCoreReport) {
  const std::string path = fixturePath("four_bar_closed.urdf");
  const CliRun run = runReport(path + " --mode spatial --json");
  EXPECT_EQ(run.status, 0) << run.err;
  EXPECT_EQ(run.out, toJson(analyzeOrFail(path, AnalysisMode::Spatial).report));
}

TEST(MobilityReportCli, OneThreadGivesTheSameReport) {
  // A model above the size where a second thread is used (a braced lattice of 2.3 10^4 equations): with
  // --one-thread the analysis and the JSON stay on one thread, and the report is the same, byte for byte.
  const GeneratorResult<std::string> urdf = toClosedLoopUrdf(makeBarLattice(32, 32, true));
  ASSERT_TRUE(std::holds_alternative<std::string>(urdf));
  const std::string path = ::testing::TempDir() + "braced_32_one_thread.urdf";
  std::ofstream(path) << std::get<std::string>(urdf);
  const CliRun two = runReport(path + " --json");
  const CliRun one = runReport(path + " --one-thread --json");
  EXPECT_EQ(two.status, 0) << two.err;
  EXPECT_EQ(one.status, 0) << one.err;
  EXPECT_GT(one.out.size(), 1000000u);
  EXPECT_TRUE(one.out == two.out);
}

TEST(MobilityReportCli, AReportThatCannotBeWrittenExitsTwo) {
  // The JSON goes to standard output as it is written; a full disk (/dev/full) is the user's error to see,
  // with one line and exit 2, as for bad input, not a silent exit 0 with a truncated report.
  for (const char* format : {" --json", ""}) {
    const CliRun run = runReport(fixturePath("four_bar_closed.urdf") + format + " >/dev/full");
    EXPECT_EQ(run.status, 2) << format;
    EXPECT_NE(run.err.find("could not write the report"), std::string::npos) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  }
}

TEST(MobilityReportCli, PositionsAreUsed) {
  const CliRun run = runReport(fixturePath("four_bar_closed.urdf") + " --positions j1=0.9 --json");
  EXPECT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.out.find("\"dof\": 1"), std::string::npos);
}

TEST(MobilityReportCli, BadInputExitsTwoWithOneLineAndNoReport) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {fixturePath("bad_unknown_link.urdf"), "j4"},
      {fixturePath("bad_unclosable.urdf"), "j4"},
      {fixturePath("bad_number.urdf"), "j2"},
      {fixturePath("bad_xml.urdf"), "bad_xml.urdf"},
      {fixturePath("four_bar_closed.urdf") + " --mode sideways", "sideways"},
      {fixturePath("four_bar_closed.urdf") + " --positions j4=1", "j4"},
      {fixturePath("four_bar_closed.urdf") + " --positions jx=1", "jx"},
      {fixturePath("four_bar_closed.urdf") + " --bogus", "--bogus"},
      {"/nonexistent.urdf", "nonexistent"},
      {"", "no model file"},
      {fixturePath("four_bar_closed.urdf") + " --positions j1=1e155", "outside the accepted range"},
      {fixturePath("formats/five_bar_gepetto.urdf") + " --closures /nonexistent.yaml", "nonexistent.yaml"},
      {fixturePath("formats/five_bar_gepetto.urdf") + " --closures", "--closures needs a value"},
  };
  for (const auto& [arguments, expected] : cases) {
    const CliRun run = runReport(arguments);
    EXPECT_EQ(run.status, 2) << arguments;
    EXPECT_TRUE(run.out.empty()) << arguments << ": " << run.out;
    EXPECT_NE(run.err.find(expected), std::string::npos) << arguments << ": " << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << arguments << ": " << run.err;
  }
}

TEST(MobilityReportCli, PlanarModeOnASpatialMechanismNamesTheJoint) {
  const CliRun run = runReport(urdfPath("bennett.urdf") + " --mode planar");
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.err.find("does not allow motion in the plane"), std::string::npos) << run.err;
}

namespace {

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

int jsonInt(const std::string& json, const std::string& key) {
  const size_t at = json.find("\"" + key + "\": ");
  return at == std::string::npos ? -99999 : std::stoi(json.substr(at + key.size() + 4));
}

}  // namespace

TEST(MobilityReportCli, ReadsEveryFormatThroughOneFrontDoor) {
  struct Case {
    std::string arguments;
    int dof;
  };
  const std::vector<Case> cases = {
      {fixturePath("formats/four_bar_urdfplus.urdf"), 1},
      {fixturePath("formats/four_bar_drake.urdf"), 1},
      {fixturePath("formats/six_bar_urdfplus.urdf"), 1},
      {fixturePath("formats/five_bar_gepetto.urdf") + " --closures " + fixturePath("formats/five_bar_6d.yaml"), 2},
      {fixturePath("formats/four_bar_mjcf.xml"), 1},
      {fixturePath("formats/leg_mjcf.xml"), 2},
      {fixturePath("formats/gripper_mimic.urdf") + " --mode spatial", 1},
  };
  for (const Case& c : cases) {
    const CliRun run = runReport(c.arguments + " --json --strict");
    EXPECT_EQ(run.status, 0) << c.arguments << ": " << run.err;
    EXPECT_TRUE(run.err.empty()) << run.err;
    EXPECT_EQ(jsonInt(run.out, "dof"), c.dof) << c.arguments;
  }
}

TEST(MobilityReportCli, WarningsGoToStderrAndStrictMakesThemErrors) {
  const std::string path = writeFile(
      "typo.urdf",
      "<robot name='typo'><link name='g'/><link name='a'/><link name='b'/>"
      "<joint name='ja' type='revolute'><parent link='g'/><child link='a'/><axis xyz='0 0 1'/></joint>"
      "<joint name='jb' type='revolute'><parent link='a'/><child link='b'/><origin xyz='1 0 0'/><axis xyz='0 0 1'/>"
      "</joint><loopjoint name='j4' type='revolute'><link1 link='b' xyz='1 0 0'/><link2 link='g' xyz='1 0 0'/>"
      "</loopjoint></robot>");
  const CliRun loose = runReport(path + " --json");
  EXPECT_EQ(loose.status, 0) << loose.err;
  EXPECT_EQ(loose.err.rfind("warning: typo.urdf: loopjoint 'j4': unknown element <loopjoint>", 0), 0u) << loose.err;
  EXPECT_EQ(std::count(loose.err.begin(), loose.err.end(), '\n'), 1) << loose.err;
  EXPECT_NE(loose.out.find("did you mean <loop_joint>"), std::string::npos);  // and in the JSON's warnings
  const CliRun strict = runReport(path + " --strict --json");
  EXPECT_EQ(strict.status, 2);
  EXPECT_TRUE(strict.out.empty());
  EXPECT_NE(strict.err.find("--strict"), std::string::npos) << strict.err;
  EXPECT_EQ(std::count(strict.err.begin(), strict.err.end(), '\n'), 1) << strict.err;
}

TEST(MobilityReportCli, HostileNamesAndExtremeNumbersGiveOneLine) {
  const std::string text = readTextFile(fixturePath("formats/four_bar_loop_joint.urdf"));
  const std::vector<std::string> inputs = {
      std::regex_replace(text, std::regex("xyz=\"0.4 0 0\""), "xyz=\"1 0 1e308\""),
      std::regex_replace(text, std::regex("link2 link=\"rocker\""), "link2 link=\"gro&#10;und\x01\""),
      std::regex_replace(text, std::regex("<\\?xml version=\"1.0\"\\?>"), "<?xml version=\"1.0\n\x02"),
  };
  for (size_t i = 0; i < inputs.size(); ++i) {
    const std::string path = writeFile("hostile" + std::to_string(i) + ".urdf", inputs[i]);
    const CliRun run = runReport(path + " --json");
    EXPECT_EQ(run.status, 2) << inputs[i];
    EXPECT_TRUE(run.out.empty());
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    for (size_t k = 0; k + 1 < run.err.size(); ++k)
      EXPECT_GE(static_cast<unsigned char>(run.err[k]), 0x20) << run.err;
  }
}

TEST(MobilityReportCli, AChainOfTwoHundredThousandLinksReportsItsDof) {
  // urdfdom walked the tree recursively and crashed past ~130 000 links; the reader is iterative and a tree is
  // eliminated from its leaves, so the whole report stays linear.
  constexpr int kLinks = 200000;
  const std::string text = straightChainUrdf(kLinks);
  const CliRun run = runReport(writeFile("chain.urdf", text) + " --json");
  EXPECT_EQ(run.status, 0) << run.err;
  EXPECT_EQ(jsonInt(run.out, "dof"), kLinks);
  EXPECT_EQ(jsonInt(run.out, "num_redundant"), 0);
}
