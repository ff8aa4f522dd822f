/// Round trips of the core <-> message conversions (STYLE.md §6); no master needed.

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "mobility_analysis/mobility_analysis.hpp"
#include "mobility_analysis/ros/RosConversions.hpp"

using namespace mobility_analysis;

namespace {

struct Analysed {
  Mechanism mechanism;
  MobilityAnalysis analysis;
};

Analysed analyse(const std::string& file, AnalysisMode mode) {
  const Result<Mechanism> mechanism = loadMechanismFromFile(file);
  if (!isOk(mechanism)) ADD_FAILURE() << diagnosticOf(mechanism).toString();
  AnalysisOptions options;
  options.mode = mode;
  const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), options);
  if (!isOk(analysis)) ADD_FAILURE() << diagnosticOf(analysis).toString();
  return {valueOf(mechanism), valueOf(analysis)};
}

const std::string kFourBar = std::string(MA_FIXTURE_DIR) + "/ros_four_bar.urdf";

bool sameColor(const std_msgs::ColorRGBA& a, const std_msgs::ColorRGBA& b) {
  return a.r == b.r && a.g == b.g && a.b == b.b && a.a == b.a;
}

bool isRed(const std_msgs::ColorRGBA& c) { return c.r == 1.0f && c.g == 0.0f && c.b == 0.0f; }

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
    for (const auto& p : m.points) EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    if (m.type == Marker::LINE_LIST) {
      EXPECT_EQ(m.points.size() % 2, 0u);
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
      EXPECT_NE(m.text.find("DOF " + std::to_string(report.dof) + " (Gr\xC3\xBC" "bler " +
                            std::to_string(report.grublerKutzbachDof) + "), " + std::to_string(report.numRedundant) +
                            " redundant"),
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
    if (t.header.frame_id == "mobility_world") continue;
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
  for (size_t i = 1; i < array.markers.size(); ++i) EXPECT_FALSE(isRed(array.markers[i].color)) << array.markers[i].ns;
}

TEST(RosMessageConversion, everyBundledModelGivesValidMarkers) {
  // The reference mechanisms of DESIGN.md §5: every file shipped in urdf/.
  if (!std::filesystem::is_directory(MA_URDF_DIR)) GTEST_SKIP() << "no " << MA_URDF_DIR;
  for (const auto& entry : std::filesystem::directory_iterator(MA_URDF_DIR)) {
    if (entry.path().extension() != ".urdf") continue;
    const std::string file = entry.path().string();
    SCOPED_TRACE(file);
    const Result<Mechanism> mechanism = loadMechanismFromFile(file);
    ASSERT_TRUE(isOk(mechanism)) << diagnosticOf(mechanism).toString();
    const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), AnalysisOptions{});
    ASSERT_TRUE(isOk(analysis)) << diagnosticOf(analysis).toString();
    checkMarkers(toMarkerArray(valueOf(mechanism), valueOf(analysis).assembled.poses, valueOf(analysis).report),
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
  EXPECT_NE(diagnosticOf(fromRequest(request, a.mechanism)).toString().find("1 values for 2"), std::string::npos);

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
