/// Finite vs instantaneous mobility and passive freedoms away from the reference table's exact poses.
#include <cmath>

#include <gtest/gtest.h>

#include "core/TestModels.hpp"
#include "mobility_analysis/analysis/FiniteMobility.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/MechanismDescription.hpp"
#include "mobility_analysis/generators/ParametricFamilies.hpp"
#include "mobility_analysis/generators/ReferenceMechanisms.hpp"

using namespace mobility_analysis;

namespace {

/// The flattened four-bar's linkage (ground 1, crank 0.4, coupler 0.9, rocker 0.3) with the crank at @p angle
/// [rad], C on the branch that becomes the flat pose at angle 0.
MechanismDescription changePointFourBar(double angle) {
  MechanismDescription m = makeFlattenedFourBar();
  const Eigen::Vector2d a(0.0, 0.0), d(1.0, 0.0);
  const Eigen::Vector2d b = 0.4 * Eigen::Vector2d(std::cos(angle), std::sin(angle));
  // C: |C - B| = 0.9, |C - D| = 0.3 (circle intersection), the one with the larger x.
  const double distance = (d - b).norm();
  const double along = (0.9 * 0.9 - 0.3 * 0.3 + distance * distance) / (2.0 * distance);
  const double across = std::sqrt(std::max(0.0, 0.9 * 0.9 - along * along));
  const Eigen::Vector2d unit = (d - b) / distance, normal(-unit.y(), unit.x());
  const Eigen::Vector2d c = b + along * unit - across * normal;
  auto p = [](const Eigen::Vector2d& v) { return Eigen::Vector3d(v.x(), v.y(), 0.0); };
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  m.links[0].visualPath = {p(a), p(d)};
  m.links[1].visualPath = {p(a), p(b)};
  m.links[2].visualPath = {p(b), p(c)};
  m.links[3].visualPath = {p(c), p(d)};
  m.connections = {makeRevolute("ground_crank", "ground", "crank", p(a), z),
                   makeRevolute("crank_coupler", "crank", "coupler", p(b), z),
                   makeRevolute("coupler_rocker", "coupler", "rocker", p(c), z),
                   makeRevolute("rocker_ground", "rocker", "ground", p(d), z)};
  return m;
}

MobilityReport analyzeDescription(const MechanismDescription& description, AnalysisMode mode) {
  const GeneratorResult<std::string> urdf = toClosedLoopUrdf(description);
  EXPECT_TRUE(std::holds_alternative<std::string>(urdf));
  const Result<Mechanism> mechanism =
      loadMechanismFromString(std::get<std::string>(urdf), description.name + ".urdf");
  EXPECT_TRUE(isOk(mechanism));
  AnalysisOptions options;
  options.mode = mode;
  const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), options);
  EXPECT_TRUE(isOk(analysis));
  return valueOf(analysis).report;
}

}  // namespace

TEST(FiniteMobility, OnlyTheFlatPoseOfTheChangePointFourBarIsSingular) {
  // 0.1 rad and 0.01 rad from flat the linkage is an ordinary four-bar: no redundancy, nothing singular.
  for (double angle : {0.1, 0.01}) {
    const MobilityReport report = analyzeDescription(changePointFourBar(angle), AnalysisMode::Planar);
    EXPECT_EQ(report.dof, 1) << angle;
    EXPECT_EQ(report.finiteDof, 1) << angle;
    EXPECT_FALSE(report.singular) << angle;
    EXPECT_EQ(report.numRedundant, 0) << angle;
  }
  const MobilityReport flat = analyzeDescription(changePointFourBar(0.0), AnalysisMode::Planar);
  EXPECT_EQ(flat.dof, 2);
  EXPECT_EQ(flat.finiteDof, 1);
  EXPECT_TRUE(flat.singular);
  ASSERT_EQ(flat.redundantConstraints.size(), 1u);
  EXPECT_EQ(flat.redundantConstraints[0].cause, "configuration");
  EXPECT_TRUE(flat.redundantJoints.empty());
}

/// Two flat change-point four-bars on one ground, the second 1 m above the first (its names end in "_2").
MechanismDescription twoFlatFourBars() {
  MechanismDescription m = changePointFourBar(0.0);
  const MechanismDescription other = changePointFourBar(0.0);
  const Eigen::Vector3d up(0.0, 1.0, 0.0);
  auto renamed = [](const std::string& name) { return name == "ground" ? name : name + "_2"; };
  for (size_t l = 1; l < other.links.size(); ++l) {
    LinkDescription link = other.links[l];
    link.name = renamed(link.name);
    for (Eigen::Vector3d& point : link.visualPath)
      point += up;
    m.links.push_back(link);
  }
  for (Connection connection : other.connections) {
    connection.name += "_2";
    connection.link1 = renamed(connection.link1);
    connection.link2 = renamed(connection.link2);
    connection.frame.translation() += up;
    m.connections.push_back(connection);
  }
  m.name = "two_flat_four_bars";
  return m;
}

TEST(FiniteMobility, TheDimensionAtASingularPoseIsTheBranchesNotTheSingularSets) {
  // Stepped along a motion that keeps the pose singular, the nullity there is the singular set's, not the
  // branches'. A floating base carries the flat four-bar to other flat poses: first order 2 + 3, the branches
  // 1 + 3 (before: finite 5, not singular, the redundancy structural).
  MechanismDescription floating = changePointFourBar(0.0);
  floating.links.insert(floating.links.begin(), LinkDescription{"world", {}, std::nullopt});
  const MobilityReport onFloatingBase = analyzeDescription(floating, AnalysisMode::Planar);
  EXPECT_EQ(onFloatingBase.dof, 5);
  EXPECT_EQ(onFloatingBase.grublerKutzbachDof, 4);
  EXPECT_EQ(onFloatingBase.finiteDof, 4);
  EXPECT_TRUE(onFloatingBase.singular);
  ASSERT_EQ(onFloatingBase.redundantConstraints.size(), 1u);
  EXPECT_EQ(onFloatingBase.redundantConstraints[0].cause, "configuration");
  // Two flat four-bars: each one's own motion leaves the other flat. First order 2 + 2, the branches 1 + 1
  // (before: finite 3).
  const MobilityReport two = analyzeDescription(twoFlatFourBars(), AnalysisMode::Planar);
  EXPECT_EQ(two.dof, 4);
  EXPECT_EQ(two.grublerKutzbachDof, 2);
  EXPECT_EQ(two.finiteDof, 2);
  EXPECT_TRUE(two.singular);
  ASSERT_EQ(two.redundantConstraints.size(), 2u);
  for (const RedundantConstraint& c : two.redundantConstraints)
    EXPECT_EQ(c.cause, "configuration") << c.equation;
}

TEST(FiniteMobility, StructuralRedundancyIsNotSingular) {
  // Bennett: 3 redundant equations at every pose of its motion, all structural.
  const MobilityReport bennett = analyzeOrFail(urdfPath("bennett.urdf"), AnalysisMode::Spatial).report;
  EXPECT_EQ(bennett.finiteDof, 1);
  EXPECT_FALSE(bennett.singular);
  for (const RedundantConstraint& c : bennett.redundantConstraints)
    EXPECT_EQ(c.cause, "structural") << c.equation;
}

// A triangular-prism scissor mast deploys (finite DOF 1 at every elevation). Some of its states of
// self-stress lie on equations the motion leaves still: their second-order forms are rounding over a scale of
// rounding (1e-17 / 1e-17), and read as obstructions of order 1 they made it singular. Above the stepping
// limit the second-order test alone decides: it then said finite DOF 0; below it, stepping had to rescue it,
// and with its elements written in another order it did not.
TEST(FiniteMobility, ADeployingTriangularMastIsNotSingularToSecondOrder) {
  for (const int units : {1, 30}) {
    SCOPED_TRACE(units);
    const MobilityReport mast = analyzeDescription(makeSleTriangularMast(units), AnalysisMode::Spatial);
    EXPECT_EQ(mast.dof, 1);
    EXPECT_EQ(mast.finiteDof, 1);
    EXPECT_FALSE(mast.singular);
    if (units == 30) {
      EXPECT_GT(mast.numCoordinates, kFiniteMobilityStepLimit);  // the second-order test alone
    }
  }
}

TEST(FiniteMobility, ProjectionClosesAStepOffTheConstraints) {
  const MobilityAnalysis analysis = analyzeOrFail(urdfPath("four_bar.urdf"), AnalysisMode::Planar);
  const CoordinateModel& model = analysis.assembled.model;
  Eigen::VectorXd start = analysis.assembled.q;
  start(start.size() - 1) += 1e-3;
  const auto [projected, closed] = projectOntoConstraints(model, start, 1e-13, 60);
  EXPECT_TRUE(closed);
  Eigen::VectorXd phi;
  computeConstraintResidual(model, projected, phi);
  EXPECT_LT(phi.cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_LT((projected - start).norm(), 2e-3);  // least change: it stays near where it started
}
