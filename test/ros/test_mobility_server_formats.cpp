/// Integration test of the running `mobility_server` node on the loop dialects (launched by
/// test_mobility_server_formats.launch): MJCF text in robot_description is analysed as MJCF, and every URDF
/// dialect, MJCF and SDFormat text sent through ~load_robot gives its closed-form DOF, the same report as the
/// core reading the file, and its warnings (never silent).
///
/// Private parameters: ~description_file (the MJCF file the launch put in robot_description), ~server.

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include "mobility_analysis/mobility_analysis.hpp"
#include "mobility_analysis/ros/RosConversions.hpp"
#include "../TextFile.hpp"

using namespace mobility_analysis;

namespace {

constexpr double kWait = 30.0;  ///< Bound of the wait for the node's services [s].

std::string descriptionFile;
std::string server = "/mobility_server";

std::string formatPath(const std::string& name) {
  return std::string(MA_FIXTURE_DIR) + "/formats/" + name;
}

/// The report the core computes for @p text read as @p source, in @p mode.
MobilityReport coreReport(const std::string& text, const std::string& source, AnalysisMode mode) {
  const Result<Mechanism> mechanism = readMechanismFromString(text, source);
  EXPECT_TRUE(isOk(mechanism)) << diagnosticOf(mechanism).toString();
  AnalysisOptions options;
  options.mode = mode;
  const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), options);
  EXPECT_TRUE(isOk(analysis)) << diagnosticOf(analysis).toString();
  return valueOf(analysis).report;
}

/// A non-persistent service call, retried (at most twice) on a transport failure only, as in
/// test_mobility_server.cpp (ros/ros_comm#1976).
template <class Service>
bool call(const std::string& name, Service& srv) {
  for (int attempt = 0; attempt < 3; ++attempt) {
    if (ros::service::call(server + "/" + name, srv))
      return true;
  }
  return false;
}

}  // namespace

TEST(FormatsThroughTheNode, mjcfTextInRobotDescriptionIsReadAsMjcf) {
  ASSERT_TRUE(ros::service::waitForService(server + "/get_redundancy", ros::Duration(kWait)));
  GetRedundancy redundancy;
  ASSERT_TRUE(call("get_redundancy", redundancy));
  ASSERT_TRUE(redundancy.response.success) << redundancy.response.message;
  // cassie_leg_mjcf.xml's closed form: Gruebler 7, the plantar connect's out-of-plane equation redundant,
  // DOF 8.
  EXPECT_EQ(redundancy.response.robot, "cassie_leg_mjcf");
  EXPECT_EQ(redundancy.response.mode, "spatial");
  EXPECT_EQ(redundancy.response.dof, 8);
  EXPECT_EQ(redundancy.response.grubler_kutzbach_dof, 7);
  EXPECT_EQ(redundancy.response.num_redundant, 1);
  EXPECT_TRUE(redundancy.response.warnings.empty());
  MobilityReport served = fromResponse(redundancy.response);
  const MobilityReport expected =
      coreReport(readTextFile(descriptionFile), "robot_description", AnalysisMode::Auto);
  served.file = expected.file;
  EXPECT_EQ(toJson(served), toJson(expected));
}

struct DialectLoad {
  const char* file;
  const char* mode;
  AnalysisMode analysisMode;
  const char* robot;
  int dof, grubler;
};

TEST(FormatsThroughTheNode, everyUrdfDialectThroughLoadRobotGivesItsDof) {
  ASSERT_TRUE(ros::service::waitForService(server + "/load_robot", ros::Duration(kWait)));
  const std::vector<DialectLoad> loads = {
      // URDF+ <loop>: planar four-bar 3*3 - 2*4 = 1.
      {"four_bar_urdfplus.urdf", "auto", AnalysisMode::Auto, "four_bar_urdfplus", 1, 1},
      // URDF+ planar leg linkage: 3*4 - 2*5 = 2.
      {"planar_leg_linkage_urdfplus.urdf", "auto", AnalysisMode::Auto, "planar_leg_linkage_urdfplus", 2, 2},
      // Drake <loop_joint> with <limit effort> and no velocity: the four-bar in space, 6*3 - 5*4 = -2, DOF 1.
      {"four_bar_drake.urdf", "spatial", AnalysisMode::Spatial, "four_bar_drake", 1, -2},
      // <mimic> gripper: two fingers, one coupling, DOF 1.
      {"gripper_mimic.urdf", "spatial", AnalysisMode::Spatial, "gripper_mimic", 1, 1},
      // MJCF text through ~load_robot too (the same front door as robot_description).
      {"cassie_leg_mjcf.xml", "", AnalysisMode::Auto, "cassie_leg_mjcf", 8, 7},
      // SDFormat text (a cyclic joint graph): the planar five-bar, 3*4 - 2*5 = 2.
      {"five_bar.sdf", "", AnalysisMode::Auto, "five_bar_sdf", 2, 2},
  };
  for (const DialectLoad& d : loads) {
    SCOPED_TRACE(d.file);
    const std::string text = readTextFile(formatPath(d.file));
    ASSERT_FALSE(text.empty());
    LoadRobot load;
    load.request.urdf = text;
    load.request.mode = d.mode;
    ASSERT_TRUE(call("load_robot", load));
    ASSERT_TRUE(load.response.success) << load.response.message;
    EXPECT_EQ(load.response.robot, d.robot);
    EXPECT_EQ(load.response.dof, d.dof);
    EXPECT_EQ(load.response.grubler_kutzbach_dof, d.grubler);
    EXPECT_TRUE(load.response.warnings.empty()) << load.response.warnings.front();
    // The same report as the core reading the same text.
    const MobilityReport expected = coreReport(text, "load_robot", d.analysisMode);
    EXPECT_EQ(load.response.num_redundant, expected.numRedundant);
    EXPECT_EQ(load.response.num_constraints, expected.numConstraints);
    GetDof dof;
    ASSERT_TRUE(call("get_dof", dof));
    EXPECT_EQ(dof.response.robot, d.robot) << "the loaded model is the one served";
    EXPECT_EQ(dof.response.dof, d.dof);
  }
}

TEST(FormatsThroughTheNode, aMisspeltLoopElementIsAWarningInTheResponse) {
  // <loopjoint> is not read: the open tree is served (planar DOF 3), never silently: the response names it.
  std::string text = readTextFile(formatPath("four_bar_loop_joint.urdf"));
  const std::string open = "<loop_joint name", close = "</loop_joint>";
  ASSERT_NE(text.find(open), std::string::npos);
  text.replace(text.find(open), open.size(), "<loopjoint name");
  text.replace(text.find(close), close.size(), "</loopjoint>");
  LoadRobot load;
  load.request.urdf = text;
  ASSERT_TRUE(call("load_robot", load));
  ASSERT_TRUE(load.response.success) << load.response.message;
  EXPECT_EQ(load.response.dof, 3);
  ASSERT_EQ(load.response.warnings.size(), 1u);
  EXPECT_NE(load.response.warnings[0].find("did you mean <loop_joint>"), std::string::npos)
      << load.response.warnings[0];
  GetRedundancy redundancy;
  ASSERT_TRUE(call("get_redundancy", redundancy));
  ASSERT_EQ(redundancy.response.warnings.size(), 1u) << "the served report keeps its warning";
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_mobility_server_formats");
  ros::NodeHandle privateHandle("~");
  privateHandle.getParam("description_file", descriptionFile);
  privateHandle.getParam("server", server);
  return RUN_ALL_TESTS();
}
