/// Round trips of the core <-> message conversions (STYLE.md §6); no master needed.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "mobility_analysis/mobility_analysis.hpp"
#include "mobility_analysis/motion/Deployment.hpp"
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
    } else if (m.ns == kJointsNamespace && mechanism.joints[m.id].kind == ConnectionKind::Cable) {
      const auto cable = std::find_if(report.cables.begin(), report.cables.end(), [&](const CableState& c) {
        return c.name == mechanism.joints[m.id].name;
      });
      ASSERT_NE(cable, report.cables.end()) << "every cable is in the report";
      bool dashed = false;
      EXPECT_TRUE(sameColor(m.color, toCableColor(cable->state, report.joints[m.id].elementClass, dashed)))
          << m.id;
      EXPECT_EQ(m.type, Marker::LINE_LIST);
      EXPECT_EQ(m.points.size() > 2, dashed) << "slack dashed, else one solid segment";
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

// --- Deployable mast (urdf/sle_deployable_*.urdf): bars 1 m at elevation beta, unit height h = sin beta;
// passive_k joins a unit's left foot (0, (k-1) h) to its left top (0, k h), length sin 45 deg; active_base
// joins the ground pin (0, 0) to the slider pin (cos beta, 0). Folded beta = 10 deg, deployed 45 deg.

const double kDeg = M_PI / 180.0;

Analysed analyseMast(const std::string& which, bool lockActiveCables = false) {
  const Result<Mechanism> mechanism =
      loadMechanismFromFile(std::string(MA_URDF_DIR) + "/sle_deployable_" + which + ".urdf");
  if (!isOk(mechanism))
    ADD_FAILURE() << diagnosticOf(mechanism).toString();
  AnalysisOptions options;
  options.mode = AnalysisMode::Planar;
  options.lockActiveCables = lockActiveCables;
  const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), options);
  if (!isOk(analysis))
    ADD_FAILURE() << diagnosticOf(analysis).toString();
  return {valueOf(mechanism), valueOf(analysis)};
}

const visualization_msgs::Marker* findMarker(const visualization_msgs::MarkerArray& array,
                                             const std::string& ns, int id) {
  for (const auto& m : array.markers) {
    if (m.ns == ns && m.id == id && m.action == visualization_msgs::Marker::ADD)
      return &m;
  }
  return nullptr;
}

Eigen::Vector3d toVector(const geometry_msgs::Point& p) {
  return {p.x, p.y, p.z};
}

double saturation(const std_msgs::ColorRGBA& c) {
  return std::max({c.r, c.g, c.b}) - std::min({c.r, c.g, c.b});
}

}  // namespace

TEST(RosMessageConversion, cableColoursFollowTheirState) {
  bool dashed = true;
  EXPECT_TRUE(sameColor(toCableColor("taut", ElementClass::Redundant, dashed),
                        toColor(ElementClass::Redundant, false)));
  EXPECT_FALSE(dashed);
  EXPECT_TRUE(sameColor(toCableColor("locked", ElementClass::Neutral, dashed),
                        toColor(ElementClass::Neutral, false)));
  EXPECT_FALSE(dashed);
  const std_msgs::ColorRGBA slack = toCableColor("slack", ElementClass::Redundant, dashed);
  EXPECT_TRUE(dashed);
  EXPECT_LT(saturation(slack), 1e-6) << "slack is grey whatever the class";
  const std_msgs::ColorRGBA driving = toCableColor("driving", ElementClass::Neutral, dashed);
  EXPECT_FALSE(dashed);
  EXPECT_GT(saturation(driving), 0.5f);
}

TEST(RosMessageConversion, slackCablesAreDashedAndTautOnesSolidAtTheirPose) {
  for (const auto& [which, beta] :
       {std::pair<std::string, double>{"folded", 10.0 * kDeg}, {"deployed", 45.0 * kDeg}}) {
    SCOPED_TRACE(which);
    const Analysed a = analyseMast(which);
    const auto array = toMarkerArray(a.mechanism, a.analysis.assembled.poses, a.analysis.report);
    checkMarkers(array, a.mechanism, a.analysis.report);
    const bool taut = which == "deployed";
    for (int k = 1; k <= 4; ++k) {
      const std::string name = "passive_" + std::to_string(k);
      const std::optional<int> j = a.mechanism.findJoint(name);
      ASSERT_TRUE(j.has_value()) << name;
      const auto* m = findMarker(array, kJointsNamespace, *j);
      ASSERT_NE(m, nullptr) << name;
      ASSERT_EQ(m->type, visualization_msgs::Marker::LINE_LIST);
      // The line runs between the cable's ends, one unit height sin(beta) apart, along y.
      const Eigen::Vector3d from = toVector(m->points.front()), to = toVector(m->points.back());
      EXPECT_NEAR((to - from).norm(), std::sin(beta), 1e-9) << name;
      EXPECT_NEAR(std::abs(from.x()), 0.0, 1e-9);
      EXPECT_NEAR(std::abs(to.x()), 0.0, 1e-9);
      if (taut) {
        EXPECT_EQ(m->points.size(), 2u) << name << " taut: one solid segment";
        EXPECT_GT(saturation(m->color), 0.3f) << name << " taut: in a colour";
      } else {
        EXPECT_GT(m->points.size(), 4u) << name << " slack: dashed";
        EXPECT_LT(saturation(m->color), 1e-6) << name << " slack: grey";
        // Dashes and gaps alternate along the line: no dash covers its whole length.
        double drawn = 0.0;
        for (size_t i = 0; i + 1 < m->points.size(); i += 2)
          drawn += (toVector(m->points[i + 1]) - toVector(m->points[i])).norm();
        EXPECT_LT(drawn, 0.75 * std::sin(beta));
        EXPECT_GT(drawn, 0.4 * std::sin(beta));
      }
    }
    const std::optional<int> active = a.mechanism.findJoint("active_base");
    ASSERT_TRUE(active.has_value());
    const auto* m = findMarker(array, kJointsNamespace, *active);
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(m->points.size(), 2u) << "the driving cable is solid";
    EXPECT_NEAR((toVector(m->points[1]) - toVector(m->points[0])).norm(), std::cos(beta), 1e-9);
  }
}

TEST(RosMessageConversion, forceColoursFollowSignAndMagnitude) {
  const std_msgs::ColorRGBA tension = toForceColor(1.0, true), compression = toForceColor(-1.0, true);
  EXPECT_GT(tension.b, tension.r + 0.5f);
  EXPECT_GT(compression.r, compression.b + 0.5f);
  EXPECT_GT(toForceColor(0.5, true).b, toForceColor(0.5, true).r) << "half a tension is still blue";
  EXPECT_GT(toForceColor(-0.5, true).r, toForceColor(-0.5, true).b) << "half a compression is still red";
  EXPECT_GT(saturation(tension), saturation(toForceColor(0.5, true)));
  EXPECT_GT(saturation(toForceColor(0.5, true)), saturation(toForceColor(0.05, true)));
  EXPECT_GT(saturation(compression), saturation(toForceColor(-0.5, true)));
  const std_msgs::ColorRGBA magnitude = toForceColor(1.0, false);
  EXPECT_GT(magnitude.g, std::max(magnitude.r, magnitude.b) + 0.5f) << "links and joints: green";
  EXPECT_GT(saturation(magnitude), saturation(toForceColor(0.3, false)));
  EXPECT_TRUE(sameColor(toForceColor(7.0, true), tension)) << "clamped to [-1, 1]";
  EXPECT_TRUE(sameColor(toForceColor(std::nan(""), false), toForceColor(0.0, false))) << "nan is no force";
}

TEST(RosMessageConversion, forcesShowAStateOfTheDeployedMastOrItsPrestress) {
  // The deployed mast with its passive cables only: N - 1 = 3 states, not prestressable (all four cables
  // resist the same motion). Automatic choice: state 0.
  const Analysed free = analyseMast("deployed");
  ASSERT_EQ(free.analysis.report.selfStress.count, 3);
  ASSERT_FALSE(free.analysis.report.selfStress.prestressable);
  EXPECT_NE(
      selectForces(free.analysis.report.selfStress, kForcesAuto).title.find("state of self-stress 0 of 3"),
      std::string::npos);
  const ForcesSelection none = selectForces(free.analysis.report.selfStress, kForcesPrestress);
  EXPECT_TRUE(none.forces.empty());
  EXPECT_NE(none.title.find("no prestress"), std::string::npos);
  EXPECT_TRUE(selectForces(free.analysis.report.selfStress, 7).forces.empty());
  EXPECT_NE(selectForces(free.analysis.report.selfStress, 7).title.find("no state 7"), std::string::npos);

  const auto stateMarkers =
      toForceMarkers(free.mechanism, free.analysis.assembled.poses, free.analysis.report, kForcesAuto);
  ASSERT_FALSE(stateMarkers.empty());
  EXPECT_EQ(stateMarkers.front().id, 0) << "the legend first";
  EXPECT_EQ(stateMarkers.front().type, visualization_msgs::Marker::TEXT_VIEW_FACING);
  EXPECT_EQ(stateMarkers.size(), 1 + free.analysis.report.selfStress.states[0].elements.size())
      << "one marker per element of the state's support";
  // A state of self-stress of cables between stiff scissors: at least two cables pull against each other.
  const int links = static_cast<int>(free.mechanism.links.size());
  const int joints = static_cast<int>(free.mechanism.joints.size());
  int cables = 0;
  for (const auto& m : stateMarkers) {
    if (m.id > links && m.id <= links + joints &&
        free.mechanism.joints[m.id - 1 - links].kind == ConnectionKind::Cable) {
      EXPECT_EQ(m.type, visualization_msgs::Marker::LINE_LIST);
      EXPECT_EQ(m.points.size(), 2u);
      ++cables;
    }
  }
  EXPECT_GE(cables, 2);
  const auto invalid = toForceMarkers(free.mechanism, free.analysis.assembled.poses, free.analysis.report, 7);
  ASSERT_EQ(invalid.size(), 1u) << "only the legend, which says why";
  EXPECT_NE(invalid.front().text.find("no state 7"), std::string::npos);

  // With the active cable locked: prestressable, and the prestress puts every taut cable in tension, so every
  // cable is drawn blue, the colour of tension.
  const Analysed locked = analyseMast("deployed", true);
  ASSERT_TRUE(locked.analysis.report.selfStress.prestressable);
  EXPECT_EQ(selectForces(locked.analysis.report.selfStress, kForcesAuto).title, "prestress");
  const auto array = toMarkerArray(locked.mechanism, locked.analysis.assembled.poses, locked.analysis.report);
  checkMarkers(array, locked.mechanism, locked.analysis.report);
  const int numLinks = static_cast<int>(locked.mechanism.links.size());
  std::set<std::string> blueCables;
  int greenLinks = 0;
  for (const auto& m : array.markers) {
    if (m.ns != kForcesNamespace || m.id == 0)
      continue;
    if (m.id >= 1 + numLinks && m.id < 1 + numLinks + static_cast<int>(locked.mechanism.joints.size())) {
      const Joint& joint = locked.mechanism.joints[m.id - 1 - numLinks];
      if (joint.kind == ConnectionKind::Cable) {
        EXPECT_GT(m.color.b, m.color.r + 0.3f) << joint.name << " in tension";
        EXPECT_EQ(m.points.size(), 2u);
        blueCables.insert(joint.name);
      }
    } else if (m.id >= 1 && m.id < 1 + numLinks && m.color.g > std::max(m.color.r, m.color.b)) {
      ++greenLinks;
    }
  }
  EXPECT_EQ(blueCables,
            (std::set<std::string>{"passive_1", "passive_2", "passive_3", "passive_4", "active_base"}));
  EXPECT_GE(greenLinks, 1) << "the bars carry the prestress";
}

TEST(RosMessageConversion, deployResponseCarriesTheDeployment) {
  const Result<Mechanism> mechanism =
      loadMechanismFromFile(std::string(MA_URDF_DIR) + "/sle_deployable_folded.urdf");
  ASSERT_TRUE(isOk(mechanism));
  DeploymentOptions options;
  options.cable = "active_base";
  options.steps = 20;
  options.analysis.mode = AnalysisMode::Planar;
  const Result<MobilityAnalysis> deployed = deployMechanism(valueOf(mechanism), options);
  ASSERT_TRUE(isOk(deployed)) << diagnosticOf(deployed).toString();
  const MobilityReport& report = valueOf(deployed).report;
  ASSERT_TRUE(report.deployment.has_value());
  Deploy::Response response;
  toResponse(report, response);
  EXPECT_TRUE(response.success);
  EXPECT_TRUE(response.message.empty());
  // Closed form: the passive cables (length sin 45 deg) go taut at beta = 45 deg, where the base cable is
  // cos 45 deg long; it started at cos 10 deg.
  EXPECT_NEAR(response.initial_length, std::cos(10.0 * kDeg), 1e-12);
  EXPECT_NEAR(response.final_length, std::cos(45.0 * kDeg), 1e-7);
  EXPECT_EQ(response.final_dof, 0);
  EXPECT_EQ(response.stopped_by,
            (std::vector<std::string>{"passive_1", "passive_2", "passive_3", "passive_4"}));
  EXPECT_EQ(response.steps, static_cast<int>(report.deployment->steps.size()));
  ASSERT_EQ(response.active_lengths.size(), response.step_dof.size());
  for (size_t i = 1; i < response.active_lengths.size(); ++i)
    EXPECT_LT(response.active_lengths[i], response.active_lengths[i - 1]) << i;
  EXPECT_EQ(response.cables.size(), 5u);
  EXPECT_EQ(response.self_stress.count, 3);

  const DeploymentInfo back = fromResponse(response);
  EXPECT_EQ(back.cable, "active_base");
  EXPECT_EQ(back.stoppedBy, report.deployment->stoppedBy);
  EXPECT_EQ(back.finalLength, report.deployment->finalLength);
  EXPECT_EQ(back.finalDof, report.deployment->finalDof);
  EXPECT_EQ(back.reason, report.deployment->reason);
  ASSERT_EQ(back.steps.size(), report.deployment->steps.size());
  for (size_t i = 0; i < back.steps.size(); ++i) {
    EXPECT_EQ(back.steps[i].activeLength, report.deployment->steps[i].activeLength);
    EXPECT_EQ(back.steps[i].dof, report.deployment->steps[i].dof);
  }
}

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
