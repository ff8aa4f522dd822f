/// Cable prestress (`self_stress.prestressable`): the shortcuts of findCablePrestress — a cable no state
/// touches, local states that tension every cable — against the linear program over the states, on random
/// bar-and-cable frameworks (where the program must decide in some), on braced lattices (closed form: every
/// braced cell carries a state with both diagonals in tension) and through the whole report.
#include <algorithm>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/LU>

#include "core/TestModels.hpp"
#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/SelfStressBasis.hpp"
#include "mobility_analysis/Tolerances.hpp"
#include "mobility_analysis/analysis/Prestress.hpp"
#include "mobility_analysis/analysis/SelfStressReport.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/ScalingFamilies.hpp"

using namespace mobility_analysis;

namespace {

/// A planar framework's rigidity matrix: node i at (2i, 2i+1); a member's row holds p_i - p_j at node i and
/// p_j - p_i at node j (the gradient of |p_i - p_j|^2 / 2); node 0 is pinned and node 1 slides along x.
struct Framework {
  SparseJacobian J;
  std::vector<int> cables;  ///< Rows of the members that are cables.
};

Framework randomFramework(std::mt19937& random, int nodes, int members, double cableShare) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<int> pick(0, nodes - 1);
  std::vector<Eigen::Vector2d> p(static_cast<size_t>(nodes));
  for (Eigen::Vector2d& point : p)
    point = Eigen::Vector2d(unit(random), unit(random));
  std::vector<Eigen::Triplet<double>> triplets{{0, 0, 1.0}, {1, 1, 1.0}, {2, 3, 1.0}};
  Framework framework;
  int row = 3;
  std::vector<std::pair<int, int>> used;
  while (row < 3 + members) {
    int i = pick(random), j = pick(random);
    if (i == j)
      continue;
    if (i > j)
      std::swap(i, j);
    if (std::find(used.begin(), used.end(), std::make_pair(i, j)) != used.end())
      continue;
    used.emplace_back(i, j);
    const Eigen::Vector2d d = p[static_cast<size_t>(i)] - p[static_cast<size_t>(j)];
    for (int a = 0; a < 2; ++a) {
      triplets.emplace_back(row, 2 * i + a, d(a));
      triplets.emplace_back(row, 2 * j + a, -d(a));
    }
    if (unit(random) < cableShare)
      framework.cables.push_back(row);
    ++row;
  }
  framework.J = SparseJacobian(row, 2 * nodes);
  framework.J.setFromTriplets(triplets.begin(), triplets.end());
  return framework;
}

/// A dense basis of the left null space (deliberately not local), each state scaled to unit largest entry.
std::vector<SelfStress> denseStates(const SparseJacobian& J) {
  const Eigen::MatrixXd dense = Eigen::MatrixXd(J).transpose();
  Eigen::FullPivLU<Eigen::MatrixXd> lu(dense);
  lu.setThreshold(1e-10);
  std::vector<SelfStress> states;
  if (lu.dimensionOfKernel() == 0)
    return states;
  const Eigen::MatrixXd kernel = lu.kernel();
  for (Eigen::Index k = 0; k < kernel.cols(); ++k) {
    const double largest = kernel.col(k).cwiseAbs().maxCoeff();
    SelfStress state;
    for (Eigen::Index r = 0; r < kernel.rows(); ++r) {
      if (std::abs(kernel(r, k)) > 1e-12 * largest)
        state.emplace_back(static_cast<int>(r), kernel(r, k) / largest);
    }
    states.push_back(std::move(state));
  }
  return states;
}

/// The prestress is a self-stress of J with every cable in tension (checked here, not by the code under
/// test).
void expectPrestress(const SparseJacobian& J, const std::vector<int>& cables,
                     const CablePrestress& prestress) {
  ASSERT_EQ(prestress.multipliers.size(), J.rows());
  const double largest = prestress.multipliers.cwiseAbs().maxCoeff();
  ASSERT_GT(largest, 0.0);
  EXPECT_LT((J.transpose() * prestress.multipliers).cwiseAbs().maxCoeff(), 1e-9 * largest);
  for (int row : cables)
    EXPECT_GT(prestress.multipliers(row), 1e-9 * largest) << "cable row " << row;
}

/// The report's states and taut cables of a generated model, at its assembled pose.
struct Analysed {
  SparseJacobian J;
  std::vector<SelfStress> states;
  std::vector<int> cables;
  MobilityReport report;
};

Analysed analyseGenerated(const MechanismDescription& description) {
  Analysed result;
  const GeneratorResult<std::string> urdf = toClosedLoopUrdf(description);
  if (!std::holds_alternative<std::string>(urdf)) {
    ADD_FAILURE() << "generator failed";
    return result;
  }
  const Result<Mechanism> mechanism = loadMechanismFromString(std::get<std::string>(urdf), "generated.urdf");
  if (!isOk(mechanism)) {
    ADD_FAILURE() << diagnosticOf(mechanism).toString();
    return result;
  }
  AnalysisOptions options;
  options.mode = AnalysisMode::Planar;
  Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), options);
  if (!isOk(analysis)) {
    ADD_FAILURE() << diagnosticOf(analysis).toString();
    return result;
  }
  const MobilityAnalysis& a = valueOf(analysis);
  result.J = computeConstraintJacobian(a.assembled.model, a.assembled.q);
  result.states = toEquilibriumStresses(
      computeSelfStressBasis(valueOf(mechanism), a.assembled.model, result.J, tolerances::kRank).stresses,
      result.J);
  result.cables = findTautCableRows(valueOf(mechanism), a.assembled.model);
  result.report = a.report;
  return result;
}

}  // namespace

TEST(Prestress, ShortcutsAgreeWithTheLinearProgramOnRandomCableNets) {
  std::mt19937 random(7);
  int byLocalStates = 0, byProgramFeasible = 0, byProgramInfeasible = 0, byUntouched = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const int nodes = 4 + trial % 5;
    // A few more members than a rigid framework needs, at most one per pair of nodes.
    const int members = std::min(2 * nodes - 3 + 1 + trial % 4, nodes * (nodes - 1) / 2);
    const Framework net = randomFramework(random, nodes, members, trial % 2 == 0 ? 0.5 : 0.9);
    if (net.cables.empty())
      continue;
    const std::vector<SelfStress> states = denseStates(net.J);
    SCOPED_TRACE("trial " + std::to_string(trial));
    // The program alone (no Jacobian: no local search) and the local search first (threshold 0).
    const CablePrestress program = findCablePrestress(states, static_cast<int>(net.J.rows()), net.cables);
    const CablePrestress shortcut =
        findCablePrestress(states, static_cast<int>(net.J.rows()), net.cables, &net.J, 0);
    EXPECT_EQ(shortcut.feasible, program.feasible);
    if (program.feasible)
      expectPrestress(net.J, net.cables, program);
    if (shortcut.feasible)
      expectPrestress(net.J, net.cables, shortcut);
    switch (shortcut.decidedBy) {
      case PrestressMethod::LocalStates:
        ++byLocalStates;
        break;
      case PrestressMethod::LinearProgram:
        ++(shortcut.feasible ? byProgramFeasible : byProgramInfeasible);
        break;
      case PrestressMethod::UntouchedCable: {
        ++byUntouched;
        EXPECT_FALSE(shortcut.feasible);
        // Independently: some cable row is 0 in every left null vector of J (dense, full pivoting).
        bool someCableFree = false;
        for (int row : net.cables) {
          bool touched = false;
          for (const SelfStress& state : states) {
            for (const auto& [r, value] : state)
              touched = touched || (r == row && value != 0.0);
          }
          someCableFree = someCableFree || !touched;
        }
        EXPECT_TRUE(someCableFree);
        break;
      }
      case PrestressMethod::None:
        EXPECT_TRUE(states.empty());
        break;
    }
  }
  // Every path was taken, the program's included, both ways.
  EXPECT_GT(byLocalStates, 0);
  EXPECT_GT(byProgramInfeasible, 0);
  EXPECT_GT(byProgramFeasible, 0);
  EXPECT_GT(byUntouched, 0);
}

TEST(Prestress, ThreeMembersInLineHaveOneStateThatPullsTheShortOnesAndPushesTheLongOne) {
  // Nodes 0 (0, 0), 1 (1, 0), 2 (2, 0); members 0-1, 1-2 (the short ones) and 0-2 (the long one); node 0
  // pinned, node 2 on x. Equilibrium along the line: the one state is y_01 = y_12 = -2 y_02 (rows as in
  // randomFramework), so the short members can be tensioned together against the long one, or the long one
  // alone, but never all three: the program has to say no where no local state says yes.
  SparseJacobian J(6, 6);
  const std::vector<Eigen::Triplet<double>> t{{0, 0, 1.0},  {1, 1, 1.0},  {2, 5, 1.0},
                                              {3, 0, -1.0}, {3, 2, 1.0},  {4, 2, -1.0},
                                              {4, 4, 1.0},  {5, 0, -2.0}, {5, 4, 2.0}};
  J.setFromTriplets(t.begin(), t.end());
  const std::vector<SelfStress> states = denseStates(J);
  ASSERT_EQ(states.size(), 1u);
  const SelfStress& state = states[0];
  ASSERT_EQ(state.size(), 3u);  // rows 3, 4, 5
  EXPECT_NEAR(state[0].second, state[1].second, 1e-12);
  EXPECT_NEAR(state[0].second, -2.0 * state[2].second, 1e-12);

  const std::vector<int> shortOnes{3, 4}, longOne{5}, all{3, 4, 5};
  for (const std::vector<int>& cables : {shortOnes, longOne}) {
    const CablePrestress shortcut = findCablePrestress(states, 6, cables, &J, 0);
    EXPECT_TRUE(shortcut.feasible);
    EXPECT_EQ(shortcut.decidedBy, PrestressMethod::LocalStates);
    expectPrestress(J, cables, shortcut);
    EXPECT_TRUE(findCablePrestress(states, 6, cables).feasible);
  }
  EXPECT_FALSE(findLocalCablePrestress(J, all).has_value());
  const CablePrestress shortcut = findCablePrestress(states, 6, all, &J, 0);
  EXPECT_FALSE(shortcut.feasible);
  EXPECT_EQ(shortcut.decidedBy, PrestressMethod::LinearProgram);
  EXPECT_FALSE(findCablePrestress(states, 6, all).feasible);
  // A "cable" on the ground row 1 (node 0's y, which nothing else loads) is in no state: no program needed.
  const CablePrestress untouched = findCablePrestress(states, 6, {1, 5}, &J, 0);
  EXPECT_FALSE(untouched.feasible);
  EXPECT_EQ(untouched.decidedBy, PrestressMethod::UntouchedCable);
}

TEST(Prestress, BracedLatticeIsPrestressedByItsCellsWithoutTheProgram) {
  for (auto [r, c] : {std::pair{1, 1}, std::pair{2, 3}, std::pair{4, 4}, std::pair{6, 5}}) {
    SCOPED_TRACE(std::to_string(r) + "x" + std::to_string(c));
    const Analysed lattice = analyseGenerated(makeBarLattice(r, c, true));
    ASSERT_EQ(static_cast<int>(lattice.states.size()), 2 * r * c - r - c + 1);
    ASSERT_EQ(static_cast<int>(lattice.cables.size()), 2 * r * c);
    const int m = static_cast<int>(lattice.J.rows());
    const CablePrestress program = findCablePrestress(lattice.states, m, lattice.cables);
    const CablePrestress shortcut = findCablePrestress(lattice.states, m, lattice.cables, &lattice.J, 0);
    EXPECT_TRUE(program.feasible);
    EXPECT_EQ(program.decidedBy, PrestressMethod::LinearProgram);
    ASSERT_TRUE(shortcut.feasible);
    EXPECT_EQ(shortcut.decidedBy, PrestressMethod::LocalStates);
    expectPrestress(lattice.J, lattice.cables, shortcut);
    // Below the threshold the report keeps the program's answer (and its vertex).
    EXPECT_EQ(findCablePrestress(lattice.states, m, lattice.cables, &lattice.J).decidedBy,
              PrestressMethod::LinearProgram);
    EXPECT_TRUE(lattice.report.selfStress.prestressable);
  }
}

TEST(Prestress, BracedLatticeReportAboveTheThresholdIsPrestressed) {
  // 23 x 23: 2 * 529 - 46 + 1 = 1013 states, above kLocalPrestressStates, so the report takes the local
  // states; the closed form (every braced cell is a state with both diagonals in tension) says prestressable.
  const Analysed lattice = analyseGenerated(makeBarLattice(23, 23, true));
  ASSERT_GT(static_cast<int>(lattice.states.size()), kLocalPrestressStates);
  EXPECT_EQ(lattice.report.selfStress.count, 1013);
  EXPECT_TRUE(lattice.report.selfStress.prestressable);
  EXPECT_TRUE(lattice.report.selfStress.prestressStable);  // first-order rigid (m = 0)
  int cables = 0;
  for (const ElementForce& force : lattice.report.selfStress.prestress) {
    if (force.kind == "cable") {
      ++cables;
      EXPECT_GT(force.force, 0.0) << force.name;
    }
  }
  EXPECT_EQ(cables, 2 * 23 * 23);
}
