#include "mobility_analysis/motion/DrivenAssembly.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <sys/wait.h>

#include "core/CliRun.hpp"
#include "core/TestModels.hpp"

using namespace mobility_analysis;

namespace {

std::string motionFixture(const std::string& name) {
  return fixturePath("motion/" + name);
}

/// Analyses @p path with @p positions driven; fails the test with the diagnostic when it cannot.
MobilityAnalysis drive(const std::string& path, const JointPositions& positions) {
  const Mechanism mechanism = loadOrFail(path);
  AnalysisOptions options;
  options.positions = positions;
  Result<MobilityAnalysis> analysis = analyzeMechanism(mechanism, options);
  if (!isOk(analysis)) {
    ADD_FAILURE() << diagnosticOf(analysis).toString();
    return MobilityAnalysis{};
  }
  return valueOf(std::move(analysis));
}

double reported(const MobilityReport& report, const std::string& joint) {
  for (const JointValue& v : report.positions)
    if (v.name == joint)
      return v.value;
  ADD_FAILURE() << "no position for " << joint;
  return NAN;
}

double wrap(double angle) {
  return std::remainder(angle, 2.0 * M_PI);
}

// The crank-rocker of test/fixtures/motion/crank_rocker.urdf: ground pins A = 0 and D = (4, 0), crank 1.5,
// coupler 3.5, rocker 3, written at crank angle 60 deg with C on the left of B -> D.
constexpr double kA = 1.5, kB = 3.5, kC = 3.0, kD = 4.0;
constexpr double kCrank0 = M_PI / 3.0;

/// Closed-form position analysis: C from the crank angle, on the left of B -> D.
Eigen::Vector2d couplerPoint(double crankAngle) {
  const Eigen::Vector2d b = kA * Eigen::Vector2d(std::cos(crankAngle), std::sin(crankAngle));
  const Eigen::Vector2d d(kD, 0.0);
  const double l = (d - b).norm();
  const double x = (kB * kB - kC * kC + l * l) / (2.0 * l);
  const Eigen::Vector2d u = (d - b) / l;
  return b + x * u + std::sqrt(kB * kB - x * x) * Eigen::Vector2d(-u.y(), u.x());
}

}  // namespace

TEST(DrivenAssembly, CrankRockerFollowsTheClosedFormOnItsWrittenBranch) {
  const Mechanism mechanism = loadOrFail(motionFixture("crank_rocker.urdf"));
  const int rocker = *mechanism.findLink("rocker");
  for (const double target : {-1.0, 0.5, 2.0, 4.0, 2.0 * M_PI + 0.3, -5.0}) {
    SCOPED_TRACE(target);
    const MobilityAnalysis a = drive(motionFixture("crank_rocker.urdf"), {{"j1", target}});
    // Held exactly, and read back from the poses.
    EXPECT_EQ(reported(a.report, "j1"), target);
    const JointPositions back = computeJointPositions(mechanism, a.assembled.poses, {{"j1", target}});
    EXPECT_NEAR(back.at("j1"), target, 1e-9);
    // On the written branch: C where the closed form puts it.
    const Eigen::Vector2d expected = couplerPoint(kCrank0 + target);
    const Eigen::Vector3d c = a.assembled.poses[rocker].translation();
    EXPECT_NEAR((c.head<2>() - expected).norm(), 0.0, 1e-9)
        << c.transpose() << " vs " << expected.transpose();
    EXPECT_LE(a.report.assembly.residual, 1e-12 * a.report.characteristicLength);
    EXPECT_GT(a.report.assembly.steps, 0);
    EXPECT_EQ(a.report.dof, 1);
  }
}

TEST(DrivenAssembly, SameAnswerForTheFileRotatedAndInMillimetres) {
  const MobilityAnalysis metres = drive(motionFixture("crank_rocker.urdf"), {{"j1", 2.0}});
  const MobilityAnalysis turned = drive(motionFixture("crank_rocker_rotated_mm.urdf"), {{"j1", 2.0}});
  for (const char* joint : {"j1", "j2", "j3"}) {
    EXPECT_NEAR(reported(metres.report, joint), reported(turned.report, joint), 1e-9) << joint;
  }
  EXPECT_EQ(metres.report.assembly.steps, turned.report.assembly.steps);
  EXPECT_LE(turned.report.assembly.residual, 1e-12 * turned.report.characteristicLength);
}

TEST(DrivenAssembly, ValueBeyondADeadPointNamesTheJointTheRequestAndTheLastValueReached) {
  // j3 is the coupler-rocker angle psi; by the cosine rule on triangle BCD its range on this branch ends
  // where the crank lines up with the ground (|BD| = d - a or d + a): the transmission angle's extremes.
  const Mechanism mechanism = loadOrFail(motionFixture("crank_rocker.urdf"));
  const Eigen::Vector2d b0 = kA * Eigen::Vector2d(std::cos(kCrank0), std::sin(kCrank0));
  const Eigen::Vector2d c0 = couplerPoint(kCrank0);
  const Eigen::Vector2d d(kD, 0.0);
  const double coupler0 = std::atan2((c0 - b0).y(), (c0 - b0).x());
  const double rocker0 = std::atan2((d - c0).y(), (d - c0).x());
  const double psi0 = wrap(rocker0 - coupler0);
  auto psiAt = [&](double bd) {  // |psi| = pi - mu, cos mu = (b^2 + c^2 - bd^2) / (2 b c), same sign as psi0
    const double mu = std::acos((kB * kB + kC * kC - bd * bd) / (2.0 * kB * kC));
    return std::copysign(M_PI - mu, psi0);
  };
  const double limitA = psiAt(kD - kA) - psi0, limitB = psiAt(kD + kA) - psi0;
  for (const double target : {3.0, -3.0}) {
    AnalysisOptions options;
    options.positions = {{"j3", target}};
    const Result<MobilityAnalysis> analysis = analyzeMechanism(mechanism, options);
    ASSERT_FALSE(isOk(analysis)) << target;
    const Diagnostic& diag = diagnosticOf(analysis);
    EXPECT_EQ(diag.elementName, "j3");
    EXPECT_NE(diag.what.find(target > 0 ? "3 rad" : "-3 rad"), std::string::npos) << diag.toString();
    const size_t at = diag.what.find("stops at ");
    ASSERT_NE(at, std::string::npos) << diag.toString();
    const double last = std::strtod(diag.what.c_str() + at + 9, nullptr);
    const double limit = target > 0 ? std::max(limitA, limitB) : std::min(limitA, limitB);
    EXPECT_NEAR(last, limit, 1e-4) << diag.toString();
  }
}

TEST(DrivenAssembly, BennettDrivenKeepsItsClosure) {
  // DESIGN.md §5: tan(t1/2) tan(t2/2) = sin((beta+alpha)/2) / sin((beta-alpha)/2), t3 = -t1; the file writes
  // t1 = 100 deg into j1's origin, so t1 = 100 deg + j1, t2 = t2(written) + j2, t3 = -t1 means j3 = -j1.
  const double alpha = 40.0 * M_PI / 180.0, beta = 70.0 * M_PI / 180.0;
  const double k = std::sin((beta + alpha) / 2.0) / std::sin((beta - alpha) / 2.0);
  const double t1Written = 100.0 * M_PI / 180.0;
  const double t2Written = 2.0 * std::atan(k / std::tan(t1Written / 2.0));
  for (const double j1 : {-0.3, 0.4, 1.0}) {
    SCOPED_TRACE(j1);
    const MobilityAnalysis a = drive(urdfPath("bennett.urdf"), {{"j1", j1}});
    EXPECT_EQ(reported(a.report, "j1"), j1);
    EXPECT_NEAR(wrap(reported(a.report, "j3") + j1), 0.0, 1e-9);
    const double t1 = t1Written + j1, t2 = t2Written + reported(a.report, "j2");
    EXPECT_NEAR(std::tan(t1 / 2.0) * std::tan(t2 / 2.0), k, 1e-9);
    EXPECT_EQ(a.report.dof, 1);
    EXPECT_LE(a.report.assembly.residual, 1e-12 * a.report.characteristicLength);
  }
}

TEST(DrivenAssembly, FollowingAMotionInSeveralCallsEndsWhereOneCallDoes) {
  // The node's use: each call starts from the previous state. A full turn of the crank and more is unwrapped
  // continuously, and a crank-rocker comes back to the same pose on the same branch after a turn.
  const Mechanism mechanism = loadOrFail(motionFixture("crank_rocker.urdf"));
  LinkPoses state = computeTreePoses(mechanism, {});
  JointPositions previous;
  for (const double j1 : {2.0, 4.0, 6.0, 2.0 * M_PI + 1.0}) {
    DrivenMotionSettings settings;
    settings.reference = previous;
    const Result<DrivenMotion> moved = followDrivenPositions(mechanism, state, {{"j1", j1}}, settings);
    ASSERT_TRUE(isOk(moved)) << diagnosticOf(moved).toString();
    state = valueOf(moved).poses;
    previous = valueOf(moved).positions;
    EXPECT_EQ(previous.at("j1"), j1);
  }
  const Result<DrivenMotion> once =
      followDrivenPositions(mechanism, computeTreePoses(mechanism, {}), {{"j1", 1.0}});
  ASSERT_TRUE(isOk(once));
  for (size_t l = 0; l < state.size(); ++l) {
    EXPECT_TRUE(state[l].isApprox(valueOf(once).poses[l], 1e-9)) << mechanism.links[l].name;
  }
  // The coupler's relative angle went round with the crank and back: unwrapped, it ends near its one-call
  // value.
  EXPECT_NEAR(wrap(previous.at("j2") - valueOf(once).positions.at("j2")), 0.0, 1e-9);
}

TEST(DrivenAssembly, AnalysisFromThePreviousStateContinuesFromIt) {
  // AnalysisOptions::startPoses is how the node follows a motion: from the state reached at j1 = 2 on to 2.5
  // is where one run from the written pose to 2.5 ends.
  const Mechanism mechanism = loadOrFail(motionFixture("crank_rocker.urdf"));
  const MobilityAnalysis first = drive(motionFixture("crank_rocker.urdf"), {{"j1", 2.0}});
  AnalysisOptions options;
  options.positions = {{"j1", 2.5}};
  options.startPoses = first.assembled.poses;
  const Result<MobilityAnalysis> next = analyzeMechanism(mechanism, options);
  ASSERT_TRUE(isOk(next)) << diagnosticOf(next).toString();
  const MobilityAnalysis direct = drive(motionFixture("crank_rocker.urdf"), {{"j1", 2.5}});
  for (size_t l = 0; l < mechanism.links.size(); ++l) {
    EXPECT_TRUE(valueOf(next).assembled.poses[l].isApprox(direct.assembled.poses[l], 1e-9))
        << mechanism.links[l].name;
  }
  EXPECT_LT(valueOf(next).report.assembly.steps,
            direct.report.assembly.steps);  // it only went the last 0.5 rad
}

TEST(DrivenAssembly, DrakeFourBarWrittenStraightIsClosedThenDriven) {
  const Mechanism mechanism = loadOrFail(motionFixture("drake_four_bar2_straight.urdf"));
  const Result<DrivenMotion> moved =
      followDrivenPositions(mechanism, computeTreePoses(mechanism, {}), {{"joint_0", 1.0}});
  ASSERT_TRUE(isOk(moved)) << diagnosticOf(moved).toString();
  EXPECT_EQ(valueOf(moved).positions.at("joint_0"), 1.0);
  EXPECT_LE(valueOf(moved).residual, 1e-12);
  const double lc = computeCharacteristicLength(mechanism, computeTreePoses(mechanism, {}));
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    EXPECT_LT(computeJointResidual(mechanism, valueOf(moved).poses, static_cast<int>(j), lc), 1e-9)
        << mechanism.joints[j].name;
  }
}

TEST(DrivenAssembly, UnknownOrMultiFreedomJointIsRefused) {
  const Mechanism mechanism = loadOrFail(motionFixture("crank_rocker.urdf"));
  const Result<DrivenMotion> loop =
      followDrivenPositions(mechanism, computeTreePoses(mechanism, {}), {{"j4", 0.1}});
  ASSERT_FALSE(isOk(loop));
  EXPECT_EQ(diagnosticOf(loop).elementName, "j4");
}

TEST(DrivenAssembly, SphericalFourBarHoldsItsCrankAndFollowsTheConeIntersection) {
  // test/fixtures/motion/spherical_4r.urdf: u1 = z, u4 = (sin 70, 0, cos 70), crank arc 30 deg written at
  // azimuth 90 deg, coupler and rocker arcs 60 deg; u3 lies on the cones of 60 deg about u2 and u4, on the
  // side of u2 x u4.
  const Mechanism mechanism = loadOrFail(motionFixture("spherical_4r.urdf"));
  const double deg = M_PI / 180.0;
  const Eigen::Vector3d u4(std::sin(70 * deg), 0.0, std::cos(70 * deg));
  for (const double j1 : {0.6, -0.8, 1.5}) {
    SCOPED_TRACE(j1);
    const MobilityAnalysis a = drive(motionFixture("spherical_4r.urdf"), {{"j1", j1}});
    EXPECT_EQ(reported(a.report, "j1"), j1);
    const double azimuth = 90 * deg + j1;
    const Eigen::Vector3d u2(std::sin(30 * deg) * std::cos(azimuth), std::sin(30 * deg) * std::sin(azimuth),
                             std::cos(30 * deg));
    const double c = std::cos(60 * deg), c24 = u2.dot(u4);
    const double p = (c - c * c24) / (1 - c24 * c24), q = (c - c * c24) / (1 - c24 * c24);
    const Eigen::Vector3d base = p * u2 + q * u4;
    const Eigen::Vector3d u3 = base + std::sqrt(1.0 - base.squaredNorm()) * u2.cross(u4).normalized();
    const Eigen::Vector3d reached = a.assembled.poses[*mechanism.findLink("rocker")].linear().col(2);
    EXPECT_NEAR((reached - u3).norm(), 0.0, 1e-9) << reached.transpose() << " vs " << u3.transpose();
    EXPECT_LE(a.report.assembly.residual, 1e-12 * a.report.characteristicLength);
  }
}

TEST(DrivenAssembly, StewartLegsDrivenReachTheirLengths) {
  // Every leg is a lower and an upper link on a prismatic joint between two balls: after driving slide i by
  // s_i the ball centres are L_i + s_i apart (L_i as written), whatever the platform does.
  const Mechanism mechanism = loadOrFail(motionFixture("stewart_6sps.urdf"));
  const LinkPoses written = computeTreePoses(mechanism, {});
  auto legLength = [&](const LinkPoses& poses, int leg) {
    const Joint& base = mechanism.joints[*mechanism.findJoint("ball" + std::to_string(leg) + "_base")];
    const Joint& top = mechanism.joints[*mechanism.findJoint("ball" + std::to_string(leg) + "_top")];
    return ((poses[base.link2] * base.frame2.translation()) - (poses[top.link2] * top.frame2.translation()))
        .norm();
  };
  const JointPositions slides = {{"slide1", 0.03}, {"slide2", -0.02}, {"slide3", 0.05},
                                 {"slide4", 0.01}, {"slide5", -0.04}, {"slide6", 0.02}};
  const MobilityAnalysis all = drive(motionFixture("stewart_6sps.urdf"), slides);
  for (int leg = 1; leg <= 6; ++leg) {
    const double s = slides.at("slide" + std::to_string(leg));
    EXPECT_NEAR(reported(all.report, "slide" + std::to_string(leg)), s, 1e-12);
    EXPECT_NEAR(legLength(all.assembled.poses, leg), legLength(written, leg) + s, 1e-9) << leg;
  }
  EXPECT_EQ(all.report.dof, 12);
  // One leg alone is held as asked too (the platform follows by least change).
  const MobilityAnalysis one = drive(motionFixture("stewart_6sps.urdf"), {{"slide1", 0.03}});
  EXPECT_EQ(reported(one.report, "slide1"), 0.03);
  EXPECT_NEAR(legLength(one.assembled.poses, 1), legLength(written, 1) + 0.03, 1e-9);
}

TEST(DrivenAssembly, PeaucellierDrivenTwentyDegreesStaysAnInversor) {
  // urdf/peaucellier.urdf: O = 0, A = (1, 0), crank AP 1, arms OB = OD = 3, rhombus side 1.5, written at a
  // crank angle of 30 deg with B on the left of O -> P. In its assembly mode O, P, Q are collinear, |OP| |OQ|
  // = 3^2 - 1.5^2 and Q runs on the line x = 3.375; the folded modes (B = D, or Q = P) break all three.
  const Mechanism mechanism = loadOrFail(urdfPath("peaucellier.urdf"));
  const Joint& bqdq = mechanism.joints[*mechanism.findJoint("bq_dq")];
  for (const double degrees : {20.0, -20.0}) {
    SCOPED_TRACE(degrees);
    const double target = degrees * M_PI / 180.0;
    const MobilityAnalysis a = drive(urdfPath("peaucellier.urdf"), {{"a_crank", target}});
    EXPECT_EQ(reported(a.report, "a_crank"), target);
    const LinkPoses& poses = a.assembled.poses;
    const Eigen::Vector3d p = poses[*mechanism.findLink("pb")].translation();
    const Eigen::Vector3d b = poses[*mechanism.findLink("bq")].translation();
    const Eigen::Vector3d d = poses[*mechanism.findLink("dq")].translation();
    const Eigen::Vector3d q = (poses[bqdq.link1] * bqdq.frame1).translation();
    // P where the crank puts it: the angle is held.
    const double crank = 30.0 * M_PI / 180.0 + target;
    EXPECT_NEAR((p - Eigen::Vector3d(1.0 + std::cos(crank), std::sin(crank), 0.0)).norm(), 0.0, 1e-9);
    EXPECT_NEAR(p.norm() * q.norm(), 6.75, 1e-9);
    EXPECT_NEAR(q.x(), 3.375, 1e-9);
    EXPECT_NEAR(p.cross(q).norm(), 0.0, 1e-9);  // O, P, Q collinear
    EXPECT_GT(p.cross(b).z(), 0.1);             // B still on the left of O -> P
    EXPECT_LT(p.cross(d).z(), -0.1);            // D on the right: the rhombus is not folded
    EXPECT_EQ(a.report.dof, 1);
    EXPECT_LE(a.report.assembly.residual, 1e-12 * a.report.characteristicLength);
  }
  // |OP| = 2 cos(crank / 2) cannot fall below arm - side = 1.5: the crank stops at 2 acos(0.75) = 82.8 deg.
  AnalysisOptions options;
  options.positions = {{"a_crank", 1.0}};
  const Result<MobilityAnalysis> beyond = analyzeMechanism(mechanism, options);
  ASSERT_FALSE(isOk(beyond));
  EXPECT_EQ(diagnosticOf(beyond).elementName, "a_crank");
  const std::string& what = diagnosticOf(beyond).what;
  const size_t at = what.find("stops at ");
  ASSERT_NE(at, std::string::npos) << what;
  EXPECT_NEAR(std::strtod(what.c_str() + at + 9, nullptr), 2.0 * std::acos(0.75) - M_PI / 6.0, 1e-4) << what;
}

TEST(DrivenAssemblyCli, TextReportSaysWhereItEndedAndUnreachableValuesExitTwo) {
  const CliRun moved = runReport(motionFixture("crank_rocker.urdf") + " --positions j1=2");
  EXPECT_EQ(moved.status, 0) << moved.err;
  EXPECT_NE(moved.out.find("positions reached [rad or m]: j1 2,"), std::string::npos) << moved.out;
  EXPECT_NE(moved.out.find("continuation steps"), std::string::npos) << moved.out;
  const CliRun json = runReport(motionFixture("crank_rocker.urdf") + " --positions j1=2 --json");
  EXPECT_NE(json.out.find("\"positions\": {\"j1\": 2,"), std::string::npos) << json.out;

  const CliRun beyond = runReport(motionFixture("crank_rocker.urdf") + " --positions j3=3");
  EXPECT_EQ(beyond.status, 2);
  EXPECT_TRUE(beyond.out.empty()) << beyond.out;
  EXPECT_EQ(std::count(beyond.err.begin(), beyond.err.end(), '\n'), 1) << beyond.err;
  EXPECT_NE(beyond.err.find("'j3': 3 rad cannot be reached"), std::string::npos) << beyond.err;
}

TEST(DrivenAssembly, ParallelogramCrossesItsBranchPointOnItsOwnBranchAndSaysSo) {
  // test/fixtures/motion/parallelogram.urdf, written at crank angle 60 deg: at 180 deg (j1 = 2 pi / 3) all
  // pins are collinear and the anti-parallelogram branch crosses. On the parallelogram branch the coupler
  // keeps its direction (j2 = -j1) and the rocker turns with the crank (j3 = j1).
  const MobilityAnalysis a = drive(motionFixture("parallelogram.urdf"), {{"j1", 3.0}});
  EXPECT_EQ(reported(a.report, "j1"), 3.0);
  EXPECT_NEAR(reported(a.report, "j2"), -3.0, 1e-9);
  EXPECT_NEAR(reported(a.report, "j3"), 3.0, 1e-9);
  ASSERT_EQ(a.report.assembly.events.size(), 1u);
  const std::string& event = a.report.assembly.events.front();
  EXPECT_EQ(event.find("branch point"), 0u) << event;
  const size_t at = event.find("j1 = ");
  ASSERT_NE(at, std::string::npos) << event;
  EXPECT_NEAR(std::strtod(event.c_str() + at + 5, nullptr), 2.0 * M_PI / 3.0, tolerances::kContinuationStep)
      << event;
  // A motion that stays away from it meets nothing.
  EXPECT_TRUE(drive(motionFixture("parallelogram.urdf"), {{"j1", 1.0}}).report.assembly.events.empty());
}

TEST(DrivenAssembly, HobermanRingTurnsAllItsUnitsAlike) {
  // urdf/hoberman_ring.urdf: six congruent angulated units, one bar the ground, DOF 1. The ring keeps its
  // six-fold symmetry as it opens (one freedom cannot break it), so every pin turns by the input angle, with
  // the sign of its side. The predictor is exact on this motion: the whole way is a few steps.
  for (const double kink : {0.1, -0.2}) {
    const MobilityAnalysis a = drive(urdfPath("hoberman_ring.urdf"), {{"kink_0", kink}});
    EXPECT_EQ(reported(a.report, "kink_0"), kink);
    for (int j = 0; j < 5; ++j) {
      EXPECT_NEAR(reported(a.report, "pin_ab_" + std::to_string(j)), kink, 1e-9) << j;
      EXPECT_NEAR(reported(a.report, "pin_ba_" + std::to_string(j)), -kink, 1e-9) << j;
    }
    EXPECT_EQ(a.report.dof, 1);
    EXPECT_LE(a.report.assembly.residual, 1e-12 * a.report.characteristicLength);
  }
}
