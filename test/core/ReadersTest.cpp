/// The readers of io/: every dialect against its closed form and its hand-converted <loop_joint> twin,
/// couplings as constraints, warnings that never let a loop go silently, strictness, one-line diagnostics
/// with hostile names, extreme numbers, deep trees.
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>

#include "core/TestModels.hpp"
#include "mobility_analysis/CouplingEquation.hpp"
#include "TextFile.hpp"

using namespace mobility_analysis;

namespace {

std::string formatPath(const std::string& name) {
  return fixturePath("formats/" + name);
}

std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

Mechanism readOrFail(const std::string& path, const ReadOptions& options = {}) {
  Result<Mechanism> mechanism = readMechanism(path, options);
  if (!isOk(mechanism)) {
    ADD_FAILURE() << diagnosticOf(mechanism).toString();
    return Mechanism{};
  }
  return valueOf(std::move(mechanism));
}

MobilityReport reportOf(const Mechanism& mechanism, AnalysisMode mode, const JointPositions& positions = {}) {
  AnalysisOptions options;
  options.mode = mode;
  options.positions = positions;
  Result<MobilityAnalysis> analysis = analyzeMechanism(mechanism, options);
  if (!isOk(analysis)) {
    ADD_FAILURE() << diagnosticOf(analysis).toString();
    return MobilityReport{};
  }
  return valueOf(std::move(analysis)).report;
}

/// A one-line message: no newline, no other control character.
void expectOneLine(const std::string& line) {
  for (const char c : line) {
    EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20 || c == 0x7f) << "control character in: " << line;
  }
}

std::vector<std::string> warningTexts(const Mechanism& mechanism) {
  std::vector<std::string> texts;
  for (const Diagnostic& d : mechanism.warnings)
    texts.push_back(d.toString());
  return texts;
}

/// The one-line refusal of reading @p text as @p source; a failure of the test when it reads.
std::string refusalOf(const std::string& text, const std::string& source) {
  const Result<Mechanism> m = readMechanismFromString(text, source);
  if (isOk(m)) {
    ADD_FAILURE() << source << " was read";
    return "";
  }
  return diagnosticOf(m).toString();
}

bool anyContains(const std::vector<std::string>& texts, const std::string& a, const std::string& b = "") {
  for (const std::string& t : texts) {
    if (t.find(a) != std::string::npos && t.find(b) != std::string::npos)
      return true;
  }
  return false;
}

}  // namespace

// --- every dialect: closed form, and the same numbers as the hand-converted <loop_joint> twin
// ----------------

struct DialectCase {
  const char* file;
  const char* closures;  ///< "" for none
  AnalysisMode mode;
  const char* expectedMode;
  int dof, grubler, redundant;
  const char* twin;  ///< "" when the closed form alone is the reference
};

class EveryDialect : public ::testing::TestWithParam<DialectCase> {};

TEST_P(EveryDialect, GivesItsClosedFormDofAndTheNumbersOfItsLoopJointTwin) {
  const DialectCase& c = GetParam();
  ReadOptions options;
  if (*c.closures != '\0')
    options.closuresFile = formatPath(c.closures);
  const Mechanism mechanism = readOrFail(formatPath(c.file), options);
  EXPECT_TRUE(mechanism.warnings.empty()) << mechanism.warnings.front().toString();
  const MobilityReport report = reportOf(mechanism, c.mode);
  EXPECT_EQ(report.mode, c.expectedMode);
  EXPECT_EQ(report.dof, c.dof);
  EXPECT_EQ(report.grublerKutzbachDof, c.grubler);
  EXPECT_EQ(report.numRedundant, c.redundant);
  if (*c.twin != '\0') {
    const MobilityReport twin = reportOf(readOrFail(formatPath(c.twin)), c.mode);
    EXPECT_EQ(twin.dof, report.dof);
    EXPECT_EQ(twin.grublerKutzbachDof, report.grublerKutzbachDof);
    EXPECT_EQ(twin.numRedundant, report.numRedundant);
    EXPECT_EQ(twin.numCoordinates, report.numCoordinates);
    EXPECT_EQ(twin.numConstraints, report.numConstraints);
  }
}

// Planar four-bar: DOF 1, Gruebler 3*3 - 2*4 = 1; in space 6*3 - 5*4 = -2 with 3 redundant. Watt six-bar:
// 3*5 - 2*7 = 1; in space 6*5 - 5*7 = -5, 6 redundant. Five-bar closed by a 6d frame: 3*6 - 2*5 - 3 - 3 = 2.
INSTANTIATE_TEST_SUITE_P(
    Formats, EveryDialect,
    ::testing::Values(
        DialectCase{"four_bar_urdfplus.urdf", "", AnalysisMode::Auto, "planar", 1, 1, 0,
                    "four_bar_loop_joint.urdf"},
        DialectCase{"four_bar_urdfplus.urdf", "", AnalysisMode::Spatial, "spatial", 1, -2, 3,
                    "four_bar_loop_joint.urdf"},
        DialectCase{"six_bar_urdfplus.urdf", "", AnalysisMode::Auto, "planar", 1, 1, 0,
                    "six_bar_loop_joint.urdf"},
        DialectCase{"six_bar_urdfplus.urdf", "", AnalysisMode::Spatial, "spatial", 1, -5, 6,
                    "six_bar_loop_joint.urdf"},
        DialectCase{"four_bar_drake.urdf", "", AnalysisMode::Auto, "planar", 1, 1, 0,
                    "four_bar_loop_joint.urdf"},
        DialectCase{"four_bar_drake.urdf", "", AnalysisMode::Spatial, "spatial", 1, -2, 3,
                    "four_bar_loop_joint.urdf"},
        DialectCase{"five_bar_gepetto.urdf", "five_bar_6d.yaml", AnalysisMode::Auto, "planar", 2, 2, 0,
                    "five_bar_loop_joint.urdf"},
        // Two 6d closures (a Watt six-bar with its closure frames on pins): the six-bar's numbers.
        DialectCase{"six_bar_gepetto.urdf", "six_bar_6d.yaml", AnalysisMode::Auto, "planar", 1, 1, 0, ""},
        DialectCase{"six_bar_gepetto.urdf", "six_bar_6d.yaml", AnalysisMode::Spatial, "spatial", 1, -5, 6,
                    ""},
        // 3d: a ball at C, so in space: the five-bar's 2 plus closure_B spinning on its pin; 6*6-25-6-3 = 2.
        DialectCase{"five_bar_gepetto.urdf", "five_bar_3d.yaml", AnalysisMode::Auto, "spatial", 3, 2, 1, ""},
        // Drake's <drake:ball_constraint>: a ball, as the MJCF connect below.
        DialectCase{"four_bar_drake_ball.urdf", "", AnalysisMode::Auto, "spatial", 1, 0, 1,
                    "four_bar_ball_loop_joint.urdf"},
        DialectCase{"four_bar_drake_ball.sdf", "", AnalysisMode::Auto, "spatial", 1, 0, 1,
                    "four_bar_ball_loop_joint.urdf"},
        // MJCF connect is a ball: 6*3 - 5*3 - 3 = 0, the planar motion makes one equation redundant.
        DialectCase{"four_bar_mjcf.xml", "", AnalysisMode::Auto, "spatial", 1, 0, 1,
                    "four_bar_ball_loop_joint.urdf"},
        // Cassie-like leg: hip-knee four-bar through the Achilles rod (1) + the rod's spin (1); 36 - 34 = 2.
        DialectCase{"leg_mjcf.xml", "", AnalysisMode::Auto, "spatial", 2, 2, 0, ""},
        // Couplings: tree minus one.
        DialectCase{"gripper_mimic.urdf", "", AnalysisMode::Spatial, "spatial", 1, 1, 0, ""},
        DialectCase{"gripper_revolute_mimic.urdf", "", AnalysisMode::Auto, "planar", 1, 1, 0, ""},
        DialectCase{"gears_urdfplus.urdf", "", AnalysisMode::Auto, "planar", 1, 1, 0, ""},
        // URDF+ planar leg linkage (hip + a parallelogram knee carrying the foot): 3*4 - 2*5 = 2; in space
        // 6*4 - 5*5 = -1, the one planar loop's 3 equations redundant.
        DialectCase{"planar_leg_linkage_urdfplus.urdf", "", AnalysisMode::Auto, "planar", 2, 2, 0,
                    "planar_leg_linkage_loop_joint.urdf"},
        DialectCase{"planar_leg_linkage_urdfplus.urdf", "", AnalysisMode::Spatial, "spatial", 2, -1, 3,
                    "planar_leg_linkage_loop_joint.urdf"},
        // Gepetto Delta, balls as three revolutes, five 3d closures: 24 - 15 = 9 (3 translations + 6 spins).
        DialectCase{"delta_gepetto.urdf", "delta_3d.yaml", AnalysisMode::Auto, "spatial", 9, 9, 0,
                    "delta_loop_joint.urdf"},
        // Gepetto Cassie-like leg, rods cut in halves welded by two 6d closures: 19 - 12 = 7 (5 motors + 2
        // spins).
        DialectCase{"cassie_leg_gepetto.urdf", "cassie_leg_6d.yaml", AnalysisMode::Auto, "spatial", 7, 7, 0,
                    "cassie_leg_loop_joint.urdf"},
        // MJCF leg with agility_cassie's topology: Gruebler 7, the plantar four-bar closed by a ball makes
        // one equation redundant: DOF 8.
        DialectCase{"cassie_leg_mjcf.xml", "", AnalysisMode::Auto, "spatial", 8, 7, 1,
                    "cassie_leg_mjcf_loop_joint.urdf"},
        // SDFormat: loops as a cyclic joint graph. Four-bar 3*3 - 2*4 = 1 (space: 6*3 - 5*4 = -2, 3
        // redundant); five-bar 3*4 - 2*5 = 2 (space: 6*4 - 5*5 = -1, 3 redundant).
        DialectCase{"four_bar.sdf", "", AnalysisMode::Auto, "planar", 1, 1, 0, "four_bar_loop_joint.urdf"},
        DialectCase{"four_bar.sdf", "", AnalysisMode::Spatial, "spatial", 1, -2, 3,
                    "four_bar_loop_joint.urdf"},
        DialectCase{"five_bar.sdf", "", AnalysisMode::Auto, "planar", 2, 2, 0,
                    "five_bar_sdf_loop_joint.urdf"},
        DialectCase{"five_bar.sdf", "", AnalysisMode::Spatial, "spatial", 2, -1, 3,
                    "five_bar_sdf_loop_joint.urdf"}),
    [](const ::testing::TestParamInfo<DialectCase>& info) {
      std::string name = std::string(info.param.file) + "_" + info.param.closures + "_" +
                         (info.param.mode == AnalysisMode::Spatial ? "spatial" : "auto");
      return std::regex_replace(name, std::regex("[^A-Za-z0-9]"), "_");
    });

TEST(Readers, WithoutItsLoopsEachModelIsTheOpenTreeItWouldBeAnalysedAsToday) {
  // The issue's complaint: loops dropped silently give the tree's DOF. Our readers give these only when the
  // loop really is absent (the loop text removed), and then nothing warns.
  std::string plus = readTextFile(formatPath("four_bar_urdfplus.urdf"));
  plus = std::regex_replace(plus, std::regex("<loop [\\s\\S]*</loop>"), "");
  const Result<Mechanism> tree = readMechanismFromString(plus, "tree.urdf");
  ASSERT_TRUE(isOk(tree));
  EXPECT_EQ(reportOf(valueOf(tree), AnalysisMode::Auto).dof, 3);
  EXPECT_EQ(reportOf(readOrFail(formatPath("five_bar_gepetto.urdf")), AnalysisMode::Auto).dof, 5);
  std::string gripper = readTextFile(formatPath("gripper_mimic.urdf"));
  gripper = std::regex_replace(gripper, std::regex("<mimic[^>]*/>"), "");
  EXPECT_EQ(reportOf(valueOf(readMechanismFromString(gripper, "g.urdf")), AnalysisMode::Spatial).dof, 2);
  // The Gepetto trees without their closure files: the Delta's 3 motors + 7 balls * 3, the Cassie-like
  // leg's 7 revolutes + 4 balls * 3 (the issue's "19 instead of 7").
  EXPECT_EQ(reportOf(readOrFail(formatPath("delta_gepetto.urdf")), AnalysisMode::Auto).dof, 24);
  EXPECT_EQ(reportOf(readOrFail(formatPath("cassie_leg_gepetto.urdf")), AnalysisMode::Auto).dof, 19);
}

TEST(Readers, GepettoDeltaHasTheDofOfTheReferenceDelta) {
  // The same Delta (geometry of urdf/delta_robot.urdf, DESIGN.md 5) written with ball-jointed rods and
  // floating platform there, with three-revolute balls and 3d closures here: the same DOF and Gruebler.
  ReadOptions options;
  options.closuresFile = formatPath("delta_3d.yaml");
  const MobilityReport gepetto =
      reportOf(readOrFail(formatPath("delta_gepetto.urdf"), options), AnalysisMode::Auto);
  const MobilityReport reference = reportOf(readOrFail(urdfPath("delta_robot.urdf")), AnalysisMode::Auto);
  EXPECT_EQ(reference.dof, 9);
  EXPECT_EQ(gepetto.dof, reference.dof);
  EXPECT_EQ(gepetto.grublerKutzbachDof, reference.grublerKutzbachDof);
  EXPECT_EQ(gepetto.numRedundant, reference.numRedundant);
}

TEST(Readers, MjcfCassieLegNamesItsRedundantConnectAndItsSpinningRod) {
  // The plantar four-bar is planar: its ball closure's out-of-plane equation is the redundant one; the
  // Achilles rod, between a ball joint and a connect, spins about its own line.
  const MobilityReport r = reportOf(readOrFail(formatPath("cassie_leg_mjcf.xml")), AnalysisMode::Auto);
  ASSERT_EQ(r.redundantJoints.size(), 1u);
  EXPECT_EQ(r.redundantJoints[0].name, "plantar");
  EXPECT_EQ(r.passiveDof, 1);
  ASSERT_EQ(r.passiveMotions.size(), 1u);
  EXPECT_EQ(r.passiveMotions[0].links, std::vector<std::string>{"achilles_rod"});
}

TEST(Readers, UrdfPlusLoopIsReadLikeALoopJoint) {
  const Mechanism m = readOrFail(formatPath("four_bar_urdfplus.urdf"));
  const Joint& loop = m.joints.back();
  EXPECT_EQ(loop.kind, ConnectionKind::LoopJoint);
  EXPECT_EQ(loop.type, JointType::Revolute);
  EXPECT_EQ(m.links[loop.link1].name, "coupler");
  EXPECT_EQ(m.links[loop.link2].name, "rocker");
  EXPECT_TRUE(loop.frame1.translation().isApprox(Eigen::Vector3d(0.4, 0.1, 0)));
  EXPECT_TRUE(loop.frame2.translation().isApprox(Eigen::Vector3d(0, 0.3, 0)));
  EXPECT_TRUE(loop.axis.isApprox(Eigen::Vector3d::UnitZ()));
}

TEST(Readers, MjcfBodiesJointsAndEqualitiesMeanWhatMujocoMeans) {
  const Mechanism m = readOrFail(formatPath("leg_mjcf.xml"));
  EXPECT_EQ(m.name, "leg_mjcf");
  EXPECT_EQ(m.links[m.rootLink].name, "world");
  auto joint = [&](const std::string& name) -> const Joint& { return m.joints[*m.findJoint(name)]; };
  EXPECT_EQ(joint("fixed_pelvis").type, JointType::Fixed);
  EXPECT_EQ(joint("rod_ball").type, JointType::Spherical);
  EXPECT_EQ(joint("knee").type, JointType::Revolute);
  EXPECT_TRUE(joint("knee").axis.isApprox(Eigen::Vector3d::UnitY()));
  const Joint& achilles = joint("achilles");
  EXPECT_EQ(achilles.kind, ConnectionKind::LoopJoint);
  EXPECT_EQ(achilles.type, JointType::Spherical);
  // The connect holds at the reference configuration: both ends at the same world point (0.1, 0, 0.9).
  const LinkPoses poses = computeTreePoses(m, {});
  EXPECT_TRUE((poses[achilles.link1] * achilles.frame1.translation()).isApprox(Eigen::Vector3d(0.1, 0, 0.9)));
  EXPECT_TRUE((poses[achilles.link2] * achilles.frame2.translation()).isApprox(Eigen::Vector3d(0.1, 0, 0.9)));
  const Joint& toe = joint("toe_follows_knee");
  EXPECT_EQ(toe.kind, ConnectionKind::Coupling);
  EXPECT_DOUBLE_EQ(toe.multiplier, 0.5);
  EXPECT_EQ(m.joints[toe.follower].name, "toe_pitch");
  EXPECT_EQ(m.joints[toe.leader].name, "knee");
  EXPECT_EQ(m.joints.back().kind, ConnectionKind::Coupling);  // couplings after every loop joint
}

// --- couplings are constraints
// -------------------------------------------------------------------------------

TEST(Couplings, HoldTheFollowerAtMultiplierTimesTheLeaderPlusOffset) {
  // b = -a + 0.1 (gripper_revolute_mimic.urdf): written with both at 0, the assembly closes the coupling.
  const MobilityReport report =
      reportOf(readOrFail(formatPath("gripper_revolute_mimic.urdf")), AnalysisMode::Auto);
  ASSERT_EQ(report.positions.size(), 2u);
  EXPECT_NEAR(report.positions[1].value, -report.positions[0].value + 0.1, 1e-9);
  // A gear with a prismatic follower: 0.02 m per rad, offset 0.01 m, in millimetres and metres alike.
  for (const double unit : {1.0, 0.001}) {
    std::ostringstream urdf;
    urdf << "<robot name='rack'><link name='g'/><link name='pinion'/><link name='rack'/>"
         << "<joint name='turn' type='continuous'><parent link='g'/><child link='pinion'/><axis xyz='0 0 "
            "1'/></joint>"
         << "<joint name='slide' type='prismatic'><parent link='g'/><child link='rack'/>"
         << "<origin xyz='0 " << 0.05 / unit << " 0'/><axis xyz='1 0 0'/>"
         << "<mimic joint='turn' multiplier='" << 0.02 / unit << "' offset='" << 0.01 / unit
         << "'/></joint></robot>";
    const Result<Mechanism> m = readMechanismFromString(urdf.str(), "rack.urdf");
    ASSERT_TRUE(isOk(m)) << diagnosticOf(m).toString();
    const MobilityReport r = reportOf(valueOf(m), AnalysisMode::Auto);
    EXPECT_EQ(r.dof, 1);
    EXPECT_EQ(r.grublerKutzbachDof, 1);
    ASSERT_EQ(r.positions.size(), 2u);
    EXPECT_NEAR(r.positions[1].value * unit, 0.02 * r.positions[0].value + 0.01, 1e-9);
  }
}

/// A planar leg as generalized_rbda writes its transmissions: hip and knee in series, a rotor on the base,
/// and a URDF+ coupling between the links @p predecessor and @p successor (ratio 2).
std::string legWithRotor(const std::string& predecessor, const std::string& successor) {
  return "<robot name='leg'><link name='base'/><link name='thigh'/><link name='shank'/><link name='rotor'/>"
         "<joint name='hip' type='revolute'><parent link='base'/><child link='thigh'/><axis xyz='0 0 1'/>"
         "<limit lower='-3' upper='3' effort='1' velocity='1'/></joint>"
         "<joint name='knee' type='revolute'><parent link='thigh'/><child link='shank'/><origin xyz='0.3 0 "
         "0'/>"
         "<axis xyz='0 0 1'/><limit lower='-3' upper='3' effort='1' velocity='1'/></joint>"
         "<joint name='spin' type='continuous'><parent link='base'/><child link='rotor'/><origin xyz='0 0.1 "
         "0'/>"
         "<axis xyz='0 0 1'/></joint>"
         "<coupling name='belt' type='rolling'><predecessor link='" +
         predecessor + "'/><successor link='" + successor + "'/><ratio value='2'/></coupling></robot>";
}

TEST(Couplings, BetweenLinksSumTheJointValuesFromTheirCommonAncestor) {
  // generalized_rbda's coupling of two links: ratio times the joint values summed from the links' nearest
  // common ancestor to the predecessor equals that sum to the successor. shank -> rotor: spin = 2 (hip +
  // knee), a belt over the knee (the MIT humanoid's ankle); thigh -> rotor: spin = 2 hip, one joint each
  // side.
  for (const auto& [predecessor, expected] :
       {std::pair<std::string, double>{"shank", 2.0 * (0.3 + 0.2)}, {"thigh", 2.0 * 0.3}}) {
    SCOPED_TRACE(predecessor);
    const Result<Mechanism> m = readMechanismFromString(legWithRotor(predecessor, "rotor"), "leg.urdf");
    ASSERT_TRUE(isOk(m)) << diagnosticOf(m).toString();
    const Joint& belt = valueOf(m).joints[*valueOf(m).findJoint("belt")];
    EXPECT_EQ(belt.kind, ConnectionKind::Coupling);
    EXPECT_EQ(belt.moreLeaders.size(), predecessor == "shank" ? 1u : 0u);
    // Three joints and one coupling: DOF 2 in the plane (3*4 - 2*3 - 3 - 1 = 2), the rotor held at 2 x the
    // sum.
    const MobilityReport r = reportOf(valueOf(m), AnalysisMode::Auto, {{"hip", 0.3}, {"knee", 0.2}});
    EXPECT_EQ(r.mode, "planar");
    EXPECT_EQ(r.dof, 2);
    EXPECT_EQ(r.grublerKutzbachDof, 2);
    EXPECT_EQ(r.numRedundant, 0);
    double spin = 0.0;
    for (const JointValue& v : r.positions)
      spin = v.name == "spin" ? v.value : spin;
    EXPECT_NEAR(spin, expected, 1e-9);
    // The natural-coordinate equation reads the same sum: spin - 2 (hip + knee) at a pose set by hand.
    for (const double written : {expected, expected - 0.4}) {
      const LinkPoses poses = computeTreePoses(valueOf(m), {{"hip", 0.3}, {"knee", 0.2}, {"spin", written}});
      const Result<CoordinateModel> built = buildCoordinateModel(
          valueOf(m), poses, AnalysisMode::Planar, computeCharacteristicLength(valueOf(m), poses));
      ASSERT_TRUE(isOk(built)) << diagnosticOf(built).toString();
      Eigen::VectorXd phi;
      computeConstraintResidual(valueOf(built), computeCoordinates(valueOf(built), poses), phi);
      const int row = valueOf(built).numConstraints() - valueOf(built).lambda - 1;
      ASSERT_EQ(valueOf(built).equations[row].kind, EquationKind::Coupling);
      EXPECT_NEAR(phi(row), written - expected, 1e-12);
    }
  }
  // One joint each side is the joint coupling <predecessor joint='hip'/><successor joint='spin'/>.
  std::string byJoint = legWithRotor("thigh", "rotor");
  byJoint.replace(byJoint.find("link='thigh'/><successor"), std::string("link='thigh'").size(),
                  "joint='hip'");
  byJoint.replace(byJoint.find("link='rotor'/><ratio"), std::string("link='rotor'").size(), "joint='spin'");
  const Result<Mechanism> twin = readMechanismFromString(byJoint, "twin.urdf");
  ASSERT_TRUE(isOk(twin)) << diagnosticOf(twin).toString();
  const MobilityReport t = reportOf(valueOf(twin), AnalysisMode::Auto, {{"hip", 0.3}, {"knee", 0.2}});
  EXPECT_EQ(t.dof, 2);
  for (const JointValue& v : t.positions) {
    if (v.name == "spin")
      EXPECT_NEAR(v.value, 0.6, 1e-9);
  }
  // A link that is the other's ancestor has no joint on its side, and a prismatic joint cannot join a sum of
  // angles: one line each, never a dropped constraint.
  EXPECT_NE(refusalOf(legWithRotor("thigh", "shank"), "leg.urdf").find("is an ancestor of"),
            std::string::npos);
  std::string sliding = legWithRotor("shank", "rotor");
  sliding.replace(sliding.find("'knee' type='revolute'"), std::string("'knee' type='revolute'").size(),
                  "'knee' type='prismatic'");
  EXPECT_NE(refusalOf(sliding, "leg.urdf").find("not revolute"), std::string::npos);
}

TEST(Couplings, HoldWhenEitherJointIsDriven) {
  // b = -a + 0.1: drive the leader and the follower follows, drive the follower and the leader does.
  const Mechanism gripper = readOrFail(formatPath("gripper_revolute_mimic.urdf"));
  for (const auto& [driven, value] : {std::pair<std::string, double>{"a", 0.4}, {"b", -0.5}}) {
    SCOPED_TRACE(driven);
    AnalysisOptions options;
    options.positions = {{driven, value}};
    const Result<MobilityAnalysis> analysis = analyzeMechanism(gripper, options);
    ASSERT_TRUE(isOk(analysis)) << diagnosticOf(analysis).toString();
    const std::vector<JointValue>& reached = valueOf(analysis).report.positions;
    ASSERT_EQ(reached.size(), 2u);
    EXPECT_NEAR(reached[driven == "a" ? 0 : 1].value, value, 1e-9) << "the driven joint is held";
    EXPECT_NEAR(reached[1].value, -reached[0].value + 0.1, 1e-9) << "the coupling holds";
    EXPECT_EQ(valueOf(analysis).report.dof, 1);
  }
}

TEST(Couplings, TakePartInTheOrderedRedundancyAfterTheLoopJoints) {
  // The same gear ratio said twice (a mimic and a URDF+ coupling): the second equation, the <coupling>, is
  // the redundant one, reported with its own source kind.
  const char* text = R"(<robot name="twice">
  <link name="ground"/><link name="a"/><link name="b"/>
  <joint name="ja" type="continuous"><parent link="ground"/><child link="a"/><axis xyz="0 0 1"/></joint>
  <joint name="jb" type="continuous"><parent link="ground"/><child link="b"/><origin xyz="0.3 0 0"/>
    <axis xyz="0 0 1"/><mimic joint="ja" multiplier="-2"/></joint>
  <coupling name="mesh"><predecessor joint="ja"/><successor joint="jb"/><ratio value="-2"/></coupling>
</robot>)";
  const Result<Mechanism> m = readMechanismFromString(text, "twice.urdf");
  ASSERT_TRUE(isOk(m)) << diagnosticOf(m).toString();
  for (const AnalysisMode mode : {AnalysisMode::Auto, AnalysisMode::Spatial}) {
    const MobilityReport r = reportOf(valueOf(m), mode);
    EXPECT_EQ(r.dof, 1);
    EXPECT_EQ(r.grublerKutzbachDof, 0);  // each coupling counts as one equation
    ASSERT_EQ(r.redundantConstraints.size(), 1u);
    EXPECT_EQ(r.redundantConstraints[0].source, "coupling");
    EXPECT_EQ(r.redundantConstraints[0].name, "mesh");
    EXPECT_EQ(r.redundantConstraints[0].kind, "coupling");
    EXPECT_EQ(r.redundantConstraints[0].index, r.numConstraints - (mode == AnalysisMode::Spatial ? 7 : 4));
    ASSERT_EQ(r.redundantJoints.size(), 1u);
    EXPECT_EQ(r.redundantJoints[0].name, "mesh");
  }
}

TEST(Couplings, GradientAndHessianMatchCentralDifferences) {
  for (const char* file : {"gripper_revolute_mimic.urdf", "gripper_mimic.urdf", "gears_urdfplus.urdf"}) {
    for (const AnalysisMode mode : {AnalysisMode::Planar, AnalysisMode::Spatial}) {
      const Mechanism m = readOrFail(formatPath(file));
      JointPositions positions;
      for (const Joint& j : m.joints) {
        if (j.kind == ConnectionKind::TreeJoint)
          positions[j.name] = 0.3 + 0.1 * positions.size();
      }
      const LinkPoses poses = computeTreePoses(m, positions);
      const Result<CoordinateModel> built =
          buildCoordinateModel(m, poses, mode, computeCharacteristicLength(m, poses));
      ASSERT_TRUE(isOk(built)) << diagnosticOf(built).toString();
      const CoordinateModel& model = valueOf(built);
      ASSERT_EQ(model.couplings.size(), 1u) << file;
      const Eigen::VectorXd q = computeCoordinates(model, poses);
      const SparseJacobian J = computeConstraintJacobian(model, q);
      const int row = model.numConstraints() - model.lambda - 1;  // the coupling: last before the boundary
      ASSERT_EQ(model.equations[row].kind, EquationKind::Coupling);
      const double h = 1e-6;
      Eigen::VectorXd phiPlus, phiMinus;
      for (int c = 0; c < model.numCoordinates(); ++c) {
        Eigen::VectorXd qp = q, qm = q;
        qp(c) += h;
        qm(c) -= h;
        computeConstraintResidual(model, qp, phiPlus);
        computeConstraintResidual(model, qm, phiMinus);
        EXPECT_NEAR(J.coeff(row, c), (phiPlus(row) - phiMinus(row)) / (2 * h), 1e-7)
            << file << " column " << c;
      }
      // The Hessian against differences of the residual itself (second differences), on its own columns.
      std::vector<int> columns;
      Eigen::MatrixXd H;
      computeCouplingHessian(model.couplings[0], model, q, columns, H);
      ASSERT_EQ(H.rows(), static_cast<int>(columns.size()));
      // The same through the form dispatcher every second-order user reads (EquationForms.hpp).
      const Eigen::MatrixXd full = computeEquationHessian(model, q, row);
      for (size_t a = 0; a < columns.size(); ++a) {
        for (size_t b = 0; b < columns.size(); ++b)
          EXPECT_DOUBLE_EQ(full(columns[a], columns[b]), H(a, b));
      }
      EXPECT_NEAR(full.norm(), H.norm(), 1e-12 * (1.0 + H.norm()));
      const double k = 1e-4;
      for (size_t a = 0; a < columns.size(); ++a) {
        for (size_t b = 0; b < columns.size(); ++b) {
          auto f = [&](double da, double db) {
            Eigen::VectorXd x = q;
            x(columns[a]) += da;
            x(columns[b]) += db;
            return evaluateCoupling(model.couplings[0], model, x);
          };
          const double second = (f(k, k) - f(k, -k) - f(-k, k) + f(-k, -k)) / (4 * k * k);
          EXPECT_NEAR(H(a, b), second, 1e-4 * (1.0 + std::abs(second))) << file;
        }
      }
    }
  }
}

// --- never silent
// ---------------------------------------------------------------------------------------------

TEST(Warnings, EveryClassFiresAndNamesItsElement) {
  const char* text = R"(<robot name="w">
  <link name="ground"/><link name="a"/><link name="b"/><link name="c"/>
  <joint name="ja" type="revolute"><parent link="ground"/><child link="a"/><axis xyz="0 0 1"/></joint>
  <joint name="jb" type="revolute"><parent link="a"/><child link="b"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="jc" type="revolute"><parent link="ground"/><child link="c"/><origin xyz="2 0 0"/><axis xyz="0 0 1"/></joint>
  <loop_joint name="no_axis" type="revolute"><link1 link="b" xyz="1 0 0"/><link1 link="a"/><link2 link="c"/></loop_joint>
  <loop_joint name="cardan" type="universal"><link1 link="b"/><link2 link="c"/><axis xyz="1 0 0"/><spring k="1"/></loop_joint>
  <loopjoint name="typo" type="revolute"/>
  <frobnicate/>
  <loop_constraint name="old"/>
  <gazebo/><transmission name="t"/><ros2_control name="r"/><material name="m"/>
</robot>)";
  const Result<Mechanism> m = readMechanismFromString(text, "warn.urdf");
  ASSERT_TRUE(isOk(m)) << diagnosticOf(m).toString();
  const std::vector<std::string> w = warningTexts(valueOf(m));
  EXPECT_TRUE(anyContains(w, "loopjoint 'typo'", "did you mean <loop_joint>"));
  EXPECT_TRUE(anyContains(w, "unknown element <frobnicate>"));
  EXPECT_TRUE(anyContains(w, "loop_constraint 'old'", "<loop>"));
  EXPECT_TRUE(anyContains(w, "loop_joint 'no_axis'", "more than one <link1>"));
  EXPECT_TRUE(anyContains(w, "loop_joint 'no_axis'", "axis defaulted to 1 0 0"));
  EXPECT_TRUE(anyContains(w, "loop_joint 'cardan'", "unknown child <spring>"));
  EXPECT_TRUE(anyContains(w, "loop_joint 'cardan'", "axis2 defaulted to 0 1 0"));
  EXPECT_EQ(w.size(), 7u);  // the well-known gazebo, transmission, ros2_control and material are not warnings
  for (const std::string& line : w) {
    EXPECT_EQ(line.rfind("warn.urdf: ", 0), 0u) << line;
    expectOneLine(line);
  }
  // URDF+ <loop> and <coupling> children too.
  const char* plus = R"(<robot name="p"><link name="g"/><link name="a"/><link name="b"/>
  <joint name="ja" type="continuous"><parent link="g"/><child link="a"/><axis xyz="0 0 1"/></joint>
  <joint name="jb" type="continuous"><parent link="g"/><child link="b"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/></joint>
  <loop name="l" type="spherical"><predecessor link="a"/><successor link="b"/><successor link="g"/><damping/></loop>
  <coupling name="c"><predecessor joint="ja"/><successor joint="jb"/><ratio value="2"/><backlash/></coupling>
  <link name="d"/><joint name="jd" type="prismatic"><parent link="a"/><child link="d"/></joint>
  <loop name="hinge" type="revolute"><predecessor link="d"/><successor link="b"/></loop>
</robot>)";
  const std::vector<std::string> wp = warningTexts(valueOf(readMechanismFromString(plus, "p.urdf")));
  // A forgotten axis, on a tree joint or a loop whose type needs one: URDF's 1 0 0, said.
  EXPECT_TRUE(anyContains(wp, "joint 'jd'", "type prismatic has no <axis>; axis defaulted to 1 0 0"));
  EXPECT_TRUE(anyContains(wp, "loop 'hinge'", "type revolute has no <axis>; axis defaulted to 1 0 0"));
  EXPECT_FALSE(anyContains(wp, "loop 'l'", "axis")) << "a spherical loop needs no axis";
  EXPECT_TRUE(anyContains(wp, "loop 'l'", "more than one <successor>"));
  EXPECT_TRUE(anyContains(wp, "loop 'l'", "unknown child <damping>"));
  EXPECT_TRUE(anyContains(wp, "coupling 'c'", "unknown child <backlash>"));
  // The closure file and MJCF.
  const std::string yaml = writeTemp("w.yaml",
                                     "closed_loop: [['closure_A', 'closure_B']]\ntype: ['6d']\n"
                                     "joint_name: ['free_B', 'no_such_joint']\n"
                                     "joint_type: ['UJOINT_XX', 'SPHERICAL']\nsolver: fast\n");
  ReadOptions options;
  options.closuresFile = yaml;
  const std::vector<std::string> wy = warningTexts(readOrFail(formatPath("five_bar_gepetto.urdf"), options));
  EXPECT_TRUE(anyContains(wy, "w.yaml: yaml 'solver'", "unknown key"));
  EXPECT_TRUE(anyContains(wy, "joint_type 'free_B'", "'UJOINT_XX' is none of"));
  EXPECT_TRUE(anyContains(wy, "joint_name 'no_such_joint'", "not a tree joint"));
  const std::string mjcf = writeTemp("w.xml", R"(<mujoco model="w"><worldbody>
  <body name="a"><joint name="ja" type="hinge"/><geom size="0.1"/></body>
  <body name="b" pos="1 0 0"><joint name="jb" type="hinge"/><geom size="0.1"/></body></worldbody>
  <equality><connect name="off" body1="a" body2="b" anchor="0.5 0 0" active="false"/>
  <joint name="hold" joint1="ja"/><joint name="cubic" joint1="jb" joint2="ja" polycoef="0 1 0.5 0 0"/></equality>
</mujoco>)");
  const std::vector<std::string> wm = warningTexts(readOrFail(mjcf));
  EXPECT_TRUE(anyContains(wm, "connect 'off'", "inactive"));
  EXPECT_TRUE(anyContains(wm, "joint 'hold'", "no joint2"));
  EXPECT_TRUE(anyContains(wm, "joint 'cubic'", "polynomial terms"));
}

TEST(Warnings, ReachTheReport) {
  const Result<Mechanism> m = readMechanismFromString(
      "<robot name='r'><link name='g'/><link name='a'/><joint name='j' type='revolute'><parent link='g'/>"
      "<child link='a'/><axis xyz='0 0 1'/></joint><loopjoint name='x'/></robot>",
      "r.urdf");
  ASSERT_TRUE(isOk(m));
  const MobilityReport report = reportOf(valueOf(m), AnalysisMode::Auto);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("did you mean <loop_joint>"), std::string::npos);
  EXPECT_NE(toJson(report).find("\"warnings\": [\"r.urdf: loopjoint 'x': unknown element"),
            std::string::npos);
}

TEST(Warnings, StrictMakesTheFirstAnError) {
  ReadOptions strict;
  strict.strict = true;
  const char* text =
      "<robot name='r'><link name='g'/><link name='a'/><joint name='j' type='revolute'>"
      "<parent link='g'/><child link='a'/><axis xyz='0 0 1'/></joint><loopjoint name='x'/></robot>";
  const Result<Mechanism> m = readMechanismFromString(text, "r.urdf", strict);
  ASSERT_FALSE(isOk(m));
  EXPECT_EQ(diagnosticOf(m).elementKind, "loopjoint");
  EXPECT_NE(diagnosticOf(m).what.find("--strict"), std::string::npos);
  // A clean file stays clean under strict.
  EXPECT_TRUE(isOk(readMechanism(formatPath("four_bar_urdfplus.urdf"), strict)));
}

// --- bad input: one line, every error class, hostile names
// ------------------------------------------------------

TEST(Diagnostics, EscapeNewlinesAndControlCharacters) {
  EXPECT_EQ(escapeForLine("gro\nund\t\r\x01\x7f ok"), "gro\\nund\\t\\r\\x01\\x7f ok");
  const Diagnostic d = makeDiagnostic("a\nb.urdf", "joint", "j\n1", "what\x1b[31m");
  EXPECT_EQ(d.toString(), "a\\nb.urdf: joint 'j\\n1': what\\x1b[31m");
}

struct HostileCase {
  const char* label;
  std::string text;
  const char* elementKind;
};

TEST(Diagnostics, EveryErrorClassWithAHostileNameGivesOneLine) {
  const std::string h = "evil&#10;name&#9;\x01";  // newline, tab and a raw control character in a name
  const std::string tree =
      "<link name='g'/><link name='a'/><link name='b'/>"
      "<joint name='ja' type='revolute'><parent link='g'/><child link='a'/><axis xyz='0 0 1'/></joint>";
  const std::string full = tree + "<joint name='jb' type='fixed'><parent link='a'/><child link='b'/></joint>";
  const std::vector<HostileCase> cases = {
      {"xml", "<?xml version='1.0'\n?><robot><", "xml"},
      {"not robot", "<evil\x01/>", "xml"},
      {"unknown link",
       "<robot name='r'>" + full + "<loop_joint name='" + h +
           "' type='fixed'><link1 link='a'/><link2 link='" + h + "'/></loop_joint></robot>",
       "loop_joint"},
      {"two parents",
       "<robot name='r'>" + tree + "<joint name='" + h +
           "' type='fixed'><parent link='g'/><child link='a'/></joint></robot>",
       "joint"},
      {"bad number",
       "<robot name='r'>" + tree + "<joint name='" + h +
           "' type='fixed'><parent link='a'/><child link='b'/><origin xyz='1 " + h + " 0'/></joint></robot>",
       "joint"},
      {"non-finite",
       "<robot name='r'>" + tree + "<joint name='" + h +
           "' type='fixed'><parent link='a'/><child link='b'/><origin xyz='1 nan 0'/></joint></robot>",
       "joint"},
      {"out of range",
       "<robot name='r'>" + tree + "<joint name='" + h +
           "' type='fixed'><parent link='a'/><child link='b'/><origin xyz='1 0 1e308'/></joint></robot>",
       "joint"},
      {"zero axis",
       "<robot name='r'>" + tree + "<joint name='" + h +
           "' type='revolute'><parent link='a'/><child link='b'/><axis xyz='0 0 0'/></joint></robot>",
       "joint"},
      {"duplicate",
       "<robot name='r'>" + tree +
           "<joint name='jb' type='fixed'><parent link='a'/><child link='b'/></joint><distance_constraint "
           "name='jb'><link1 link='a'/><link2 link='b'/></distance_constraint></robot>",
       "distance_constraint"},
      {"disconnected", "<robot name='r'><link name='g'/><link name='" + h + "'/></robot>", "link"},
      {"loop type",
       "<robot name='r'>" + full + "<loop name='l' type='" + h +
           "'><predecessor link='a'/><successor link='g'/></loop></robot>",
       "loop"},
      {"tree type",
       "<robot name='r'>" + tree + "<joint name='jb' type='" + h +
           "'><parent link='a'/><child link='b'/></joint></robot>",
       "joint"},
      {"cable",
       "<robot name='r'>" + tree +
           "<joint name='jb' type='fixed'><parent link='a'/><child link='b'/></joint><cable name='" + h +
           "' length='-1'><link1 link='a'/><link2 link='b'/></cable></robot>",
       "cable"},
      {"mimic leader",
       "<robot name='r'>" + tree +
           "<joint name='jb' type='revolute'><parent link='a'/><child link='b'/><axis xyz='0 0 1'/><mimic "
           "joint='" +
           h + "'/></joint></robot>",
       "joint"},
      {"coupling ratio",
       "<robot name='r'>" + tree +
           "<joint name='jb' type='revolute'><parent link='a'/><child link='b'/><axis xyz='0 0 "
           "1'/></joint><coupling name='" +
           h + "'><predecessor joint='ja'/><successor joint='jb'/><ratio value='" + h +
           "'/></coupling></robot>",
       "coupling"},
      {"self loop",
       "<robot name='r'>" + full + "<loop_joint name='" + h +
           "' type='fixed'><link1 link='a'/><link2 link='a'/></loop_joint></robot>",
       "loop_joint"},
  };
  for (const HostileCase& c : cases) {
    const Result<Mechanism> m = readMechanismFromString(c.text, "evil\nfile.urdf");
    ASSERT_FALSE(isOk(m)) << c.label;
    EXPECT_EQ(diagnosticOf(m).elementKind, c.elementKind) << c.label << ": " << diagnosticOf(m).toString();
    expectOneLine(diagnosticOf(m).toString());
  }
  // The closure file: an unknown frame and a malformed YAML (yaml-cpp's message), each one line.
  for (const std::string& yaml :
       {std::string("closed_loop: [['nowhere\\nland', 'closure_B']]\ntype: ['6d']\n"),
        std::string("closed_loop: [[\n  'a\x01'\ntype: {")}) {
    ReadOptions options;
    options.closuresFile = writeTemp("hostile.yaml", yaml);
    const Result<Mechanism> m = readMechanism(formatPath("five_bar_gepetto.urdf"), options);
    ASSERT_FALSE(isOk(m)) << yaml;
    expectOneLine(diagnosticOf(m).toString());
  }
  // MuJoCo's own (multi-line) refusal.
  const Result<Mechanism> mj = readMechanismFromString(
      "<mujoco model='m'><worldbody><body name='a'><joint type='nonsense\n'/></body></worldbody></mujoco>",
      "evil.xml");
  ASSERT_FALSE(isOk(mj));
  EXPECT_EQ(diagnosticOf(mj).elementKind, "mujoco");
  expectOneLine(diagnosticOf(mj).toString());
  // Positions with a hostile joint name.
  const Mechanism four = readOrFail(formatPath("four_bar_loop_joint.urdf"));
  const Result<JointPositions> p = makeJointPositions({"j\n1"}, {0.1}, four);
  ASSERT_FALSE(isOk(p));
  expectOneLine(diagnosticOf(p).toString());
}

// --- numbers: representable where they enter, never inf/nan in a written report
// ---------------------------------

TEST(Numbers, OutOfRangeCoordinatesAndPositionsAreRefusedWhereTheyEnter) {
  std::string text = readTextFile(formatPath("four_bar_loop_joint.urdf"));
  const std::string far = std::regex_replace(text, std::regex("xyz=\"0.4 0 0\""), "xyz=\"0.4 0 1e308\"");
  const Result<Mechanism> m = readMechanismFromString(far, "far.urdf");
  ASSERT_FALSE(isOk(m));
  EXPECT_EQ(diagnosticOf(m).elementName, "j3");
  EXPECT_NE(diagnosticOf(m).what.find("range"), std::string::npos);
  // 1e12 is the absolute edge (accepted in a model that is all that big: HardInputsTest); in this 0.4 m four-bar it
  // is also far beyond 1e6 times the model's typical length, refused by the relative range.
  const Result<Mechanism> edge = readMechanismFromString(
      std::regex_replace(text, std::regex("xyz=\"0.4 0 0\""), "xyz=\"0.4 0 1e12\""), "x.urdf");
  ASSERT_FALSE(isOk(edge));
  EXPECT_NE(diagnosticOf(edge).what.find("typical length"), std::string::npos);
  const Mechanism four = readOrFail(formatPath("four_bar_loop_joint.urdf"));
  EXPECT_FALSE(isOk(parseJointPositions("j1=1e155", four)));
  EXPECT_FALSE(isOk(makeJointPositions({"j1"}, {-1e13}, four)));
  EXPECT_TRUE(isOk(parseJointPositions("j1=0.5", four)));
}

TEST(Numbers, TheJsonWriterRefusesInfAndNanAndNeverWritesThem) {
  MobilityReport report = reportOf(readOrFail(formatPath("four_bar_loop_joint.urdf")), AnalysisMode::Auto);
  ASSERT_TRUE(isOk(writeJson(report)));
  MobilityReport withInf = report;
  withInf.characteristicLength = std::numeric_limits<double>::infinity();
  MobilityReport withNan = report;
  withNan.positions[0].value = std::nan("");
  for (const MobilityReport* bad : {&withInf, &withNan}) {
    const Result<std::string> json = writeJson(*bad);
    ASSERT_FALSE(isOk(json));
    expectOneLine(diagnosticOf(json).toString());
    EXPECT_FALSE(isOk(writeText(*bad)));
    // toJson itself writes null, never a token no JSON parser accepts.
    const std::string raw = toJson(*bad);
    EXPECT_EQ(raw.find("inf"), std::string::npos);
    EXPECT_EQ(raw.find("nan"), std::string::npos);
    EXPECT_NE(raw.find("null"), std::string::npos);
  }
  EXPECT_NE(diagnosticOf(writeJson(withInf)).what.find("characteristic_length is inf"), std::string::npos);
  // Counts that contradict each other are refused too.
  MobilityReport inconsistent = report;
  inconsistent.dof += 1;
  EXPECT_FALSE(isOk(writeJson(inconsistent)));
  inconsistent = report;
  inconsistent.numRedundant += 1;
  EXPECT_FALSE(isOk(writeJson(inconsistent)));
}

// --- deep trees: read without recursion
// ------------------------------------------------------------------------------

TEST(DeepTrees, AChainOfTwoHundredThousandLinksLoads) {
  constexpr int kLinks = 200000;
  const std::string text = straightChainUrdf(kLinks);
  const Result<Mechanism> m = readMechanismFromString(text, "chain.urdf");
  ASSERT_TRUE(isOk(m)) << diagnosticOf(m).toString();
  EXPECT_EQ(valueOf(m).links.size(), static_cast<size_t>(kLinks + 1));
  EXPECT_EQ(valueOf(m).joints.size(), static_cast<size_t>(kLinks));
  EXPECT_EQ(valueOf(m).rootLink, 0);
  // A cycle deep in it is still found, iteratively.
  std::string cyclic = "<robot name='cycle'><link name='l0'/>";
  for (int i = 1; i <= 30; ++i) {
    const std::string n = std::to_string(i), p = std::to_string(i == 1 ? 20 : i - 1);
    cyclic += "<link name='l" + n + "'/><joint name='j" + n + "' type='fixed'><parent link='l" + p +
              "'/><child link='l" + n + "'/></joint>";
  }
  cyclic += "</robot>";
  const Result<Mechanism> c = readMechanismFromString(cyclic, "cyclic.urdf");
  ASSERT_FALSE(isOk(c));
  EXPECT_NE(diagnosticOf(c).toString().find("cycle"), std::string::npos);
}

/// The value reached by joint @p name in @p report (NaN when it is not listed).
double reachedValue(const MobilityReport& report, const std::string& name) {
  for (const JointValue& v : report.positions) {
    if (v.name == name)
      return v.value;
  }
  return std::nan("");
}

TEST(Readers, MjcfTendonEqualityOverFixedTendonsIsACoupling) {
  // Three hinges in a row; fixed tendons are weighted sums of joint values (L = sum coef qpos), and a tendon
  // equality holds L1 - L1_0 = c0 + c1 (L2 - L2_0).
  auto finger = [](const std::string& tendons, const std::string& equality) {
    return R"(<mujoco model="finger"><worldbody>
      <body name="a"><joint name="knuckle" type="hinge" axis="0 0 1"/><geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.01"/>
        <body name="b" pos="0.3 0 0"><joint name="middle" type="hinge" axis="0 0 1"/><geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01"/>
          <body name="c" pos="0.2 0 0"><joint name="tip" type="hinge" axis="0 0 1"/><geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.01"/>
          </body></body></body></worldbody><tendon>)" +
           tendons + "</tendon><equality>" + equality + "</equality></mujoco>";
  };
  // One tendon held at its reference length: knuckle - 2 tip = 0 (knuckle = 2 tip). Three hinges, one
  // coupling: planar DOF 2.
  const Result<Mechanism> coupler = readMechanismFromString(
      finger(
          R"(<fixed name="coupler"><joint joint="knuckle" coef="1"/><joint joint="tip" coef="-2"/></fixed>)",
          R"(<tendon name="hold" tendon1="coupler"/>)"),
      "finger.xml");
  ASSERT_TRUE(isOk(coupler)) << diagnosticOf(coupler).toString();
  EXPECT_TRUE(valueOf(coupler).warnings.empty());
  const MobilityReport held = reportOf(valueOf(coupler), AnalysisMode::Auto, {{"tip", 0.2}, {"middle", 0.1}});
  EXPECT_EQ(held.dof, 2);
  EXPECT_EQ(held.grublerKutzbachDof, 2);
  EXPECT_NEAR(reachedValue(held, "knuckle"), 0.4, 1e-9);
  // Two tendons, weighted sums on both sides: knuckle + 3 middle = 0.05 + 0.5 (2 tip + middle); the written
  // pose is off by the offset and is assembled onto it.
  const Result<Mechanism> two = readMechanismFromString(
      finger(R"(<fixed name="base"><joint joint="knuckle" coef="1"/><joint joint="middle" coef="3"/></fixed>
                <fixed name="end"><joint joint="tip" coef="2"/><joint joint="middle" coef="1"/></fixed>)",
             R"(<tendon name="follow" tendon1="base" tendon2="end" polycoef="0.05 0.5 0 0 0"/>)"),
      "finger.xml");
  ASSERT_TRUE(isOk(two)) << diagnosticOf(two).toString();
  const MobilityReport followed = reportOf(valueOf(two), AnalysisMode::Auto, {{"tip", 0.3}, {"middle", 0.2}});
  EXPECT_EQ(followed.dof, 2);
  EXPECT_NEAR(reachedValue(followed, "knuckle"), 0.05 + 0.5 * (2.0 * 0.3 + 0.2) - 3.0 * 0.2, 1e-9);
  // A spatial tendon's length is no sum of joint values: a warning, not a silent drop.
  const Result<Mechanism> spatial = readMechanismFromString(
      R"(<mujoco model="string"><worldbody><site name="s0" pos="0 0.1 0"/>
        <body name="a"><joint name="knuckle" type="hinge" axis="0 0 1"/><geom size="0.01"/><site name="s1" pos="0.3 0 0"/>
        </body></worldbody><tendon><spatial name="string"><site site="s0"/><site site="s1"/></spatial></tendon>
        <equality><tendon name="pull" tendon1="string"/></equality></mujoco>)",
      "string.xml");
  ASSERT_TRUE(isOk(spatial)) << diagnosticOf(spatial).toString();
  EXPECT_TRUE(anyContains(warningTexts(valueOf(spatial)), "tendon 'pull'", "not a fixed tendon over hinges"));
}

TEST(Readers, MjcfWeldHoldsTwoBodiesTogether) {
  // Two cranks on parallel hinges, welded to each other: nothing moves. In the plane 3*2 - 2*2 - 3 = -1, so
  // one equation is redundant; in space 6*2 - 5*2 - 6 = -4, four.
  const std::string path = ::testing::TempDir() + "weld.xml";
  std::ofstream(path) << R"(<mujoco model="weld"><worldbody>
  <body name="a"><joint name="ja" type="hinge" axis="0 0 1"/><geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.01"/></body>
  <body name="b" pos="1 0 0"><joint name="jb" type="hinge" axis="0 0 1"/><geom type="capsule" fromto="0 0 0 -0.5 0 0" size="0.01"/></body>
  </worldbody><equality><weld name="glue" body1="a" body2="b"/></equality></mujoco>)";
  const Mechanism m = readOrFail(path);
  EXPECT_EQ(m.joints[*m.findJoint("glue")].type, JointType::Fixed);
  const MobilityReport planar = reportOf(m, AnalysisMode::Auto);
  EXPECT_EQ(planar.mode, "planar");
  EXPECT_EQ(planar.dof, 0);
  EXPECT_EQ(planar.grublerKutzbachDof, -1);
  EXPECT_EQ(planar.numRedundant, 1);
  const MobilityReport spatial = reportOf(m, AnalysisMode::Spatial);
  EXPECT_EQ(spatial.dof, 0);
  EXPECT_EQ(spatial.grublerKutzbachDof, -4);
  EXPECT_EQ(spatial.numRedundant, 4);
}

TEST(Readers, ARefusalNamesTheWarningBeforeIt) {
  // The misspelt <jiont> is not read, so l2 is a second root: the refusal's one line says both.
  const std::string line = refusalOf(
      "<robot name='a'><link name='l1'/><link name='l2'/><jiont name='j' type='fixed'><parent link='l1'/>"
      "<child link='l2'/></jiont><frobnicate/></robot>",
      "typo.urdf");
  EXPECT_NE(line.find("two roots"), std::string::npos) << line;
  EXPECT_NE(line.find("(after the warning jiont 'j': unknown element <jiont> is not read, and 1 more)"),
            std::string::npos)
      << line;
  EXPECT_EQ(line.find('\n'), std::string::npos);
  // The same in SDFormat: a misspelt <lnk> leaves the joint's child unknown to libsdformat.
  std::string sdf = readTextFile(formatPath("four_bar_drake_ball.sdf"));
  sdf.replace(sdf.find("<link name=\"crank\">"), 5, "<lnk");
  sdf.replace(sdf.find("</link>"), 7, "</lnk>");
  const std::string sdfLine = refusalOf(sdf, "typo.sdf");
  EXPECT_NE(sdfLine.find("(after the warning lnk 'crank': unknown element <lnk> is not read"),
            std::string::npos)
      << sdfLine;
}

TEST(Readers, DrakeBallConstraintNeedsEveryPart) {
  // Drake requires all four children; a missing one is one line naming the constraint, never a dropped loop.
  const std::string text = readTextFile(formatPath("four_bar_drake_ball.urdf"));
  const Mechanism m = readOrFail(formatPath("four_bar_drake_ball.urdf"));
  const Joint& ball = m.joints[*m.findJoint("ball_constraint_0")];
  EXPECT_EQ(ball.kind, ConnectionKind::LoopJoint);
  EXPECT_EQ(ball.type, JointType::Spherical);
  EXPECT_TRUE(ball.frame2.translation().isApprox(Eigen::Vector3d(0, 0.3, 0)));
  for (const std::string part : {"body_A", "p_BQ"}) {
    std::string cut = text;
    const size_t at = cut.find("<drake:ball_constraint_" + part);
    cut.erase(at, cut.find("/>", at) + 2 - at);
    const std::string line = refusalOf(cut, "cut.urdf");
    EXPECT_NE(line.find("ball_constraint_0"), std::string::npos) << line;
    EXPECT_NE(line.find("missing <drake:ball_constraint_" + part), std::string::npos) << line;
  }
}

TEST(Readers, DrakeJointsAreTreeJoints) {
  // An RSSR as Drake writes it: the crank carries the rod on a <drake:joint type="ball">, and the rod's other
  // end is held on the rocker by a <drake:ball_constraint>. Crank about z at the origin, B (0.2, 0, 0);
  // rocker about y at D (1, 0, 0), C (1, 0, 0.3). 6*3 - 5*2 - 3 - 3 = 2: the rocker's motion and the rod's
  // spin.
  const std::string rssr = R"(<robot name="rssr" xmlns:drake="http://drake.mit.edu">
    <link name="ground"/><link name="crank"/><link name="rod"/><link name="rocker"/>
    <joint name="input" type="continuous"><parent link="ground"/><child link="crank"/><axis xyz="0 0 1"/></joint>
    <drake:joint name="ball_b" type="ball"><parent link="crank"/><child link="rod"/><origin xyz="0.2 0 0"/>
    </drake:joint>
    <joint name="output" type="continuous"><parent link="ground"/><child link="rocker"/><origin xyz="1 0 0"/>
      <axis xyz="0 1 0"/></joint>
    <drake:ball_constraint><drake:ball_constraint_body_A name="rod"/><drake:ball_constraint_p_AP value="0.8 0 0.3"/>
      <drake:ball_constraint_body_B name="rocker"/><drake:ball_constraint_p_BQ value="0 0 0.3"/></drake:ball_constraint>
  </robot>)";
  const Result<Mechanism> m = readMechanismFromString(rssr, "rssr.urdf");
  ASSERT_TRUE(isOk(m)) << diagnosticOf(m).toString();
  EXPECT_TRUE(valueOf(m).warnings.empty());
  const Joint& ball = valueOf(m).joints[*valueOf(m).findJoint("ball_b")];
  EXPECT_EQ(ball.kind, ConnectionKind::TreeJoint);
  EXPECT_EQ(ball.type, JointType::Spherical);
  const MobilityReport r = reportOf(valueOf(m), AnalysisMode::Auto);
  EXPECT_EQ(r.mode, "spatial");
  EXPECT_EQ(r.dof, 2);
  EXPECT_EQ(r.grublerKutzbachDof, 2);
  EXPECT_EQ(r.numRedundant, 0);
  EXPECT_EQ(r.passiveDof, 1);
  EXPECT_EQ(r.assembly.iterations, 0);  // the written pose closes
  // Drake's universal joint turns about x, then y; a type Drake builds otherwise (a screw) is one line.
  std::string universal = rssr;
  universal.replace(universal.find(R"(type="ball")"), 11, R"(type="universal")");
  const Result<Mechanism> u = readMechanismFromString(universal, "rssr.urdf");
  ASSERT_TRUE(isOk(u)) << diagnosticOf(u).toString();
  const Joint& cross = valueOf(u).joints[*valueOf(u).findJoint("ball_b")];
  EXPECT_EQ(cross.type, JointType::Universal);
  EXPECT_EQ(cross.axis, Eigen::Vector3d::UnitX());
  EXPECT_EQ(cross.axis2, Eigen::Vector3d::UnitY());
  std::string screw = rssr;
  screw.replace(screw.find(R"(type="ball")"), 11, R"(type="screw")");
  const std::string screwLine = refusalOf(screw, "rssr.urdf");
  EXPECT_NE(screwLine.find("drake:joint 'ball_b': type 'screw' is not read"), std::string::npos) << screwLine;
}

TEST(SdfReader, DrakeBallConstraintClosesAtTheWrittenPoseAndOtherNamespacesWarn) {
  // The point on the rocker is written in its SDFormat frame (at C), not its pin's: read right, the loop
  // closes at the written pose with no assembly.
  const std::string path = formatPath("four_bar_drake_ball.sdf");
  const MobilityReport report = reportOf(readOrFail(path), AnalysisMode::Auto);
  EXPECT_LT(report.closureResidualBefore, 1e-12);
  EXPECT_EQ(report.assembly.iterations, 0);
  // libsdformat keeps an element of another namespace silently; the reader says it is not read.
  std::string text = readTextFile(path);
  text.replace(text.find("    <drake:ball_constraint>"), 0, "<drake:linear_bushing_rpy/>");
  const Result<Mechanism> bushing = readMechanismFromString(text, "bushing.sdf");
  ASSERT_TRUE(isOk(bushing)) << diagnosticOf(bushing).toString();
  EXPECT_TRUE(anyContains(warningTexts(valueOf(bushing)), "drake:linear_bushing_rpy", "is not read"));
  // A point that is not three numbers is one line.
  text = readTextFile(path);
  text.replace(text.find(">0 0 0</drake:ball_constraint_p_BQ>"), 6, ">0 0");
  const std::string line = refusalOf(text, "bad.sdf");
  EXPECT_NE(line.find("p_BQ '0 0' is not three numbers"), std::string::npos) << line;
}

TEST(Readers, ClosureFileFramesOfJointsAndLoopNames) {
  // A frame may be a tree joint (its child link's frame); the closures are named closed_loop_<i>.
  const std::string yaml =
      writeTemp("framed.yaml", "closed_loop: [['to_closure_A', 'free_B']]\ntype: ['3d']\n");
  ReadOptions options;
  options.closuresFile = yaml;
  const Mechanism m = readOrFail(formatPath("five_bar_gepetto.urdf"), options);
  EXPECT_TRUE(m.warnings.empty());
  const Joint& c = m.joints[*m.findJoint("closed_loop_0")];
  EXPECT_EQ(c.kind, ConnectionKind::LoopJoint);
  EXPECT_EQ(c.type, JointType::Spherical);
  EXPECT_EQ(m.links[c.link1].name, "closure_A");
  EXPECT_EQ(m.links[c.link2].name, "closure_B");
  // Same as the 3d closure file: DOF 3.
  EXPECT_EQ(reportOf(m, AnalysisMode::Auto).dof, 3);
  // Sizes that differ are named.
  std::ofstream(yaml)
      << "closed_loop: [['closure_A', 'closure_B'], ['closure_A', 'crank_left']]\ntype: ['6d']\n";
  const Result<Mechanism> bad = readMechanism(formatPath("five_bar_gepetto.urdf"), options);
  ASSERT_FALSE(isOk(bad));
  EXPECT_NE(diagnosticOf(bad).what.find("1 types for 2 closed_loop pairs"), std::string::npos);
}

/// The five-bar of five_bar_gepetto.urdf welded at C (6d), with the closure file's extra lines @p rebuild.
MobilityReport weldedFiveBarWith(const std::string& rebuild, std::vector<std::string>* warnings = nullptr) {
  ReadOptions options;
  options.closuresFile =
      writeTemp("rebuilt.yaml", "closed_loop: [['closure_A', 'closure_B']]\ntype: ['6d']\n" + rebuild);
  const Mechanism m = readOrFail(formatPath("five_bar_gepetto.urdf"), options);
  if (warnings != nullptr)
    *warnings = warningTexts(m);
  return reportOf(m, AnalysisMode::Auto);
}

TEST(Readers, ClosureFileRebuildsTreeJointsAsGepettosLoaderDoes) {
  // Gepetto's joint_name / joint_type turn tree joints of the URDF into other joints. Here the pin free_B
  // that carries closure_B on distal_right; closure_B is welded to closure_A on distal_left. Links 7,
  // revolutes 4 (5 equations each in space), to_closure_A fixed (6), the weld (6). As written: the planar
  // five-bar, 3*6 - 2*4 - 3 - 3 = 2.
  const MobilityReport pin = weldedFiveBarWith("");
  EXPECT_EQ(pin.mode, "planar");
  EXPECT_EQ(pin.dof, 2);
  // SPHERICAL: a ball at C. The five-bar moves as before (2) and the ball's rotation is set by the weld;
  // 36 - 20 - 6 - 3 - 6 = 1, so the ball's out-of-plane equation is redundant.
  const MobilityReport ball = weldedFiveBarWith("joint_name: ['free_B']\njoint_type: ['SPHERICAL']\n");
  EXPECT_EQ(ball.mode, "spatial");
  EXPECT_EQ(ball.dof, 2);
  EXPECT_EQ(ball.grublerKutzbachDof, 1);
  EXPECT_EQ(ball.numRedundant, 1);
  // UJOINT_ZX: a universal joint turning about z on distal_right, then x on closure_B: the five-bar still
  // turns about z at C (2), and x cannot turn, as both sides only turn about z; 36 - 20 - 6 - 4 - 6 = 0.
  const MobilityReport ujointZx = weldedFiveBarWith("joint_name: ['free_B']\njoint_type: ['UJOINT_ZX']\n");
  EXPECT_EQ(ujointZx.dof, 2);
  EXPECT_EQ(ujointZx.grublerKutzbachDof, 0);
  EXPECT_EQ(ujointZx.numRedundant, 2);
  // Pinocchio's R_Z then R_X at the joint's place: z turns on the parent's side, x on the child's.
  ReadOptions options;
  options.closuresFile = writeTemp("zx.yaml",
                                   "closed_loop: [['closure_A', 'closure_B']]\ntype: ['6d']\n"
                                   "joint_name: ['free_B']\njoint_type: ['UJOINT_ZX']\n");
  const Mechanism zx = readOrFail(formatPath("five_bar_gepetto.urdf"), options);
  const Joint& universal = zx.joints[*zx.findJoint("free_B")];
  EXPECT_EQ(universal.type, JointType::Universal);
  EXPECT_EQ(universal.axis, Eigen::Vector3d::UnitZ());
  EXPECT_EQ(universal.axis2, Eigen::Vector3d::UnitX());
  EXPECT_EQ(zx.links[universal.link1].name, "distal_right");
  // UJOINT_XY: neither axis is z, so C holds the two distal links' angle: a four-bar (1), Gruebler 0.
  const MobilityReport ujointXy = weldedFiveBarWith("joint_name: ['free_B']\njoint_type: ['UJOINT_XY']\n");
  EXPECT_EQ(ujointXy.dof, 1);
  EXPECT_EQ(ujointXy.grublerKutzbachDof, 0);
  EXPECT_EQ(ujointXy.numRedundant, 1);
  // FIXED: frozen at zero, C is rigid: the four-bar again, in the plane 3*6 - 2*4 - 3*3 = 1.
  const MobilityReport frozen = weldedFiveBarWith("joint_name: ['free_B']\njoint_type: ['FIXED']\n");
  EXPECT_EQ(frozen.mode, "planar");
  EXPECT_EQ(frozen.dof, 1);
  EXPECT_EQ(frozen.grublerKutzbachDof, 1);
  // An older file's rotule_name: every tree joint whose name contains it becomes a ball (free_B alone here).
  const MobilityReport rotule = weldedFiveBarWith("rotule_name: free_\n");
  EXPECT_EQ(rotule.dof, ball.dof);
  EXPECT_EQ(rotule.grublerKutzbachDof, ball.grublerKutzbachDof);
  EXPECT_EQ(rotule.numRedundant, ball.numRedundant);
  // A name that is no tree joint (a typo, which Gepetto's loader passes over) and a type it does not build
  // are warnings; the joints stay as the URDF writes them.
  std::vector<std::string> warnings;
  const MobilityReport unread = weldedFiveBarWith(
      "joint_name: ['free_b', 'elbow_left']\njoint_type: ['SPHERICAL', 'PLANAR']\n", &warnings);
  EXPECT_EQ(unread.dof, 2);
  EXPECT_EQ(unread.mode, "planar");
  EXPECT_TRUE(anyContains(warnings, "joint_name 'free_b'", "not a tree joint"));
  EXPECT_TRUE(anyContains(warnings, "joint_type 'elbow_left'", "'PLANAR'"));
}

TEST(Readers, ClosureFileRebuildErrorsAreOneLine) {
  ReadOptions options;
  // One type per name.
  options.closuresFile = writeTemp("short.yaml",
                                   "closed_loop: [['closure_A', 'closure_B']]\ntype: ['6d']\n"
                                   "joint_name: ['free_B', 'elbow_left']\njoint_type: ['SPHERICAL']\n");
  const Result<Mechanism> shorter = readMechanism(formatPath("five_bar_gepetto.urdf"), options);
  ASSERT_FALSE(isOk(shorter));
  EXPECT_NE(diagnosticOf(shorter).toString().find("1 joint types for 2 joint names"), std::string::npos);
  // A joint a <mimic> couples keeps one value: it cannot become a ball.
  options.closuresFile = writeTemp(
      "coupled.yaml", "closed_loop: []\ntype: []\njoint_name: ['right']\njoint_type: ['SPHERICAL']\n");
  const Result<Mechanism> coupled = readMechanism(formatPath("gripper_mimic.urdf"), options);
  ASSERT_FALSE(isOk(coupled));
  const std::string line = diagnosticOf(coupled).toString();
  EXPECT_NE(line.find("joint_name 'right'"), std::string::npos) << line;
  EXPECT_NE(line.find("coupled"), std::string::npos) << line;
  EXPECT_EQ(line.find('\n'), std::string::npos);
}

// --- SDFormat
// ------------------------------------------------------------------------------------------------

/// Whether this process has mapped libsdformat (its static initialisers have run).
bool libsdformatMapped() {
  return readTextFile("/proc/self/maps").find("libsdformat") != std::string::npos;
}

TEST(SdfReader, LibsdformatIsLoadedOnlyWhenAnSdfFileIsRead) {
  // Each case in a fresh process (a death test re-runs this binary for this test alone), since any earlier
  // test that read an SDF file would have loaded it already.
  ::testing::GTEST_FLAG(death_test_style) = "threadsafe";
  EXPECT_EXIT(
      {
        const bool before = libsdformatMapped();
        readOrFail(formatPath("four_bar_urdfplus.urdf"));
        std::exit(!before && !libsdformatMapped() ? 0 : 1);
      },
      ::testing::ExitedWithCode(0), "");
  EXPECT_EXIT(
      {
        readOrFail(formatPath("four_bar.sdf"));
        std::exit(libsdformatMapped() ? 0 : 1);
      },
      ::testing::ExitedWithCode(0), "");
}

TEST(SdfReader, PosesFollowSdformatFrameSemantics) {
  // four_bar.sdf: the rocker placed relative_to a <frame> and flipped, j4 posed relative to its child and its
  // axis expressed_in the model frame. Read right, the loop's two ends meet at C (0.4, 0.3, 0) and every axis
  // is +z in the world (read without expressed_in, j4's axis would be -z).
  const Mechanism m = readOrFail(formatPath("four_bar.sdf"));
  EXPECT_EQ(m.name, "four_bar_sdf");
  EXPECT_EQ(m.links[m.rootLink].name, "world");
  const Joint& j4 = m.joints[*m.findJoint("j4")];
  EXPECT_EQ(j4.kind, ConnectionKind::LoopJoint);
  EXPECT_EQ(m.joints.back().name, "j4");
  EXPECT_EQ(m.links[j4.link1].name, "coupler");
  EXPECT_EQ(m.links[j4.link2].name, "rocker");
  EXPECT_EQ(m.joints[*m.findJoint("j3")].type, JointType::Continuous);
  const LinkPoses poses = computeTreePoses(m, {});
  EXPECT_TRUE((poses[j4.link1] * j4.frame1.translation()).isApprox(Eigen::Vector3d(0.4, 0.3, 0)));
  EXPECT_TRUE((poses[j4.link2] * j4.frame2.translation()).isApprox(Eigen::Vector3d(0.4, 0.3, 0)));
  for (const Joint& j : m.joints) {
    const Eigen::Vector3d world = poses[j.link1].linear() * j.frame1.linear() * j.axis;
    EXPECT_TRUE(world.isApprox(Eigen::Vector3d::UnitZ())) << j.name << ": " << world.transpose();
  }
  // The rocker's tree joint is at D, where the rocker was placed through the frame pin_d.
  EXPECT_TRUE(poses[*m.findLink("rocker")].translation().isApprox(Eigen::Vector3d(0.4, 0, 0)));
  // A model posed in its world: the model frame is the ground's, the five-bar closes at C.
  const Mechanism five = readOrFail(formatPath("five_bar.sdf"));
  const Joint& c = five.joints.back();
  const LinkPoses p5 = computeTreePoses(five, {});
  EXPECT_TRUE((p5[c.link1] * c.frame1.translation()).isApprox(Eigen::Vector3d(0.15, 0.35, 0)));
  EXPECT_TRUE((p5[c.link2] * c.frame2.translation()).isApprox(Eigen::Vector3d(0.15, 0.35, 0)));
}

TEST(SdfReader, BallAndUniversalJointsInTheTreeOrClosingTheLoop) {
  // A spatial RSUR (crank about z at A, rocker about x at D, coupler on a ball at B, closed by a universal at
  // C) and the RUSR (universal in the tree, ball closing the loop): 6*3 - 5 - 5 - 3 - 4 = 1 = DOF, nothing
  // redundant (general geometry; a universal keeps the coupler from spinning).
  for (const bool universalInTree : {false, true}) {
    SCOPED_TRACE(universalInTree ? "RUSR" : "RSUR");
    const std::string treeType = universalInTree ? "universal" : "ball";
    const std::string loopType = universalInTree ? "ball" : "universal";
    const std::string axes = "<axis><xyz>0 1 0</xyz></axis><axis2><xyz>1 0 0</xyz></axis2>";
    const std::string text = R"(<sdf version="1.9"><model name="rsur">
  <link name="crank"/><link name="coupler"><pose>0 0.2 0 0 0 0</pose></link>
  <link name="rocker"><pose>0.4 0 0 0 0 0</pose></link>
  <joint name="a" type="revolute"><parent>world</parent><child>crank</child><axis><xyz>0 0 1</xyz></axis></joint>
  <joint name="b" type=")" + treeType +
                             R"("><parent>crank</parent><child>coupler</child>)" +
                             (universalInTree ? axes : "") + R"(</joint>
  <joint name="d" type="revolute"><parent>world</parent><child>rocker</child><axis><xyz>1 0 0</xyz></axis></joint>
  <joint name="c" type=")" + loopType +
                             R"("><parent>coupler</parent><child>rocker</child>
    <pose>0 0.1 0.25 0 0 0</pose>)" +
                             (universalInTree ? "" : axes) + R"(</joint></model></sdf>)";
    const Result<Mechanism> m = readMechanismFromString(text, "rsur.sdf");
    ASSERT_TRUE(isOk(m)) << diagnosticOf(m).toString();
    EXPECT_TRUE(valueOf(m).warnings.empty()) << valueOf(m).warnings.front().toString();
    EXPECT_EQ(valueOf(m).joints[*valueOf(m).findJoint("b")].type,
              universalInTree ? JointType::Universal : JointType::Spherical);
    EXPECT_EQ(valueOf(m).joints.back().kind, ConnectionKind::LoopJoint);
    const MobilityReport r = reportOf(valueOf(m), AnalysisMode::Auto);
    EXPECT_EQ(r.mode, "spatial");
    EXPECT_EQ(r.dof, 1);
    EXPECT_EQ(r.grublerKutzbachDof, 1);
    EXPECT_EQ(r.numRedundant, 0);
  }
}

TEST(SdfReader, NeverSilentAndRefusalsAreOneLine) {
  // Warnings: a misspelt <jiont>, a revolute without <axis>, a nested model, a second model in the world.
  const std::string text = R"(<sdf version="1.9"><world name="w"><model name="m">
  <link name="a"/><link name="b"><pose>1 0 0 0 0 0</pose></link>
  <joint name="ja" type="revolute"><parent>world</parent><child>a</child><axis><xyz>0 0 1</xyz></axis></joint>
  <joint name="jb" type="revolute"><parent>a</parent><child>b</child></joint>
  <jiont name="closing" type="revolute"><parent>b</parent><child>a</child></jiont>
  <model name="inner"><link name="i"/></model>
</model><model name="other"><link name="o"/></model></world></sdf>)";
  const Result<Mechanism> m = readMechanismFromString(text, "w.sdf");
  ASSERT_TRUE(isOk(m)) << diagnosticOf(m).toString();
  const std::vector<std::string> w = warningTexts(valueOf(m));
  EXPECT_TRUE(anyContains(w, "jiont 'closing'", "did you mean <joint>")) << ::testing::PrintToString(w);
  EXPECT_TRUE(anyContains(w, "joint 'jb'", "has no <axis>"));
  EXPECT_TRUE(anyContains(w, "model 'inner'", "nested model"));
  EXPECT_TRUE(anyContains(w, "model 'other'", "only the first model"));
  EXPECT_EQ(reportOf(valueOf(m), AnalysisMode::Auto).warnings.size(), w.size());
  ReadOptions strict;
  strict.strict = true;
  const Result<Mechanism> s = readMechanismFromString(text, "w.sdf", strict);
  ASSERT_FALSE(isOk(s));
  EXPECT_NE(diagnosticOf(s).what.find("--strict"), std::string::npos);
  // Refusals, each naming its element in one line.
  const std::string head = R"(<sdf version="1.9"><model name="m"><link name="a"/><link name="b"/>
  <joint name="ja" type="revolute"><parent>world</parent><child>a</child><axis><xyz>0 0 1</xyz></axis></joint>)";
  struct Refusal {
    const char* label;
    std::string text;
    const char* kind;
    const char* mention;
  };
  const std::vector<Refusal> refusals = {
      {"screw",
       head +
           R"(<joint name="jb" type="screw"><parent>a</parent><child>b</child><axis><xyz>0 0 1</xyz></axis></joint></model></sdf>)",
       "joint", "screw"},
      {"zero axis",
       head +
           R"(<joint name="jb" type="revolute"><parent>a</parent><child>b</child><axis><xyz>0 0 0</xyz></axis></joint></model></sdf>)",
       "", "norm of the xyz vector"},  // libsdformat's own refusal, which names no element
      {"backwards",
       head +
           R"(<joint name="jb" type="revolute"><parent>b</parent><child>a</child><axis><xyz>0 0 1</xyz></axis></joint></model></sdf>)",
       "link", "not reached"},
      {"unknown link",
       head +
           R"(<joint name="jb" type="revolute"><parent>a</parent><child>c&#10;x</child><axis><xyz>0 0 1</xyz></axis></joint></model></sdf>)",
       "", "c"},
      {"out of range",
       head +
           R"(<joint name="jb" type="revolute"><parent>a</parent><child>b</child><pose>1e300 0 0 0 0 0</pose><axis><xyz>0 0 1</xyz></axis></joint></model></sdf>)",
       "joint", "range"},
      {"not xml", "<sdf version='1.9'><model name='m'>\n<link", "", ""},
  };
  for (const Refusal& r : refusals) {
    SCOPED_TRACE(r.label);
    const Result<Mechanism> bad = readMechanismFromString(r.text, "bad.sdf");
    ASSERT_FALSE(isOk(bad));
    expectOneLine(diagnosticOf(bad).toString());
    if (*r.kind != '\0')
      EXPECT_EQ(diagnosticOf(bad).elementKind, r.kind) << diagnosticOf(bad).toString();
    EXPECT_NE(diagnosticOf(bad).toString().find(r.mention), std::string::npos)
        << diagnosticOf(bad).toString();
  }
}

TEST(SdfReader, TheFrontDoorKnowsSdfByItsRootOrItsExtension) {
  // The same four-bar from the file, from its text, and from a copy whose name ends in .sdf.
  const std::string text = readTextFile(formatPath("four_bar.sdf"));
  const Result<Mechanism> fromText = readMechanismFromString(text, "robot_description");
  ASSERT_TRUE(isOk(fromText)) << diagnosticOf(fromText).toString();
  EXPECT_EQ(valueOf(fromText).name, "four_bar_sdf");
  EXPECT_EQ(valueOf(fromText).file, "robot_description");
  const Result<Mechanism> bad = readMechanism(writeTemp("empty.sdf", "<nothing/>"));
  ASSERT_FALSE(isOk(bad));
  EXPECT_NE(diagnosticOf(bad).toString().find("empty.sdf"), std::string::npos);
  EXPECT_NE(diagnosticOf(bad).toString().find("libsdformat"), std::string::npos)
      << diagnosticOf(bad).toString();
}

TEST(Warnings, AMisspeltLoopInMjcfOrAClosureFileIsNeverAnOpenTree) {
  // MJCF: MuJoCo's schema refuses <conect> (exit 2), so the leg is never read without its plantar loop.
  std::string mjcf = readTextFile(formatPath("cassie_leg_mjcf.xml"));
  mjcf = std::regex_replace(mjcf, std::regex("<connect name=\"plantar\""), "<conect name=\"plantar\"");
  const Result<Mechanism> m = readMechanismFromString(mjcf, "leg.xml");
  ASSERT_FALSE(isOk(m));
  EXPECT_NE(diagnosticOf(m).what.find("conect"), std::string::npos) << diagnosticOf(m).toString();
  expectOneLine(diagnosticOf(m).toString());
  // Closure file: 'closed_loops' is not the key, and a closure file without closed_loop is refused.
  ReadOptions options;
  options.closuresFile = writeTemp("typo.yaml", "closed_loops: [['closure_A', 'closure_B']]\ntype: ['6d']\n");
  const Result<Mechanism> y = readMechanism(formatPath("five_bar_gepetto.urdf"), options);
  ASSERT_FALSE(isOk(y));
  EXPECT_NE(diagnosticOf(y).toString().find("'closed_loop': is missing"), std::string::npos)
      << diagnosticOf(y).toString();
}
