/// Round trips of the core <-> message conversions (STYLE.md §6); no master needed.

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "mobility_analysis/mobility_analysis.hpp"
#include "mobility_analysis/ros/DriveableJoints.hpp"
#include "mobility_analysis/ros/RosConversions.hpp"

using namespace mobility_analysis;

namespace {

struct Analysed {
  Mechanism mechanism;
  MobilityAnalysis analysis;
};

Analysed analyse(const std::string& file, AnalysisMode mode) {
  const Result<Mechanism> mechanism = loadMechanismFromFile(file);
  if (!isOk(mechanism))
    ADD_FAILURE() << diagnosticOf(mechanism).toString();
  AnalysisOptions options;
  options.mode = mode;
  const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), options);
  if (!isOk(analysis))
    ADD_FAILURE() << diagnosticOf(analysis).toString();
  return {valueOf(mechanism), valueOf(analysis)};
}

const std::string kFourBar = std::string(MA_FIXTURE_DIR) + "/ros_four_bar.urdf";

bool sameColor(const std_msgs::ColorRGBA& a, const std_msgs::ColorRGBA& b) {
  return a.r == b.r && a.g == b.g && a.b == b.b && a.a == b.a;
}

bool isRed(const std_msgs::ColorRGBA& c) {
  return c.r == 1.0f && c.g == 0.0f && c.b == 0.0f;
}

/// Checks what rviz would warn about or silently drop, and the contract of DESIGN.md §4.
void checkMarkers(const visualization_msgs::MarkerArray& array, const Mechanism& mechanism,
                  const MobilityReport& report) {
  using visualization_msgs::Marker;
  ASSERT_FALSE(array.markers.empty());
  EXPECT_EQ(array.markers.front().action, Marker::DELETEALL) << "DELETEALL must come first";
  std::set<std::pair<std::string, int>> ids;
  std::map<std::string, int> perNamespace;
  for (size_t i = 1; i < array.markers.size(); ++i) {
    const Marker& m = array.markers[i];
    SCOPED_TRACE(m.ns + "/" + std::to_string(m.id));
    EXPECT_EQ(m.action, Marker::ADD);
    EXPECT_EQ(m.header.frame_id, mechanism.links[mechanism.rootLink].name);
    EXPECT_TRUE(ids.insert({m.ns, m.id}).second) << "duplicate id";
    ++perNamespace[m.ns];
    EXPECT_GT(m.scale.x, 0.0);
    EXPECT_GT(m.scale.y, 0.0);
    EXPECT_GT(m.scale.z, 0.0);
    EXPECT_GT(m.color.a, 0.0f);
    const auto& q = m.pose.orientation;
    EXPECT_NEAR(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w, 1.0, 1e-9);
    for (const auto& p : m.points)
      EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    if (m.type == Marker::LINE_LIST) {
      EXPECT_EQ(m.points.size() % 2, 0u);
    }
  }
  // No two labels on one another: at least half a text height apart (a door and its frame share their
  // points).
  std::vector<Eigen::Vector3d> labelAt;
  double textHeight = 0.0;
  for (const Marker& m : array.markers) {
    if (m.ns != kLabelsNamespace)
      continue;
    labelAt.emplace_back(m.pose.position.x, m.pose.position.y, m.pose.position.z);
    textHeight = m.scale.z;
  }
  for (size_t a = 0; a < labelAt.size(); ++a) {
    for (size_t b = a + 1; b < labelAt.size(); ++b) {
      EXPECT_GT((labelAt[a] - labelAt[b]).norm(), 0.5 * textHeight)
          << "labels " << a << " and " << b << " overlap";
    }
  }
  const int numLinks = static_cast<int>(mechanism.links.size());
  const int numJoints = static_cast<int>(mechanism.joints.size());
  EXPECT_EQ(perNamespace[kLinksNamespace], numLinks);
  EXPECT_EQ(perNamespace[kJointsNamespace], numJoints);
  EXPECT_EQ(perNamespace[kLabelsNamespace], numLinks + numJoints);
  EXPECT_EQ(perNamespace[kTitleNamespace], 1);
  for (const Marker& m : array.markers) {
    if (m.ns == kLinksNamespace) {
      EXPECT_TRUE(sameColor(m.color, toColor(report.links[m.id].elementClass, true))) << m.id;
    } else if (m.ns == kJointsNamespace) {
      EXPECT_TRUE(sameColor(m.color, toColor(report.joints[m.id].elementClass, false)) ||
                  (mechanism.joints[m.id].type == JointType::Floating && m.color.a < 1.0f))
          << m.id;
    } else if (m.ns == kLabelsNamespace) {
      EXPECT_EQ(m.type, Marker::TEXT_VIEW_FACING);
      const bool isLink = m.id < numLinks;
      const ElementStatus& s = isLink ? report.links[m.id] : report.joints[m.id - numLinks];
      EXPECT_EQ(m.text, s.name);
      EXPECT_TRUE(sameColor(m.color, toColor(s.elementClass, isLink)));
    } else if (m.ns == kTitleNamespace) {
      EXPECT_EQ(m.type, Marker::TEXT_VIEW_FACING);
      EXPECT_NE(m.text.find("DOF " + std::to_string(report.dof) +
                            " (Gr\xC3\xBC"
                            "bler " +
                            std::to_string(report.grublerKutzbachDof) + "), " +
                            std::to_string(report.numRedundant) + " redundant"),
                std::string::npos)
          << m.text;
    }
  }
}

}  // namespace

TEST(RosMessageConversion, redundancyResponseRoundTripEqualsJson) {
  for (AnalysisMode mode : {AnalysisMode::Spatial, AnalysisMode::Planar}) {
    const Analysed a = analyse(kFourBar, mode);
    GetRedundancy::Response response;
    toResponse(a.analysis.report, response);
    EXPECT_TRUE(response.success);
    EXPECT_TRUE(response.message.empty());
    EXPECT_EQ(toJson(fromResponse(response)), toJson(a.analysis.report));
    EXPECT_EQ(response.num_redundant, response.dof - response.grubler_kutzbach_dof);
  }
}

TEST(RosMessageConversion, dofResponseCarriesTheReportFields) {
  const Analysed a = analyse(kFourBar, AnalysisMode::Spatial);
  const MobilityReport& r = a.analysis.report;
  GetDof::Response response;
  toResponse(r, response);
  EXPECT_TRUE(response.success);
  EXPECT_EQ(response.robot, r.robot);
  EXPECT_EQ(response.mode, r.mode);
  EXPECT_EQ(response.lambda, r.lambda);
  EXPECT_EQ(response.dof, 1);
  EXPECT_EQ(response.grubler_kutzbach_dof, -2);
  EXPECT_EQ(response.num_redundant, 3);
  EXPECT_EQ(response.num_coordinates, r.numCoordinates);
  EXPECT_EQ(response.num_constraints, r.numConstraints);
  EXPECT_EQ(response.rank, r.rank);
  EXPECT_EQ(std::vector<int>(response.nullity_trace.begin(), response.nullity_trace.end()), r.nullityTrace);
}

/// The four-bar's report with every field of the finite-mobility, motion and reader work set to a value that
/// differs from its default, so a field the conversions forget shows in the JSON.
MobilityReport fullReport() {
  MobilityReport r = analyse(kFourBar, AnalysisMode::Spatial).analysis.report;
  r.finiteDof = 1;
  r.singular = true;
  r.passiveDof = 1;
  r.outputDof = 0;
  r.passiveMotions = {PassiveMotion{{"coupler", "rocker"}, "rod coupler spins about its line"}};
  if (!r.redundantConstraints.empty())
    r.redundantConstraints.front().cause = "configuration";
  r.positions.push_back(JointValue{"extra", -0.123456789012345});
  r.assembly.residual = 2.5e-13;
  r.assembly.steps = 7;
  r.assembly.iterations = 19;
  r.assembly.events = {"branch point near crank_coupler = 0.5"};
  r.warnings = {"link 'ground': <inertial> ignored", "second warning"};
  return r;
}

TEST(RosMessageConversion, everyReportFieldRoundTripsThroughGetRedundancyAndLoadRobot) {
  const MobilityReport r = fullReport();
  ASSERT_FALSE(r.positions.empty());
  GetRedundancy::Response redundancy;
  toResponse(r, redundancy);
  EXPECT_EQ(toJson(fromResponse(redundancy)), toJson(r));
  ASSERT_EQ(redundancy.positions.size(), r.positions.size());
  EXPECT_EQ(redundancy.positions.back().name, "extra");
  EXPECT_EQ(redundancy.assembly.events, r.assembly.events);
  EXPECT_EQ(redundancy.redundant_constraints.front().cause, "configuration");

  LoadRobot::Response load;
  toResponse(r, load);
  EXPECT_TRUE(load.success);
  EXPECT_EQ(toJson(fromResponse(load)), toJson(r)) << "LoadRobot answers the full report";
}

TEST(RosMessageConversion, dofResponseCarriesFiniteMobilityPositionsAssemblyAndWarnings) {
  const MobilityReport r = fullReport();
  GetDof::Response response;
  toResponse(r, response);
  const MobilityReport back = fromResponse(response);
  EXPECT_EQ(back.finiteDof, r.finiteDof);
  EXPECT_EQ(back.singular, r.singular);
  EXPECT_EQ(back.passiveDof, r.passiveDof);
  EXPECT_EQ(back.outputDof, r.outputDof);
  ASSERT_EQ(back.passiveMotions.size(), 1u);
  EXPECT_EQ(back.passiveMotions[0].links, r.passiveMotions[0].links);
  EXPECT_EQ(back.passiveMotions[0].description, r.passiveMotions[0].description);
  ASSERT_EQ(back.positions.size(), r.positions.size());
  for (size_t i = 0; i < r.positions.size(); ++i) {
    EXPECT_EQ(back.positions[i].name, r.positions[i].name);
    EXPECT_EQ(back.positions[i].value, r.positions[i].value);
  }
  EXPECT_EQ(back.assembly.residual, r.assembly.residual);
  EXPECT_EQ(back.assembly.steps, r.assembly.steps);
  EXPECT_EQ(back.assembly.iterations, r.assembly.iterations);
  EXPECT_EQ(back.assembly.events, r.assembly.events);
  EXPECT_EQ(back.warnings, r.warnings);
  EXPECT_EQ(back.dof, r.dof);
  EXPECT_EQ(back.nullityTrace, r.nullityTrace);
}

TEST(RosMessageConversion, jointStateListsEveryTreeJointValueInDocumentOrder) {
  const Analysed a = analyse(kFourBar, AnalysisMode::Planar);
  const MobilityReport& r = a.analysis.report;
  const sensor_msgs::JointState state = toJointState(r, ros::Time(42, 7));
  EXPECT_EQ(state.header.stamp, ros::Time(42, 7));
  ASSERT_EQ(state.name.size(), r.positions.size());
  ASSERT_EQ(state.position.size(), r.positions.size());
  // Every 1-DOF tree joint of the file (floating and fixed ones have no single value), in document order.
  std::vector<std::string> expected;
  for (const Joint& j : a.mechanism.joints) {
    if (j.kind == ConnectionKind::TreeJoint &&
        (j.type == JointType::Revolute || j.type == JointType::Continuous ||
         j.type == JointType::Prismatic)) {
      expected.push_back(j.name);
    }
  }
  EXPECT_EQ(state.name, expected);
  for (size_t i = 0; i < r.positions.size(); ++i)
    EXPECT_EQ(state.position[i], r.positions[i].value);
}

TEST(RosMessageConversion, floatingHungLinksGetTheirTransformFromTheTreeParent) {
  // RSSR: the rod hangs from its tree parent by a floating joint, which robot_state_publisher does not
  // publish.
  const Analysed a = analyse(std::string(MA_URDF_DIR) + "/rssr.urdf", AnalysisMode::Spatial);
  const LinkPoses& poses = a.analysis.assembled.poses;
  const auto transforms =
      toTransforms(a.mechanism, poses, "mobility_world", ros::Time(0), LinkFrames::FloatingHung);
  int floating = 0;
  for (const Joint& j : a.mechanism.joints) {
    if (j.kind == ConnectionKind::TreeJoint && j.type == JointType::Floating)
      ++floating;
  }
  ASSERT_GT(floating, 0) << "rssr.urdf hangs its rod by a floating joint";
  ASSERT_EQ(transforms.size(), static_cast<size_t>(floating) + 1);
  EXPECT_EQ(transforms.front().header.frame_id, "mobility_world");
  for (size_t i = 1; i < transforms.size(); ++i) {
    const auto& t = transforms[i];
    const std::optional<int> parent = a.mechanism.findLink(t.header.frame_id);
    const std::optional<int> child = a.mechanism.findLink(t.child_frame_id);
    ASSERT_TRUE(parent && child);
    const std::optional<int> joint = a.mechanism.findParentJoint(*child);
    ASSERT_TRUE(joint);
    EXPECT_EQ(a.mechanism.joints[*joint].type, JointType::Floating);
    EXPECT_EQ(a.mechanism.joints[*joint].link1, *parent);
    EXPECT_TRUE((poses[*parent] * fromTransform(t.transform)).isApprox(poses[*child], 1e-12))
        << t.child_frame_id;
  }
}

TEST(RosMessageConversion, aLinkWithManyJointsIsAStarNotEveryPair) {
  // A ground with 40 cranks hung at 40 distinct points (and 2 more at one of them): the ground's marker joins
  // its 40 distinct points to their centroid (80 points), not every pair (1 560 points).
  Mechanism m;
  m.name = "comb";
  m.links.push_back(Link{"ground"});
  for (int i = 0; i < 42; ++i) {
    m.links.push_back(Link{"crank" + std::to_string(i)});
    Joint j;
    j.name = "pin" + std::to_string(i);
    j.type = JointType::Revolute;
    j.link1 = 0;
    j.link2 = i + 1;
    j.axis = Eigen::Vector3d::UnitZ();
    j.frame1.translation() = Eigen::Vector3d(std::min(i, 39) * 0.1, 0.0, 0.0);
    m.joints.push_back(j);
  }
  const LinkPoses poses = computeTreePoses(m, {});
  MobilityReport report;
  report.characteristicLength = 1.0;
  const auto array = toMarkerArray(m, poses, report);
  bool found = false;
  for (const auto& marker : array.markers) {
    if (marker.ns == kLinksNamespace && marker.id == 0) {
      found = true;
      EXPECT_EQ(marker.type, visualization_msgs::Marker::LINE_LIST);
      EXPECT_EQ(marker.points.size(), 80u);
    }
  }
  EXPECT_TRUE(found);
}

TEST(DriveableJoints, oneJointPerFreeDirectionInDocumentOrder) {
  // DOF 1 loops: the first tree joint drives; RSSR (DOF 2): the crank drives, the rod's spin moves no joint;
  // PUMA 560: every one of its six joints.
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"four_bar.urdf", {"ground_crank"}}, {"bennett.urdf", {"j1"}}, {"rssr.urdf", {"r1"}}};
  for (AnalysisMode mode : {AnalysisMode::Auto, AnalysisMode::Spatial}) {
    for (const auto& [file, expected] : cases) {
      SCOPED_TRACE(file);
      const Analysed a = analyse(std::string(MA_URDF_DIR) + "/" + file, mode);
      EXPECT_EQ(findDriveableJoints(a.mechanism, a.analysis), expected);
    }
  }
  const Analysed puma = analyse(std::string(MA_URDF_DIR) + "/puma560.urdf", AnalysisMode::Spatial);
  EXPECT_EQ(findDriveableJoints(puma.mechanism, puma.analysis).size(), 6u);
}

TEST(RosMessageConversion, failureCarriesTheDiagnostic) {
  LoadRobot::Response response;
  toFailure(makeDiagnostic("x.urdf", "loop_joint", "j4", "link2 'rockr' is not a link"), response);
  EXPECT_FALSE(response.success);
  EXPECT_EQ(response.message, "x.urdf: loop_joint 'j4': link2 'rockr' is not a link");
}

TEST(RosMessageConversion, poseTransformRoundTrip) {
  const Analysed a = analyse(kFourBar, AnalysisMode::Planar);
  const LinkPoses& poses = a.analysis.assembled.poses;
  const auto transforms = toTransforms(a.mechanism, poses, "mobility_world", ros::Time(0));
  ASSERT_EQ(transforms.size(), a.mechanism.links.size());  // links - root + mobility_world.
  EXPECT_EQ(transforms.front().header.frame_id, "mobility_world");
  EXPECT_EQ(transforms.front().child_frame_id, "ground");
  std::set<std::string> children;
  for (const auto& t : transforms) {
    children.insert(t.child_frame_id);
    if (t.header.frame_id == "mobility_world")
      continue;
    EXPECT_EQ(t.header.frame_id, "ground");
    const std::optional<int> link = a.mechanism.findLink(t.child_frame_id);
    ASSERT_TRUE(link.has_value());
    const Eigen::Isometry3d back = fromTransform(t.transform);
    EXPECT_TRUE(back.isApprox(poses[*link], 1e-12)) << t.child_frame_id;
  }
  EXPECT_EQ(children.size(), transforms.size());
  EXPECT_EQ(toTransforms(a.mechanism, poses, "", ros::Time(0)).size(), a.mechanism.links.size() - 1);
  EXPECT_EQ(toTransforms(a.mechanism, poses, "ground", ros::Time(0)).size(), a.mechanism.links.size() - 1);
}

TEST(RosMessageConversion, markersOverConstrainedShowRed) {
  const Analysed a = analyse(kFourBar, AnalysisMode::Spatial);
  const auto array = toMarkerArray(a.mechanism, a.analysis.assembled.poses, a.analysis.report);
  checkMarkers(array, a.mechanism, a.analysis.report);
  int red = 0;
  for (const auto& m : array.markers) {
    if (m.ns == kJointsNamespace && isRed(m.color)) {
      ++red;
      EXPECT_EQ(a.mechanism.joints[m.id].name, "j4");
    }
  }
  EXPECT_EQ(red, 1);
}

TEST(RosMessageConversion, markersExactlyConstrainedShowNoRed) {
  const Analysed a = analyse(kFourBar, AnalysisMode::Planar);
  const auto array = toMarkerArray(a.mechanism, a.analysis.assembled.poses, a.analysis.report);
  checkMarkers(array, a.mechanism, a.analysis.report);
  for (size_t i = 1; i < array.markers.size(); ++i)
    EXPECT_FALSE(isRed(array.markers[i].color)) << array.markers[i].ns;
}

TEST(RosMessageConversion, everyBundledModelGivesValidMarkers) {
  // The reference mechanisms of DESIGN.md §5: every file shipped in urdf/.
  if (!std::filesystem::is_directory(MA_URDF_DIR))
    GTEST_SKIP() << "no " << MA_URDF_DIR;
  for (const auto& entry : std::filesystem::directory_iterator(MA_URDF_DIR)) {
    if (entry.path().extension() != ".urdf")
      continue;
    const std::string file = entry.path().string();
    SCOPED_TRACE(file);
    const Result<Mechanism> mechanism = loadMechanismFromFile(file);
    ASSERT_TRUE(isOk(mechanism)) << diagnosticOf(mechanism).toString();
    const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), AnalysisOptions{});
    ASSERT_TRUE(isOk(analysis)) << diagnosticOf(analysis).toString();
    checkMarkers(
        toMarkerArray(valueOf(mechanism), valueOf(analysis).assembled.poses, valueOf(analysis).report),
        valueOf(mechanism), valueOf(analysis).report);
  }
}

TEST(RosMessageConversion, requestPositionsAreChecked) {
  const Analysed a = analyse(kFourBar, AnalysisMode::Planar);
  GetDof::Request request;
  ASSERT_TRUE(isOk(fromRequest(request, a.mechanism)));
  EXPECT_TRUE(valueOf(fromRequest(request, a.mechanism)).empty());

  request.joint_names = {"j1", "j2"};
  request.positions = {0.3};
  ASSERT_FALSE(isOk(fromRequest(request, a.mechanism)));
  EXPECT_NE(diagnosticOf(fromRequest(request, a.mechanism)).toString().find("1 values for 2"),
            std::string::npos);

  request.joint_names = {"nope"};
  ASSERT_FALSE(isOk(fromRequest(request, a.mechanism)));
  EXPECT_NE(diagnosticOf(fromRequest(request, a.mechanism)).toString().find("nope"), std::string::npos);

  request.joint_names = {"j1"};
  request.positions = {std::numeric_limits<double>::quiet_NaN()};
  ASSERT_FALSE(isOk(fromRequest(request, a.mechanism)));
  EXPECT_NE(diagnosticOf(fromRequest(request, a.mechanism)).toString().find("j1"), std::string::npos);

  GetRedundancy::Request good;
  good.joint_names = {"j1"};
  good.positions = {0.3};
  ASSERT_TRUE(isOk(fromRequest(good, a.mechanism)));
  EXPECT_DOUBLE_EQ(valueOf(fromRequest(good, a.mechanism)).at("j1"), 0.3);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
