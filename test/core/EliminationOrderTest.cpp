/// The sweep order: a permutation of the equations and coordinates that releases each equation once its links
/// are reached, and never jumps along a connection without equations.
#include "mobility_analysis/EliminationOrder.hpp"

#include <algorithm>
#include <numeric>

#include <gtest/gtest.h>

#include "core/TestModels.hpp"

using namespace mobility_analysis;

namespace {

bool isPermutation(std::vector<int> values, int size) {
  std::vector<int> expected(size);
  std::iota(expected.begin(), expected.end(), 0);
  std::sort(values.begin(), values.end());
  return values == expected;
}

}  // namespace

TEST(EliminationOrder, IsAPermutationReleasingJointsAfterTheirLinks) {
  for (const char* file : {"bennett.urdf", "rssr.urdf", "hoberman_ring.urdf", "door.urdf", "sle_mast.urdf"}) {
    SCOPED_TRACE(file);
    const Mechanism mechanism = loadOrFail(urdfPath(file));
    Result<AssembledMechanism> assembled =
        assembleMechanism(mechanism, computeTreePoses(mechanism, {}), AnalysisMode::Spatial);
    ASSERT_TRUE(isOk(assembled));
    const CoordinateModel& model = valueOf(assembled).model;
    const EliminationOrder order = computeSweepOrder(mechanism, model);
    ASSERT_TRUE(isPermutation(order.rows, model.numConstraints()));
    ASSERT_TRUE(isPermutation(order.columnPriority, model.numCoordinates()));

    // A connection's equations come after the rigid-link equations of both its links; the ground comes first.
    std::vector<int> lastLinkRow(mechanism.links.size(), -1);
    for (size_t i = 0; i < order.rows.size(); ++i) {
      const ConstraintEquation& eq = model.equations[order.rows[i]];
      if (eq.source == EquationSource::Link)
        lastLinkRow[eq.element] = static_cast<int>(i);
    }
    for (size_t i = 0; i < order.rows.size(); ++i) {
      const ConstraintEquation& eq = model.equations[order.rows[i]];
      if (eq.source != EquationSource::Joint)
        continue;
      EXPECT_GT(static_cast<int>(i), lastLinkRow[mechanism.joints[eq.element].link1]);
      EXPECT_GT(static_cast<int>(i), lastLinkRow[mechanism.joints[eq.element].link2]);
    }
    EXPECT_EQ(model.equations[order.rows.front()].element, mechanism.rootLink);
  }
}

TEST(EliminationOrder, FloatingJointsDoNotShortcutTheSweep) {
  // The RSSR's rod hangs from the ground by a floating joint; the sweep must reach it through a spherical
  // joint, i.e. after one of the cranks.
  const Mechanism mechanism = loadOrFail(urdfPath("rssr.urdf"));
  Result<AssembledMechanism> assembled =
      assembleMechanism(mechanism, computeTreePoses(mechanism, {}), AnalysisMode::Spatial);
  ASSERT_TRUE(isOk(assembled));
  const CoordinateModel& model = valueOf(assembled).model;
  const EliminationOrder order = computeSweepOrder(mechanism, model);
  std::vector<int> firstSeen(mechanism.links.size(), -1);
  for (size_t i = 0; i < order.rows.size(); ++i) {
    const ConstraintEquation& eq = model.equations[order.rows[i]];
    if (eq.source == EquationSource::Link && firstSeen[eq.element] < 0)
      firstSeen[eq.element] = static_cast<int>(i);
  }
  for (const Joint& joint : mechanism.joints) {
    if (joint.type != JointType::Floating)
      continue;
    const int rod = joint.link2;
    bool reachedThroughEquations = false;
    for (const Joint& other : mechanism.joints) {
      if (other.type == JointType::Floating || (other.link1 != rod && other.link2 != rod))
        continue;
      const int neighbour = other.link1 == rod ? other.link2 : other.link1;
      reachedThroughEquations = reachedThroughEquations || firstSeen[neighbour] < firstSeen[rod];
    }
    EXPECT_TRUE(reachedThroughEquations) << joint.name;
  }
}
