/// Balls written as three revolutes (Gepetto's way): found where the axes meet and span space, merged into
/// one spherical joint for the passive-freedom search, with the published models' closed forms.
#include "mobility_analysis/analysis/CompositeBalls.hpp"

#include <string>

#include <gtest/gtest.h>

#include "core/TestModels.hpp"

using namespace mobility_analysis;

namespace {

/// A rod hangs from the ground by three revolutes r0, r1, r2 (axes @p a0, @p a1, @p a2, r1 placed @p offset
/// from r0) at (0.2, 0.1, 0.3), and its other end, 1 m below, is held by a spherical loop joint to a base
/// welded to the ground (a second link: a rod between two balls on the ground alone is output, not idle).
/// With the axes meeting at one point and spanning space the three revolutes are a ball: the rod can only
/// spin about the line through its two ends (DOF 1, passive; the bottom ball's equation along the rod is
/// redundant).
std::string rodOnThreeRevolutes(const char* a0, const char* a1, const char* a2, const char* offset = "0 0 0",
                                const char* extra = "") {
  auto joint = [](const char* name, const char* parent, const char* child, const char* origin,
                  const char* axis) {
    return std::string("<joint name=\"") + name + "\" type=\"revolute\"><parent link=\"" + parent +
           "\"/><child link=\"" + child + "\"/><origin xyz=\"" + origin + "\"/><axis xyz=\"" + axis +
           "\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint>\n";
  };
  return std::string(
             "<robot name=\"ball_as_revolutes\">\n"
             "<link name=\"ground\"/><link name=\"s1\"/><link name=\"s2\"/><link name=\"rod\"/>\n"
             "<link name=\"base\"/><joint name=\"weld\" type=\"fixed\"><parent link=\"ground\"/>"
             "<child link=\"base\"/></joint>\n") +
         joint("r0", "ground", "s1", "0.2 0.1 0.3", a0) + joint("r1", "s1", "s2", offset, a1) +
         joint("r2", "s2", "rod", "0 0 0", a2) +
         "<loop_joint name=\"bottom\" type=\"spherical\"><link1 link=\"rod\" xyz=\"0 0 -1\"/>"
         "<link2 link=\"base\" xyz=\"0.2 0.1 -0.7\"/></loop_joint>\n" +
         extra + "</robot>";
}

Mechanism fromText(const std::string& urdf) {
  Result<Mechanism> mechanism = readMechanismFromString(urdf, "ball_as_revolutes.urdf");
  EXPECT_TRUE(isOk(mechanism)) << (isOk(mechanism) ? "" : diagnosticOf(mechanism).toString());
  return isOk(mechanism) ? valueOf(std::move(mechanism)) : Mechanism{};
}

std::vector<CompositeBall> ballsAtWrittenPose(const Mechanism& mechanism) {
  return findCompositeBalls(mechanism, computeTreePoses(mechanism, {}), 1.0);
}

MobilityReport spatialReport(const Mechanism& mechanism) {
  AnalysisOptions options;
  options.mode = AnalysisMode::Spatial;
  const Result<MobilityAnalysis> analysis = analyzeMechanism(mechanism, options);
  EXPECT_TRUE(isOk(analysis)) << (isOk(analysis) ? "" : diagnosticOf(analysis).toString());
  return isOk(analysis) ? valueOf(analysis).report : MobilityReport{};
}

Mechanism gepetto(const std::string& urdf, const std::string& closures) {
  ReadOptions options;
  options.closuresFile = fixturePath("formats/" + closures);
  Result<Mechanism> mechanism = readMechanism(fixturePath("formats/" + urdf), options);
  EXPECT_TRUE(isOk(mechanism)) << (isOk(mechanism) ? "" : diagnosticOf(mechanism).toString());
  return isOk(mechanism) ? valueOf(std::move(mechanism)) : Mechanism{};
}

}  // namespace

TEST(CompositeBalls, ThreeRevolutesWhoseAxesMeetAndSpanSpaceAreABall) {
  for (const char* a1 : {"0 1 0", "0.6 0.8 0"}) {  // orthogonal axes, and axes at 53 degrees
    SCOPED_TRACE(a1);
    const Mechanism mechanism = fromText(rodOnThreeRevolutes("1 0 0", a1, "0 0.6 0.8"));
    const std::vector<CompositeBall> balls = ballsAtWrittenPose(mechanism);
    ASSERT_EQ(balls.size(), 1u);
    auto name = [&](int joint) { return mechanism.joints[static_cast<size_t>(joint)].name; };
    EXPECT_EQ(name(balls[0].joints[0]) + name(balls[0].joints[1]) + name(balls[0].joints[2]), "r0r1r2");
    EXPECT_EQ(mechanism.links[static_cast<size_t>(balls[0].end1)].name, "ground");
    EXPECT_EQ(mechanism.links[static_cast<size_t>(balls[0].end2)].name, "rod");
    EXPECT_LT((balls[0].center - Eigen::Vector3d(0.2, 0.1, 0.3)).norm(), 1e-12);
    // The rod between two balls: it spins about the line through them and nothing else moves (Tsai).
    const MobilityReport report = spatialReport(mechanism);
    EXPECT_EQ(report.dof, 1);
    EXPECT_EQ(report.passiveDof, 1);
    EXPECT_EQ(report.outputDof, 0);
    ASSERT_EQ(report.passiveMotions.size(), 1u);
    EXPECT_EQ(report.passiveMotions[0].links, std::vector<std::string>{"rod"});
    EXPECT_EQ(report.passiveMotions[0].description,
              "link rod spins about the line through its ball joints r0+r1+r2 and bottom");
  }
}

TEST(CompositeBalls, AxesThatMissEachOtherOrLieInOnePlaneAreNoBall) {
  // r1 1 cm off r0's axis: the axes do not meet.
  EXPECT_TRUE(
      ballsAtWrittenPose(fromText(rodOnThreeRevolutes("1 0 0", "0 1 0", "0 0 1", "0 0.01 0"))).empty());
  // Gimbal lock: r2 parallel to r0, the three axes in one plane span no space.
  EXPECT_TRUE(ballsAtWrittenPose(fromText(rodOnThreeRevolutes("1 0 0", "0 1 0", "1 0 0"))).empty());
  // A revolute driven by another through a mimic is not free to make a ball.
  const std::string mimic = rodOnThreeRevolutes(
      "1 0 0", "0 1 0", "0 0 1", "0 0 0",
      "<link name=\"crank\"/><joint name=\"drive\" type=\"revolute\"><parent link=\"ground\"/>"
      "<child link=\"crank\"/><axis xyz=\"0 0 1\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" "
      "velocity=\"1\"/></joint>\n");
  ASSERT_EQ(ballsAtWrittenPose(fromText(mimic)).size(), 1u);
  std::string coupled = mimic;
  coupled.replace(
      coupled.find("<limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint>\n<joint "
                   "name=\"r2\""),
      0, "<mimic joint=\"drive\"/>");
  EXPECT_TRUE(ballsAtWrittenPose(fromText(coupled)).empty());
}

TEST(CompositeBalls, GepettoDeltaSplitsLikeTheReferenceDelta) {
  // DESIGN.md 5: Delta robot with ball-jointed parallelogram rods, 9 = 6 passive (rod spins) + 3 output.
  // The reference writes its balls as spherical joints; the Gepetto file as three revolutes each (7 balls).
  const Mechanism delta = gepetto("delta_gepetto.urdf", "delta_3d.yaml");
  EXPECT_EQ(ballsAtWrittenPose(delta).size(), 7u);
  const MobilityReport report = spatialReport(delta);
  const MobilityReport reference = spatialReport(loadOrFail(urdfPath("delta_robot.urdf")));
  EXPECT_EQ(reference.passiveDof, 6);
  EXPECT_EQ(report.dof, reference.dof);
  EXPECT_EQ(report.passiveDof, reference.passiveDof);
  EXPECT_EQ(report.outputDof, reference.outputDof);
}

TEST(CompositeBalls, GepettoCassieLegsCutRodsSpinAsOneBody) {
  // Each rod is two halves with their closure frames welded at the middle (6d): one rigid body of four
  // links between two three-revolute balls. The fixture's closed form: 7 = 5 motors + 2 rod spins.
  const MobilityReport report = spatialReport(gepetto("cassie_leg_gepetto.urdf", "cassie_leg_6d.yaml"));
  EXPECT_EQ(report.dof, 7);
  EXPECT_EQ(report.passiveDof, 2);
  EXPECT_EQ(report.outputDof, 5);
}

TEST(CompositeBalls, TheMergedMechanismMovesAsTheWrittenOne) {
  // Three revolutes meeting at a point are locally a ball: the merged Delta (each of the 7 balls one
  // spherical joint, its two inner links gone) closes at the same pose and has the written one's DOF, the
  // nullity of its own Jacobian there.
  const Mechanism delta = gepetto("delta_gepetto.urdf", "delta_3d.yaml");
  const LinkPoses poses = computeTreePoses(delta, {});
  const MechanismWithBalls merged = mergeCompositeBalls(delta, poses, findCompositeBalls(delta, poses, 1.0));
  EXPECT_EQ(merged.mechanism.links.size(), delta.links.size() - 14);
  EXPECT_EQ(merged.mechanism.joints.size(), delta.joints.size() - 14);
  const Result<CoordinateModel> model =
      buildCoordinateModel(merged.mechanism, merged.poses, AnalysisMode::Spatial, 1.0);
  ASSERT_TRUE(isOk(model)) << diagnosticOf(model).toString();
  const Eigen::VectorXd q = computeCoordinates(valueOf(model), merged.poses);
  Eigen::VectorXd residual;
  computeConstraintResidual(valueOf(model), q, residual);
  EXPECT_LT(residual.cwiseAbs().maxCoeff(), 1e-12);
  const OrderedRank ranks =
      computeOrderedRank(computeConstraintJacobian(valueOf(model), q), tolerances::kRank);
  EXPECT_EQ(ranks.dof(), 9);
}

TEST(CompositeBalls, SameSplitInMillimetresAndTurnedInSpace) {
  // The axes must meet within a fraction of Lc, so the test scales with the model: the Gepetto Delta in
  // millimetres, turned 0.7 rad about (1, 2, 3) (every joint from the ground turned, the rest follows).
  Mechanism delta = gepetto("delta_gepetto.urdf", "delta_3d.yaml");
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (Joint& joint : delta.joints) {
    joint.frame1.translation() *= 1000.0;
    joint.frame2.translation() *= 1000.0;
    if (joint.link1 == delta.rootLink) {
      joint.frame1.translation() = turn * joint.frame1.translation();
      joint.frame1.linear() = turn * joint.frame1.linear();
    }
  }
  const MobilityReport report = spatialReport(delta);
  EXPECT_LT(report.characteristicLength, 1e3);
  EXPECT_GT(report.characteristicLength, 1e2);
  EXPECT_EQ(report.dof, 9);
  EXPECT_EQ(report.passiveDof, 6);
  EXPECT_EQ(report.outputDof, 3);
}

TEST(CompositeBalls, MjcfHingeTripleInOneBodyIsABall) {
  // MuJoCo composes a body's joints in series at their positions: three hinges at one point, then a connect
  // at the rod's other end to a body welded to the world. The rod spins about the line through both.
  const char* mjcf = R"(<mujoco model="hinge_triple"><worldbody>
    <body name="base"><body name="rod" pos="0.2 0.1 0.3">
      <joint name="hx" type="hinge" axis="1 0 0"/><joint name="hy" type="hinge" axis="0 1 0"/>
      <joint name="hz" type="hinge" axis="0 0 1"/><geom type="capsule" fromto="0 0 0 0 0 -1" size="0.01"/>
    </body></body>
    <body name="anchor" pos="0.5 0.1 -0.7"><geom type="sphere" size="0.02"/></body>
  </worldbody><equality><connect name="bottom" body1="rod" body2="anchor" anchor="0 0 -1"/></equality></mujoco>)";
  const Result<Mechanism> mechanism = readMechanismFromString(mjcf, "hinge_triple.xml");
  ASSERT_TRUE(isOk(mechanism)) << diagnosticOf(mechanism).toString();
  EXPECT_EQ(ballsAtWrittenPose(valueOf(mechanism)).size(), 1u);
  const MobilityReport report = spatialReport(valueOf(mechanism));
  EXPECT_EQ(report.dof, 1);
  EXPECT_EQ(report.passiveDof, 1);
  ASSERT_EQ(report.passiveMotions.size(), 1u);
  EXPECT_EQ(report.passiveMotions[0].description,
            "link rod spins about the line through its ball joints hx+hy+hz and bottom");
}
