#include "mobility_analysis/Assembly.hpp"

#include <gtest/gtest.h>

#include "core/TestModels.hpp"

using namespace mobility_analysis;

TEST(Assembly, LoopWrittenFiveDegreesOpenCloses) {
  const Mechanism mechanism = loadOrFail(fixturePath("four_bar_open.urdf"));
  const LinkPoses start = computeTreePoses(mechanism, {});
  const double lc = computeCharacteristicLength(mechanism, start);
  const std::optional<int> j4 = mechanism.findJoint("j4");
  ASSERT_TRUE(j4);
  EXPECT_GT(computeJointResidual(mechanism, start, *j4, lc), 0.01);  // really open as written
  const Result<AssembledMechanism> assembled = assembleMechanism(mechanism, start, AnalysisMode::Planar);
  ASSERT_TRUE(isOk(assembled)) << diagnosticOf(assembled).toString();
  const AssembledMechanism& a = valueOf(assembled);
  EXPECT_GT(a.initialResidual, 0.01);
  EXPECT_LT(a.finalResidual, 1e-9);
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    EXPECT_LT(computeJointResidual(mechanism, a.poses, static_cast<int>(j), lc), 1e-8) << mechanism.joints[j].name;
  }
  // Least change: the ground does not move, and the crank stays near where it was written.
  EXPECT_TRUE(a.poses[mechanism.rootLink].isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  const int crank = *mechanism.findLink("crank");
  EXPECT_LT((a.poses[crank].linear() - start[crank].linear()).norm(), 0.2);
}

TEST(Assembly, ClosedMechanismIsLeftWhereItIs) {
  const Mechanism mechanism = loadOrFail(fixturePath("four_bar_closed.urdf"));
  const LinkPoses start = computeTreePoses(mechanism, {});
  const Result<AssembledMechanism> assembled = assembleMechanism(mechanism, start, AnalysisMode::Spatial);
  ASSERT_TRUE(isOk(assembled));
  EXPECT_EQ(valueOf(assembled).iterations, 0);
  for (size_t l = 0; l < start.size(); ++l) {
    EXPECT_TRUE(valueOf(assembled).poses[l].isApprox(start[l], 1e-9)) << mechanism.links[l].name;
  }
}

TEST(Assembly, ImpossibleLoopFailsNamingTheLoopJointAndItsResidual) {
  const Mechanism mechanism = loadOrFail(fixturePath("bad_unclosable.urdf"));
  const Result<AssembledMechanism> assembled =
      assembleMechanism(mechanism, computeTreePoses(mechanism, {}), AnalysisMode::Auto);
  ASSERT_FALSE(isOk(assembled));
  const Diagnostic& d = diagnosticOf(assembled);
  EXPECT_EQ(d.elementKind, "loop_joint");
  EXPECT_EQ(d.elementName, "j4");
  EXPECT_NE(d.what.find("residual"), std::string::npos) << d.toString();
  EXPECT_EQ(d.file, "bad_unclosable.urdf");
}

TEST(Assembly, GivenPositionsAreTheStartingGuess) {
  const Mechanism mechanism = loadOrFail(fixturePath("four_bar_closed.urdf"));
  const LinkPoses start = computeTreePoses(mechanism, {{"j1", 0.9}});
  const Result<AssembledMechanism> assembled = assembleMechanism(mechanism, start, AnalysisMode::Planar);
  ASSERT_TRUE(isOk(assembled)) << diagnosticOf(assembled).toString();
  const double lc = computeCharacteristicLength(mechanism, start);
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    EXPECT_LT(computeJointResidual(mechanism, valueOf(assembled).poses, static_cast<int>(j), lc), 1e-8);
  }
}
