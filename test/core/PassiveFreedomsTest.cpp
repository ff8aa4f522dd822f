/// Passive freedoms (Tsai 1999) on small inline models whose answer is known by inspection.
#include "mobility_analysis/analysis/PassiveFreedoms.hpp"

#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "TextFile.hpp"
#include "core/TestModels.hpp"

using namespace mobility_analysis;

namespace {

/// Link m hangs between the ground (revolute about @p axis1 at the origin) and link n (revolute about x at
/// (1, 0, 0)); n is welded to the ground by a loop joint. With axis1 = x the two revolutes are coaxial.
std::string coaxialUrdf(const char* axis1) {
  return std::string(R"(<robot name="coaxial">
  <link name="ground"/><link name="m"/><link name="n"/>
  <joint name="r1" type="revolute"><parent link="ground"/><child link="m"/><axis xyz=")") +
         axis1 + R"("/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="r2" type="revolute"><parent link="m"/><child link="n"/><origin xyz="1 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <loop_joint name="weld" type="fixed"><link1 link="n" xyz="0 0.5 0"/><link2 link="ground" xyz="1 0.5 0"/>
  </loop_joint>
</robot>)";
}

MobilityReport analyze(const std::string& urdf) {
  const Result<Mechanism> mechanism = loadMechanismFromString(urdf, "coaxial.urdf");
  EXPECT_TRUE(isOk(mechanism));
  AnalysisOptions options;
  options.mode = AnalysisMode::Spatial;
  const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), options);
  EXPECT_TRUE(isOk(analysis)) << (isOk(analysis) ? "" : diagnosticOf(analysis).toString());
  return valueOf(analysis).report;
}

}  // namespace

TEST(PassiveFreedoms, ALinkBetweenTwoCoaxialRevolutesSpinsIdly) {
  const MobilityReport report = analyze(coaxialUrdf("1 0 0"));
  EXPECT_EQ(report.dof, 1);  // m turns about x; n is welded to the ground
  EXPECT_EQ(report.passiveDof, 1);
  EXPECT_EQ(report.outputDof, 0);
  ASSERT_EQ(report.passiveMotions.size(), 1u);
  EXPECT_EQ(report.passiveMotions[0].links, std::vector<std::string>{"m"});
  EXPECT_EQ(report.passiveMotions[0].description,
            "link m spins about the line through its revolute joints r1 and r2");
}

TEST(PassiveFreedoms, RevolutesThatAreNotCoaxialLeaveNoIdleMotion) {
  // The first axis turned to z: the two axes cross at right angles, m cannot turn, nothing moves.
  const MobilityReport report = analyze(coaxialUrdf("0 0 1"));
  EXPECT_EQ(report.dof, 0);
  EXPECT_EQ(report.passiveDof, 0);
  EXPECT_TRUE(report.passiveMotions.empty());
}

namespace {

/// A random "hub and rod" mechanism: hubs (>= 3 connections each, never idle) joined by rods and by chains of
/// two rods, every link floating from the ground (so every constraint is a loop element at a written world
/// point), in space. Its passive freedoms are known by Tsai's rule, whatever the random geometry:
///   rod S-S (balls at both ends): 1, the spin about the line through its balls;
///   rod R-R, both revolutes along the rod: 1; rod R-S, the revolute's axis through the ball: 1;
///   rod R-R or R-S with random axes: 0;
///   chain S-R-S (random middle axis): 1, the pair turning rigidly about the line through its end balls;
///   chain S-S-S: 3, each rod's spin and the pair's turn about its end balls.
struct HubAndRods {
  std::string urdf;
  int passive = 0;
};

HubAndRods randomHubAndRods(unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> coordinate(-2.0, 2.0);
  auto point = [&] { return Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random)); };
  auto text = [](const Eigen::Vector3d& v) {
    char buffer[96];
    std::snprintf(buffer, sizeof(buffer), "%.17g %.17g %.17g", v.x(), v.y(), v.z());
    return std::string(buffer);
  };
  HubAndRods result;
  std::string links = "<link name=\"ground\"/>", joints, loops;
  int numLinks = 0, numLoops = 0;
  auto addLink = [&](const std::string& name) {
    links += "<link name=\"" + name + "\"/>";
    joints += "<joint name=\"f_" + name + "\" type=\"floating\"><parent link=\"ground\"/><child link=\"" +
              name + "\"/></joint>";
    ++numLinks;
  };
  // One end: a ball at p, or a revolute at p about axis.
  auto addEnd = [&](const std::string& a, const std::string& b, const Eigen::Vector3d& p, bool ball,
                    const Eigen::Vector3d& axis) {
    loops += "<loop_joint name=\"c" + std::to_string(numLoops++) + "\" type=\"" +
             (ball ? "spherical" : "revolute") + "\"><link1 link=\"" + a + "\" xyz=\"" + text(p) +
             "\"/><link2 link=\"" + b + "\" xyz=\"" + text(p) + "\"/>" +
             (ball ? "" : "<axis xyz=\"" + text(axis) + "\"/>") + "</loop_joint>";
  };
  const int numHubs = 4;
  std::vector<std::string> hubs = {"ground"};
  for (int h = 1; h < numHubs; ++h) {
    hubs.push_back("hub" + std::to_string(h));
    addLink(hubs.back());
  }
  const int numRods = 18;  // each hub meets at least 3 of them: round robin over the hub pairs
  for (int r = 0; r < numRods; ++r) {
    const std::string a = hubs[r % numHubs], b = hubs[(r + 1 + r / numHubs % (numHubs - 1)) % numHubs];
    const Eigen::Vector3d p = point(), q = point(), along = (q - p).normalized();
    const std::string rod = "rod" + std::to_string(r);
    addLink(rod);
    switch (r % 6) {
      case 0:  // S-S
        addEnd(a, rod, p, true, Eigen::Vector3d::Zero());
        addEnd(rod, b, q, true, Eigen::Vector3d::Zero());
        result.passive += 1;
        break;
      case 1:  // R-R along the rod
        addEnd(a, rod, p, false, along);
        addEnd(rod, b, q, false, along);
        result.passive += 1;
        break;
      case 2:  // R through the ball, S
        addEnd(a, rod, p, false, along);
        addEnd(rod, b, q, true, Eigen::Vector3d::Zero());
        result.passive += 1;
        break;
      case 3:  // R-R, random axes
        addEnd(a, rod, p, false, point().normalized());
        addEnd(rod, b, q, false, point().normalized());
        break;
      case 4: {  // S-R-S chain of two rods
        const std::string second = rod + "b";
        addLink(second);
        addEnd(a, rod, p, true, Eigen::Vector3d::Zero());
        addEnd(rod, second, 0.5 * (p + q) + 0.3 * point(), false, point().normalized());
        addEnd(second, b, q, true, Eigen::Vector3d::Zero());
        result.passive += 1;
        break;
      }
      default: {  // S-S-S chain of two rods
        const std::string second = rod + "b";
        addLink(second);
        addEnd(a, rod, p, true, Eigen::Vector3d::Zero());
        addEnd(rod, second, 0.5 * (p + q) + 0.3 * point(), true, Eigen::Vector3d::Zero());
        addEnd(second, b, q, true, Eigen::Vector3d::Zero());
        result.passive += 3;
        break;
      }
    }
  }
  result.urdf = "<robot name=\"hubs\">" + links + joints + loops + "</robot>";
  return result;
}

}  // namespace

TEST(PassiveFreedoms, hubAndRodMechanismsHaveTsaisCountOfIdleMotions) {
  // Independent expectation per rod and rod pair (above), on random geometry; every group size 1-2 and
  // every kind of end is met, and the fast rejection of groups without a null twist must not drop one.
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const HubAndRods model = randomHubAndRods(seed);
    const Result<Mechanism> mechanism = loadMechanismFromString(model.urdf, "hubs.urdf");
    ASSERT_TRUE(isOk(mechanism)) << diagnosticOf(mechanism).toString();
    const Result<AssembledMechanism> assembled = assembleMechanism(
        valueOf(mechanism), computeTreePoses(valueOf(mechanism), {}), AnalysisMode::Spatial);
    ASSERT_TRUE(isOk(assembled)) << diagnosticOf(assembled).toString();
    const AssembledMechanism& a = valueOf(assembled);
    const SparseJacobian J = computeConstraintJacobian(a.model, a.q);
    const PassiveFreedoms passive = findPassiveFreedoms(valueOf(mechanism), a.model, a.q, J);
    EXPECT_EQ(passive.dof, model.passive) << "seed " << seed;
    EXPECT_EQ(passive.motions.size(), static_cast<size_t>(model.passive)) << "seed " << seed;
  }
}

namespace {

/// The passive freedoms of @p mechanism in @p mode, searched with or without the end-connection bound.
PassiveFreedoms searchPassive(const Mechanism& mechanism, AnalysisMode mode, bool endConnectionBound) {
  const Result<AssembledMechanism> assembled =
      assembleMechanism(mechanism, computeTreePoses(mechanism, {}), mode);
  EXPECT_TRUE(isOk(assembled)) << (isOk(assembled) ? "" : diagnosticOf(assembled).toString());
  if (!isOk(assembled))
    return {};
  const AssembledMechanism& a = valueOf(assembled);
  const SparseJacobian J = computeConstraintJacobian(a.model, a.q);
  PassiveFreedomsOptions options;
  options.endConnectionBound = endConnectionBound;
  return findPassiveFreedoms(mechanism, a.model, a.q, J, options);
}

/// The same motions, group for group and phrase for phrase, with the bound as in the full search.
void expectSameAnswer(const Mechanism& mechanism, AnalysisMode mode, const std::string& what) {
  const PassiveFreedoms fast = searchPassive(mechanism, mode, true);
  const PassiveFreedoms full = searchPassive(mechanism, mode, false);
  EXPECT_EQ(full.groupsRigidByEnds, 0) << what;
  EXPECT_EQ(fast.dof, full.dof) << what;
  ASSERT_EQ(fast.motions.size(), full.motions.size()) << what;
  for (size_t k = 0; k < full.motions.size(); ++k) {
    EXPECT_EQ(fast.motions[k].links, full.motions[k].links) << what << " motion " << k;
    EXPECT_EQ(fast.motions[k].description, full.motions[k].description) << what << " motion " << k;
  }
}

}  // namespace

TEST(PassiveFreedoms, endConnectionBoundKeepsEveryIdleMotionOfTheFullSearch) {
  // Models that do have idle motions (Tsai): Stewart 6-SPS (six legs spinning between their balls), the
  // Delta robot (six ball-jointed rods), RSSR (the rod), RPPR (the slider between parallel slides), and the
  // random hub-and-rod mechanisms with every kind of end; plus trees and the loop models without any.
  struct Case {
    std::string path;
    AnalysisMode mode;
    int passive;  // Tsai's count, known independently
  };
  const std::vector<Case> cases = {
      {fixturePath("motion/stewart_6sps.urdf"), AnalysisMode::Spatial, 6},
      {urdfPath("delta_robot.urdf"), AnalysisMode::Spatial, 6},
      {urdfPath("rssr.urdf"), AnalysisMode::Spatial, 1},
      {urdfPath("rppr.urdf"), AnalysisMode::Auto, 1},
      {urdfPath("puma560.urdf"), AnalysisMode::Spatial, 0},
      {urdfPath("four_bar.urdf"), AnalysisMode::Auto, 0},
      {urdfPath("four_bar.urdf"), AnalysisMode::Spatial, 0},
      {urdfPath("hoberman_ring.urdf"), AnalysisMode::Auto, 0},
      {urdfPath("sarrus.urdf"), AnalysisMode::Spatial, 0},
  };
  for (const Case& c : cases) {
    const Mechanism mechanism = loadOrFail(c.path);
    EXPECT_EQ(searchPassive(mechanism, c.mode, true).dof, c.passive) << c.path;
    expectSameAnswer(mechanism, c.mode, c.path);
  }
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const HubAndRods model = randomHubAndRods(seed);
    const Result<Mechanism> mechanism = loadMechanismFromString(model.urdf, "hubs.urdf");
    ASSERT_TRUE(isOk(mechanism));
    EXPECT_EQ(searchPassive(valueOf(mechanism), AnalysisMode::Spatial, true).dof, model.passive);
    expectSameAnswer(valueOf(mechanism), AnalysisMode::Spatial, "hubs seed " + std::to_string(seed));
  }
}

TEST(PassiveFreedoms, endConnectionBoundSettlesEveryGroupOfASerialChain) {
  // Two revolutes at different points leave a link (or a chain of links moving as one) no twist: on a chain
  // the bound settles every candidate group, in the plane and in space, and the full search agrees.
  const Result<Mechanism> mechanism = loadMechanismFromString(straightChainUrdf(40), "chain.urdf");
  ASSERT_TRUE(isOk(mechanism));
  for (AnalysisMode mode : {AnalysisMode::Planar, AnalysisMode::Spatial}) {
    const PassiveFreedoms fast = searchPassive(valueOf(mechanism), mode, true);
    const PassiveFreedoms full = searchPassive(valueOf(mechanism), mode, false);
    EXPECT_EQ(fast.dof, 0);
    EXPECT_EQ(full.dof, 0);
    // Links l1..l39 have two connections (l40 is the free end): 39 single links, 38 pairs, 37 triples.
    EXPECT_EQ(fast.groupsRigidByEnds, 39 + 38 + 37);
    EXPECT_EQ(fast.groupsSearched, 0);
    EXPECT_EQ(full.groupsSearched, 39 + 38 + 37);
  }
}

TEST(PassiveFreedoms, aMechanismFarFromTheOriginHasTheSameIdleMotionsAndBound) {
  // A group's twists are taken about a point of the group, not the origin of the model: far from it a twist
  // about the origin mixed lengths of 10^5 with lengths of 1, the end-connection bound could not settle a
  // single group of a chain 10^4 m away and the search was left to decide each one. Near and far, the same
  // idle motions, every chain group settled by the bound, and the full search agreeing.
  std::string chain = straightChainUrdf(40);
  chain.replace(chain.find("<origin xyz='0.1 0 0'/>"), 23, "<origin xyz='10000 20000 0'/>");
  const Result<Mechanism> far = loadMechanismFromString(chain, "far_chain.urdf");
  ASSERT_TRUE(isOk(far));
  for (AnalysisMode mode : {AnalysisMode::Planar, AnalysisMode::Spatial}) {
    const PassiveFreedoms fast = searchPassive(valueOf(far), mode, true);
    EXPECT_EQ(fast.dof, 0);
    EXPECT_EQ(fast.groupsRigidByEnds, 39 + 38 + 37);
    EXPECT_EQ(fast.groupsSearched, 0);
  }
  for (const char* file : {"delta_robot.urdf", "rssr.urdf"}) {
    const Mechanism near = loadOrFail(urdfPath(file));
    const Result<Mechanism> moved =
        loadMechanismFromString(placedAt(readTextFile(urdfPath(file)), "300 -200 100"), file);
    ASSERT_TRUE(isOk(moved)) << diagnosticOf(moved).toString();
    const PassiveFreedoms a = searchPassive(near, AnalysisMode::Spatial, true);
    const PassiveFreedoms b = searchPassive(valueOf(moved), AnalysisMode::Spatial, true);
    EXPECT_GT(a.dof, 0) << file;
    EXPECT_EQ(b.dof, a.dof) << file;
    ASSERT_EQ(b.motions.size(), a.motions.size()) << file;
    for (size_t k = 0; k < a.motions.size(); ++k)
      EXPECT_EQ(b.motions[k].description, a.motions[k].description) << file << " motion " << k;
    EXPECT_EQ(b.groupsRigidByEnds, a.groupsRigidByEnds) << file;
    expectSameAnswer(valueOf(moved), AnalysisMode::Spatial, std::string(file) + " far");
  }
}

namespace {

/// A serial chain of @p n links l0..l(n-1) from the ground, each joined to the one before by a joint of
/// @p type whose frame is 0.1 m along and turned by @p rpy from the one before; @p ball writes Drake's
/// `<drake:joint type="ball">` (URDF's own tree has no ball joint).
std::string serialChainUrdf(int n, const std::string& type, const std::string& rpy, bool ball) {
  std::string urdf = "<robot name='serial' xmlns:drake='http://drake.mit.edu'><link name='ground'/>";
  for (int i = 0; i < n; ++i) {
    const std::string tag = ball ? "drake:joint" : "joint";
    urdf += "<link name='l" + std::to_string(i) + "'/><" + tag + " name='j" + std::to_string(i) + "' type='" +
            type + "'><parent link='" + (i == 0 ? std::string("ground") : "l" + std::to_string(i - 1)) +
            "'/><child link='l" + std::to_string(i) + "'/><origin xyz='0.1 0 0' rpy='" + rpy +
            "'/><axis xyz='0 0 1'/>" +
            (type == "prismatic" ? "<limit lower='-1' upper='1' effort='1' velocity='1'/>" : "") + "</" +
            tag + ">";
  }
  return urdf + "</robot>";
}

/// @p n rods, each floating from the ground, joined end to end by ball joints at consecutive points of a
/// circle that would hold @p perCircle of them (radius 0.1 m perCircle / 2 pi), the points raised by -0.02,
/// 0 and 0.02 m in turn; the first and the last rods are ball-jointed to the ground.
std::string rodArcUrdf(int n, int perCircle, double unit) {
  const double radius = 0.1 * perCircle / (2.0 * M_PI);
  auto point = [&](int i) {
    const double angle = 2.0 * M_PI * i / perCircle;
    char buffer[96];
    std::snprintf(buffer, sizeof(buffer), "%.17g %.17g %.17g", unit * radius * std::cos(angle),
                  unit * radius * std::sin(angle), unit * 0.02 * (i % 3 - 1));
    return std::string(buffer);
  };
  auto name = [&](int i) { return i < 0 || i >= n ? std::string("ground") : "r" + std::to_string(i); };
  std::string urdf = "<robot name='arc'><link name='ground'/>";
  for (int i = 0; i < n; ++i)
    urdf += "<link name='r" + std::to_string(i) + "'/><joint name='f" + std::to_string(i) +
            "' type='floating'><parent link='ground'/><child link='r" + std::to_string(i) + "'/></joint>";
  for (int i = 0; i <= n; ++i)
    urdf += "<loop_joint name='b" + std::to_string(i) + "' type='spherical'><link1 link='" + name(i - 1) +
            "' xyz='" + point(i) + "'/><link2 link='" + name(i) + "' xyz='" + point(i) + "'/></loop_joint>";
  return urdf + "</robot>";
}

}  // namespace

TEST(PassiveFreedoms, EveryIdleMotionOfAChainCountsOnceWhicheverGroupShowsIt) {
  // passive_dof is the dimension of the span of the idle motions. A chain shows the same motion through
  // several groups (a pair of rods turning about the line of both is the sum of their spins), and the sum
  // may run through a group that shares no link with the one compared: rod l1's spin is the pair l0-l1's
  // less rod l0's. Closed forms, independent of the search:
  //  - a straight rope of n rods (balls on one line): n - 1, each rod but the free last one spinning about
  //    the line (every pair and triple turns about the same line);
  //  - a helical rope: 3 n - 6, every motion of rods l0..l(n-2) between the ground and l(n-1) held still
  //    (3 (n - 1) freedoms less the 3 of l(n-1)'s ball), each a sum of single, pair and triple motions;
  //  - a chain of planar joints in space (all normals z): 3 (n - 1), each link but the last sliding and
  //    turning in its plane between its two neighbours;
  //  - a telescope (prismatic joints, all along z): n - 1, each stage but the last sliding between its
  //    neighbours; its one output is the last stage's slide (before: n passive, 0 output).
  // Compared only with the motions sharing one of its links (as before), the straight rope of 6 rods counted
  // 10, the rope of 200 rods 495, and the planar chain of 6 links 30 motions (reported as 18, the whole DOF).
  struct Case {
    std::string what, urdf;
    int dof, passive;
  };
  const int n = 6;
  const std::vector<Case> cases = {
      {"straight rope", serialChainUrdf(n, "ball", "0 0 0", true), 3 * n, n - 1},
      {"helical rope", serialChainUrdf(n, "ball", "0.3 0.2 0.7", true), 3 * n, 3 * n - 6},
      {"planar chain", serialChainUrdf(n, "planar", "0 0 0", false), 3 * n, 3 * (n - 1)},
      {"telescope", serialChainUrdf(n, "prismatic", "0 0 0", false), n, n - 1},
      {"long straight rope", serialChainUrdf(200, "ball", "0 0 0", true), 600, 199},
  };
  for (const Case& c : cases) {
    const MobilityReport report = analyze(c.urdf);
    EXPECT_EQ(report.dof, c.dof) << c.what;
    EXPECT_EQ(report.passiveDof, c.passive) << c.what;
    EXPECT_EQ(report.outputDof, c.dof - c.passive) << c.what;
    EXPECT_EQ(report.passiveMotions.size(), static_cast<size_t>(c.passive)) << c.what;
  }
  // Listed from the simplest groups: on the straight rope, the rods' own spins.
  const MobilityReport rope = analyze(cases[0].urdf);
  for (const PassiveMotion& motion : rope.passiveMotions) {
    EXPECT_EQ(motion.links.size(), 1u) << motion.description;
    EXPECT_NE(motion.description.find("spins about the line through its ball joints"), std::string::npos);
  }
  // A planar-jointed link turns about the plane's normal, which passes through neither joint point (the
  // joints are at 0.1 m spacing along x): no phrase may claim the line through its joints.
  const MobilityReport planar = analyze(cases[2].urdf);
  int turns = 0;
  for (const PassiveMotion& motion : planar.passiveMotions) {
    const bool turn = motion.description.find(" turns about an axis along (0, 0, ") != std::string::npos;
    const bool slide = motion.description.find(" slides along ") != std::string::npos;
    EXPECT_TRUE(turn || slide) << motion.description;
    turns += turn ? 1 : 0;
  }
  EXPECT_GE(turns, 1);
}

TEST(PassiveFreedoms, SmallRodsInALargeMechanismAreComparedInTheirOwnLength) {
  // Rods 0.1 m long on an arc of a circle 64 m across, ball-jointed end to end between two ground balls:
  // n rods, n + 1 balls, DOF 6 n - 3 (n + 1) = 3 n - 3, and every one is idle (the n rods' spins, the n - 1
  // pairs' and n - 2 triples' turns about their end balls: 3 n - 3 motions, all independent on a short arc of
  // the same circle, where the model's unit Lc is small). In Lc units a long arc's rods moved their points
  // 600 times less than their directions, and the pairs whose two rods are nearly in line fell to the
  // tolerance: 1 000 of the 3 000 rods' pairs were lost. In millimetres, the same.
  for (const int n : {30, 3000}) {
    for (const double unit : {1.0, 1000.0}) {
      const MobilityReport report = analyze(rodArcUrdf(n, 4000, unit));
      EXPECT_EQ(report.dof, 3 * n - 3) << n << " rods, unit " << unit;
      EXPECT_EQ(report.passiveDof, 3 * n - 3) << n << " rods, unit " << unit;
    }
  }
}
