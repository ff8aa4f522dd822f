#include "mobility_analysis/ConstraintJacobian.hpp"

#include <random>
#include <set>

#include <gtest/gtest.h>

#include "EigenTestHelpers.hpp"
#include "mobility_analysis/coordinates/EquationForms.hpp"
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

namespace {

/// Each equation's Hessian against central differences of its Jacobian row at a random pose, per form; the
/// quadratic forms' Hessians must not move with q, and the stressed Hessian is the weighted sum.
void expectHessiansMatchFiniteDifferences(const CoordinateModel& model, unsigned seed,
                                          std::set<EquationForm>& formsSeen) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(-0.3, 0.3);
  Eigen::VectorXd q = model.q0, q2 = model.q0;
  for (int i = 0; i < q.size(); ++i) {
    q(i) += uniform(random);
    q2(i) += uniform(random);
  }
  const double h = 1e-5;
  std::vector<Eigen::MatrixXd> numeric(model.numConstraints(),
                                       Eigen::MatrixXd(model.numCoordinates(), model.numCoordinates()));
  for (int j = 0; j < q.size(); ++j) {
    Eigen::VectorXd qp = q, qm = q;
    qp(j) += h;
    qm(j) -= h;
    const Eigen::MatrixXd difference =
        (Eigen::MatrixXd(computeConstraintJacobian(model, qp)) - Eigen::MatrixXd(computeConstraintJacobian(model, qm))) /
        (2 * h);
    for (int i = 0; i < model.numConstraints(); ++i)
      numeric[i].col(j) = difference.row(i).transpose();
  }
  Eigen::VectorXd weights(model.numConstraints());
  Eigen::MatrixXd weightedSum = Eigen::MatrixXd::Zero(model.numCoordinates(), model.numCoordinates());
  for (int i = 0; i < model.numConstraints(); ++i) {
    const ConstraintEquation& eq = model.equations[i];
    formsSeen.insert(eq.form);
    const Eigen::MatrixXd analytic = computeEquationHessian(model, q, i);
    EXPECT_TRUE(matricesNear(numeric[i], analytic, 1e-7)) << describeEquation(model, i);
    EXPECT_TRUE(matricesNear(analytic, analytic.transpose(), 0.0)) << "not symmetric: " << describeEquation(model, i);
    if (hasConstantHessian(eq.form)) {
      EXPECT_TRUE(matricesNear(computeEquationHessian(model, q2, i), analytic, 1e-14)) << describeEquation(model, i);
    }
    weights(i) = uniform(random);
    weightedSum += weights(i) * analytic;
  }
  EXPECT_TRUE(matricesNear(Eigen::MatrixXd(computeStressedHessian(model, q, weights)), weightedSum, 1e-12));
  // Second-order Taylor expansion: exact (up to rounding) for the quadratic forms, O(|d|^3) for the triple.
  Eigen::VectorXd delta(q.size());
  for (int i = 0; i < delta.size(); ++i)
    delta(i) = 1e-3 * uniform(random);
  Eigen::VectorXd phi, phiStep;
  computeConstraintResidual(model, q, phi);
  computeConstraintResidual(model, q + delta, phiStep);
  const Eigen::VectorXd linear = computeConstraintJacobian(model, q) * delta;
  for (int i = 0; i < model.numConstraints(); ++i) {
    const double quadratic = 0.5 * delta.dot(computeEquationHessian(model, q, i) * delta);
    EXPECT_NEAR(phiStep(i), phi(i) + linear(i) + quadratic, hasConstantHessian(model.equations[i].form) ? 1e-13 : 1e-8)
        << describeEquation(model, i);
  }
}

}  // namespace

TEST(ConstraintJacobian, HessiansMatchFiniteDifferencesForEveryForm) {
  std::set<EquationForm> forms;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    expectHessiansMatchFiniteDifferences(buildFromText(allJointKindsUrdf(), AnalysisMode::Spatial), seed, forms);
    expectHessiansMatchFiniteDifferences(buildFromText(planarJointKindsUrdf(), AnalysisMode::Planar), seed, forms);
  }
  const Mechanism sliders = loadOrFail(urdfPath("three_sliders.urdf"));
  const LinkPoses poses = computeTreePoses(sliders, {});
  const Result<CoordinateModel> spatialSliders = buildCoordinateModel(
      sliders, poses, AnalysisMode::Spatial, computeCharacteristicLength(sliders, poses));
  ASSERT_TRUE(isOk(spatialSliders));
  expectHessiansMatchFiniteDifferences(valueOf(spatialSliders), 7, forms);
  for (EquationForm form : {EquationForm::Dot, EquationForm::Cross, EquationForm::Component,
                            EquationForm::Combination, EquationForm::Triple}) {
    EXPECT_TRUE(forms.count(form)) << "no equation of form " << static_cast<int>(form);
  }
  EXPECT_FALSE(hasConstantHessian(EquationForm::Triple));
  EXPECT_TRUE(hasConstantHessian(EquationForm::Combination));
}

TEST(ConstraintJacobian, HalvesOnTwoThreadsGiveTheSameMatrix) {
  // From 2 10^4 equations the analysis writes the second half of the rows on a second thread: the matrix
  // must be the one-thread matrix, index for index and bit for bit (a chain in the plane and in space).
  Result<Mechanism> mechanism = loadMechanismFromString(straightChainUrdf(6000), "chain.urdf");
  ASSERT_TRUE(isOk(mechanism)) << diagnosticOf(mechanism).toString();
  for (AnalysisMode mode : {AnalysisMode::Planar, AnalysisMode::Spatial}) {
    const ModelAtTreePose m = assembleAtTreePose(valueOf(mechanism), mode);
    ASSERT_GE(m.J.rows(), 20000);
    const SparseJacobian one = computeConstraintJacobian(m.assembled.model, m.assembled.q, false);
    const SparseJacobian two = computeConstraintJacobian(m.assembled.model, m.assembled.q, true);
    ASSERT_EQ(one.rows(), two.rows());
    ASSERT_EQ(one.nonZeros(), two.nonZeros());
    EXPECT_TRUE(std::equal(one.outerIndexPtr(), one.outerIndexPtr() + one.rows() + 1, two.outerIndexPtr()));
    EXPECT_TRUE(std::equal(one.innerIndexPtr(), one.innerIndexPtr() + one.nonZeros(), two.innerIndexPtr()));
    EXPECT_TRUE(std::equal(one.valuePtr(), one.valuePtr() + one.nonZeros(), two.valuePtr()));
    EXPECT_TRUE(std::equal(one.valuePtr(), one.valuePtr() + one.nonZeros(), m.J.valuePtr()));
  }
}
