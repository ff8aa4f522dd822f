/// The CLI as a user runs it: exit codes, stdout only on success, one line on stderr on bad input.
#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <sys/wait.h>

#include "core/TestModels.hpp"

using namespace mobility_analysis;

namespace {

struct CliRun {
  int status;
  std::string out, err;
};

CliRun runReport(const std::string& arguments) {
  const std::string errFile = ::testing::TempDir() + "mobility_report_stderr.txt";
  const std::string command = std::string(MA_REPORT_EXE) + " " + arguments + " 2>" + errFile;
  CliRun run;
  FILE* pipe = popen(command.c_str(), "r");
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) run.out.append(buffer.data(), n);
  run.status = WEXITSTATUS(pclose(pipe));
  std::ifstream err(errFile);
  std::stringstream text;
  text << err.rdbuf();
  run.err = text.str();
  return run;
}

}  // namespace

TEST(MobilityReportCli, JsonEqualsTheCoreReport) {
  const std::string path = fixturePath("four_bar_closed.urdf");
  const CliRun run = runReport(path + " --mode spatial --json");
  EXPECT_EQ(run.status, 0) << run.err;
  EXPECT_EQ(run.out, toJson(analyzeOrFail(path, AnalysisMode::Spatial).report));
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
      {"", "no URDF file"},
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
