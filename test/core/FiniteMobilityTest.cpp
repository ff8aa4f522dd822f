/// Finite vs instantaneous mobility and passive freedoms away from the reference table's exact poses.
#include <cmath>

#include <gtest/gtest.h>

#include "core/TestModels.hpp"
#include "mobility_analysis/analysis/FiniteMobility.hpp"
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/MechanismDescription.hpp"
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

TEST(FiniteMobility, StructuralRedundancyIsNotSingular) {
  // Bennett: 3 redundant equations at every pose of its motion, all structural.
  const MobilityReport bennett = analyzeOrFail(urdfPath("bennett.urdf"), AnalysisMode::Spatial).report;
  EXPECT_EQ(bennett.finiteDof, 1);
  EXPECT_FALSE(bennett.singular);
  for (const RedundantConstraint& c : bennett.redundantConstraints)
    EXPECT_EQ(c.cause, "structural") << c.equation;
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
