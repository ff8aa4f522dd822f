#include "mobility_analysis/ConstraintJacobian.hpp"

#include <random>
#include <set>

#include <gtest/gtest.h>

#include "EigenTestHelpers.hpp"
#include "core/TestModels.hpp"

using namespace mobility_analysis;

namespace {

CoordinateModel buildFromText(const char* text, AnalysisMode mode) {
  Result<Mechanism> mechanism = loadMechanismFromString(text, "inline.urdf");
  EXPECT_TRUE(isOk(mechanism)) << (isOk(mechanism) ? "" : diagnosticOf(mechanism).toString());
  const Mechanism& m = valueOf(mechanism);
  const LinkPoses poses = computeTreePoses(m, {});
  Result<CoordinateModel> model = buildCoordinateModel(m, poses, mode, computeCharacteristicLength(m, poses));
  EXPECT_TRUE(isOk(model)) << (isOk(model) ? "" : diagnosticOf(model).toString());
  return valueOf(model);
}

/// Central differences of Phi; the error of the analytic Jacobian must be within the truncation and rounding
/// error of the step (h^2 for quadratic equations, which are exact up to rounding, plus eps / h).
void expectJacobianMatchesFiniteDifferences(const CoordinateModel& model, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(-0.3, 0.3);
  Eigen::VectorXd q = model.q0;
  for (int i = 0; i < q.size(); ++i)
    q(i) += uniform(random);  // a random pose, off the constraint manifold
  const Eigen::MatrixXd analytic = Eigen::MatrixXd(computeConstraintJacobian(model, q));
  const double h = 1e-6;
  Eigen::MatrixXd numeric(model.numConstraints(), model.numCoordinates());
  Eigen::VectorXd plus, minus;
  for (int j = 0; j < q.size(); ++j) {
    Eigen::VectorXd qp = q, qm = q;
    qp(j) += h;
    qm(j) -= h;
    computeConstraintResidual(model, qp, plus);
    computeConstraintResidual(model, qm, minus);
    numeric.col(j) = (plus - minus) / (2 * h);
  }
  EXPECT_TRUE(matricesNear(numeric, analytic, 1e-8));
}

}  // namespace

TEST(ConstraintJacobian, MatchesFiniteDifferencesForEverySpatialEquationKind) {
  const CoordinateModel model = buildFromText(allJointKindsUrdf(), AnalysisMode::Spatial);
  std::set<EquationKind> kinds;
  for (const ConstraintEquation& eq : model.equations)
    kinds.insert(eq.kind);
  // Every kind the spatial table produces is present, so the check below covers each of them.
  for (EquationKind kind :
       {EquationKind::LinkDistance, EquationKind::UnitNorm, EquationKind::LinkDotProduct,
        EquationKind::LinearCombination, EquationKind::CoincidentPoint, EquationKind::ParallelAxis,
        EquationKind::PointOnAxisLine, EquationKind::FixedTwist, EquationKind::AxisAngle,
        EquationKind::PointInPlane, EquationKind::Distance, EquationKind::FixedCoordinate}) {
    EXPECT_TRUE(kinds.count(kind)) << "no equation of kind " << toString(kind);
  }
  for (unsigned seed = 1; seed <= 5; ++seed)
    expectJacobianMatchesFiniteDifferences(model, seed);
}

TEST(ConstraintJacobian, MatchesFiniteDifferencesInThePlane) {
  const CoordinateModel model = buildFromText(planarJointKindsUrdf(), AnalysisMode::Planar);
  EXPECT_EQ(model.dim, 2);
  std::set<EquationKind> kinds;
  for (const ConstraintEquation& eq : model.equations)
    kinds.insert(eq.kind);
  for (EquationKind kind :
       {EquationKind::LinkDistance, EquationKind::LinearCombination, EquationKind::CoincidentPoint,
        EquationKind::ParallelAxis, EquationKind::PointOnAxisLine, EquationKind::FixedTwist,
        EquationKind::Distance, EquationKind::FixedCoordinate}) {
    EXPECT_TRUE(kinds.count(kind)) << "no planar equation of kind " << toString(kind);
  }
  for (unsigned seed = 1; seed <= 5; ++seed)
    expectJacobianMatchesFiniteDifferences(model, seed);
}

TEST(ConstraintJacobian, MatchesFiniteDifferencesForTheTripleProductTwist) {
  // Three sliders analysed in space: every direction of every link lies in the plane of the slide axes, so no
  // pair of directions sees the twist of slide_ab; a triple product (the normal of one link's directions . a
  // direction of the other) does. (The other slides find a parallel pair, whose cross product sees it.)
  const Mechanism mechanism = loadOrFail(urdfPath("three_sliders.urdf"));
  const LinkPoses poses = computeTreePoses(mechanism, {});
  const Result<CoordinateModel> model = buildCoordinateModel(mechanism, poses, AnalysisMode::Spatial,
                                                             computeCharacteristicLength(mechanism, poses));
  ASSERT_TRUE(isOk(model));
  int triples = 0;
  for (const ConstraintEquation& eq : valueOf(model).equations) {
    if (eq.form == EquationForm::Triple) {
      ++triples;
      EXPECT_EQ(eq.kind, EquationKind::FixedTwist);
    }
  }
  EXPECT_EQ(triples, 1);
  for (unsigned seed = 1; seed <= 5; ++seed)
    expectJacobianMatchesFiniteDifferences(valueOf(model), seed);
}

TEST(ConstraintJacobian, ResidualVanishesAtTheWrittenPoseOfAClosedMechanism) {
  const Mechanism mechanism = loadOrFail(fixturePath("four_bar_closed.urdf"));
  const LinkPoses poses = computeTreePoses(mechanism, {});
  for (AnalysisMode mode : {AnalysisMode::Planar, AnalysisMode::Spatial}) {
    const Result<CoordinateModel> model =
        buildCoordinateModel(mechanism, poses, mode, computeCharacteristicLength(mechanism, poses));
    ASSERT_TRUE(isOk(model));
    Eigen::VectorXd phi;
    computeConstraintResidual(valueOf(model), valueOf(model).q0, phi);
    EXPECT_LT(phi.cwiseAbs().maxCoeff(), 1e-12) << toString(mode);
  }
}

TEST(ConstraintJacobian, EachEquationWritesOnlyItsOwnFewColumns) {
  const CoordinateModel model = buildFromText(allJointKindsUrdf(), AnalysisMode::Spatial);
  const SparseJacobian J = computeConstraintJacobian(model, model.q0);
  for (int r = 0; r < J.rows(); ++r) {
    EXPECT_LE(J.row(r).nonZeros(), 4 * model.dim) << describeEquation(model, r);
    EXPECT_GT(J.row(r).nonZeros(), 0) << describeEquation(model, r);
  }
}
