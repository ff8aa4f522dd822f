#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/TestModels.hpp"
#include "mobility_analysis/analysis/DriveableJoints.hpp"

using namespace mobility_analysis;

TEST(DriveableJoints, oneJointPerFreeDirectionInDocumentOrder) {
  // DOF 1 loops: the first tree joint drives; RSSR (DOF 2): the crank drives, the rod's spin moves no joint;
  // PUMA 560: every one of its six joints.
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"four_bar.urdf", {"ground_crank"}}, {"bennett.urdf", {"j1"}}, {"rssr.urdf", {"r1"}}};
  for (AnalysisMode mode : {AnalysisMode::Auto, AnalysisMode::Spatial}) {
    for (const auto& [file, expected] : cases) {
      SCOPED_TRACE(file);
      const Mechanism mechanism = loadOrFail(urdfPath(file));
      EXPECT_EQ(findDriveableJoints(mechanism, analyzeOrFail(urdfPath(file), mode)), expected);
    }
  }
  const Mechanism puma = loadOrFail(urdfPath("puma560.urdf"));
  EXPECT_EQ(findDriveableJoints(puma, analyzeOrFail(urdfPath("puma560.urdf"), AnalysisMode::Spatial)).size(),
            6u);
}

TEST(DriveableJoints, noneForARigidStructure) {
  // The deployed SLE mast is rigid once its cables are taut (DESIGN.md §5: DOF 0): nothing to drive.
  const Mechanism mast = loadOrFail(urdfPath("sle_deployable_deployed.urdf"));
  const MobilityAnalysis analysis =
      analyzeOrFail(urdfPath("sle_deployable_deployed.urdf"), AnalysisMode::Auto);
  ASSERT_EQ(analysis.report.dof, 0);
  EXPECT_TRUE(findDriveableJoints(mast, analysis).empty());
}
