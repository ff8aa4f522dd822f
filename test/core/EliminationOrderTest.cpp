/// The sweep order: a permutation of the equations and coordinates that releases each equation once its links
/// are reached, and never jumps along a connection without equations.
#include "mobility_analysis/EliminationOrder.hpp"

#include <algorithm>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "core/TestModels.hpp"
#include "mobility_analysis/SparseElimination.hpp"
#include "mobility_analysis/Tolerances.hpp"

using namespace mobility_analysis;

namespace {

bool isPermutation(std::vector<int> values, int size) {
  std::vector<int> expected(size);
  std::iota(expected.begin(), expected.end(), 0);
  std::sort(values.begin(), values.end());
  return values == expected;
}

/// Loops of every kind: a spatial over-constrained loop, balls, a planar ring, a door, a scissor mast.
const std::vector<const char*> kModels = {"bennett.urdf", "rssr.urdf", "hoberman_ring.urdf", "door.urdf",
                                          "sle_mast.urdf"};

}  // namespace

TEST(EliminationOrder, IsAPermutationReleasingJointsAfterTheirLinks) {
  for (const char* file : kModels) {
    SCOPED_TRACE(file);
    const ModelAtTreePose m = assembleAtTreePose(loadOrFail(urdfPath(file)), AnalysisMode::Spatial);
    const Mechanism& mechanism = m.mechanism;
    const CoordinateModel& model = m.assembled.model;
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

TEST(EliminationOrder, AnyOrderOfTheLinksIsBuiltLikeTheSweep) {
  // computeOrderOfLinks (the benchmark's AMD order) builds rows and column priorities from a link order the
  // way the sweep does: given the sweep's own link order it returns the sweep's order, and given any order a
  // permutation of the equations and coordinates in which each connection comes after its links, with the
  // Jacobian's rank (which no order changes) found again by the elimination the self-stress basis uses.
  for (const char* file : kModels) {
    SCOPED_TRACE(file);
    const ModelAtTreePose m = assembleAtTreePose(loadOrFail(urdfPath(file)), AnalysisMode::Spatial);
    const Mechanism& mechanism = m.mechanism;
    const CoordinateModel& model = m.assembled.model;
    const SparseJacobian& J = m.J;
    const EliminationOrder sweep = computeSweepOrder(mechanism, model);

    // The sweep's link order: links by the first pivot priority of their coordinates.
    std::vector<int> firstColumn(mechanism.links.size(), model.numCoordinates());
    for (size_t l = 0; l < mechanism.links.size(); ++l) {
      for (int e : model.bodyElements[l]) {
        for (int i = 0; i < model.dim; ++i)
          firstColumn[l] = std::min(firstColumn[l], sweep.columnPriority[model.elements[e].offset + i]);
      }
    }
    std::vector<int> links(mechanism.links.size());
    std::iota(links.begin(), links.end(), 0);
    std::sort(links.begin(), links.end(), [&](int a, int b) { return firstColumn[a] < firstColumn[b]; });
    const EliminationOrder again = computeOrderOfLinks(mechanism, model, links);
    EXPECT_EQ(again.rows, sweep.rows);
    EXPECT_EQ(again.columnPriority, sweep.columnPriority);
    EXPECT_EQ(again.closing, sweep.closing);

    auto rankIn = [&](const EliminationOrder& order) {
      SparseElimination elimination(static_cast<int>(J.cols()), order.columnPriority, tolerances::kRank,
                                    false);
      for (int r : order.rows) {
        const double norm = J.row(r).norm();
        elimination.addRow(J, r, norm > 0.0 ? 1.0 / norm : 0.0);
      }
      return elimination.rank();
    };
    const int rank = rankIn(sweep);
    std::mt19937 random(7);
    for (int trial = 0; trial < 3; ++trial) {
      std::shuffle(links.begin(), links.end(), random);
      const EliminationOrder shuffled = computeOrderOfLinks(mechanism, model, links);
      ASSERT_TRUE(isPermutation(shuffled.rows, model.numConstraints()));
      ASSERT_TRUE(isPermutation(shuffled.columnPriority, model.numCoordinates()));
      std::vector<int> position(model.numConstraints());
      for (size_t i = 0; i < shuffled.rows.size(); ++i)
        position[shuffled.rows[i]] = static_cast<int>(i);
      for (int r = 0; r < model.numConstraints(); ++r) {
        const ConstraintEquation& eq = model.equations[r];
        if (eq.source != EquationSource::Joint)
          continue;
        for (int s = 0; s < model.numConstraints(); ++s) {
          const ConstraintEquation& other = model.equations[s];
          const Joint& joint = mechanism.joints[eq.element];
          if (other.source == EquationSource::Link &&
              (other.element == joint.link1 || other.element == joint.link2)) {
            EXPECT_GT(position[r], position[s]);
          }
        }
      }
      EXPECT_EQ(rankIn(shuffled), rank);
    }
  }
}
