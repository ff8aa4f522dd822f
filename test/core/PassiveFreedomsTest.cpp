/// Passive freedoms (Tsai 1999) on small inline models whose answer is known by inspection.
#include "mobility_analysis/analysis/PassiveFreedoms.hpp"

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
