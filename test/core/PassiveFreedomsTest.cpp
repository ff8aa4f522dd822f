/// Passive freedoms (Tsai 1999) on small inline models whose answer is known by inspection.
#include "mobility_analysis/analysis/PassiveFreedoms.hpp"

#include <cstdio>
#include <random>

#include <gtest/gtest.h>

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
