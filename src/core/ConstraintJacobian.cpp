#include "mobility_analysis/ConstraintJacobian.hpp"

#include <vector>

#include "mobility_analysis/coordinates/EquationForms.hpp"

namespace mobility_analysis {

// Each function below is a dispatcher: the form types of EquationForms.hpp own the algebra.

void computeConstraintResidual(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                               Eigen::VectorXd& phi) {
  const ElementView view(model, q);
  phi.resize(model.numConstraints());
  for (int i = 0; i < model.numConstraints(); ++i) {
    const ConstraintEquation& eq = model.equations[i];
    phi(i) = visitForm(eq.form, [&](auto form) { return form.value(view, eq); });
  }
}

SparseJacobian computeConstraintJacobian(const CoordinateModel& model,
                                         const Eigen::Ref<const Eigen::VectorXd>& q) {
  const ElementView view(model, q);
  GradientSink triplets;
  triplets.reserve(static_cast<size_t>(model.numConstraints()) * 12);
  for (int i = 0; i < model.numConstraints(); ++i) {
    const ConstraintEquation& eq = model.equations[i];
    visitForm(eq.form, [&](auto form) { form.gradient(view, eq, i, triplets); });
  }
  SparseJacobian jacobian(model.numConstraints(), model.numCoordinates());
  jacobian.setFromTriplets(triplets.begin(), triplets.end());
  jacobian.prune(0.0);
  return jacobian;
}

Eigen::MatrixXd computeEquationHessian(const CoordinateModel& model,
                                       const Eigen::Ref<const Eigen::VectorXd>& q, int row) {
  const ElementView view(model, q);
  HessianSink triplets;
  const ConstraintEquation& eq = model.equations[row];
  visitForm(eq.form, [&](auto form) { form.hessian(view, eq, 1.0, triplets); });
  Eigen::MatrixXd hessian = Eigen::MatrixXd::Zero(model.numCoordinates(), model.numCoordinates());
  // The forms write both triangles ((a, b) block M, (b, a) block M^T); repeated entries add up.
  for (const Eigen::Triplet<double>& t : triplets)
    hessian(t.row(), t.col()) += t.value();
  return hessian;
}

Eigen::SparseMatrix<double> computeStressedHessian(const CoordinateModel& model,
                                                   const Eigen::Ref<const Eigen::VectorXd>& q,
                                                   const Eigen::Ref<const Eigen::VectorXd>& weights) {
  const ElementView view(model, q);
  HessianSink triplets;
  for (int i = 0; i < model.numConstraints(); ++i) {
    if (weights(i) == 0.0)
      continue;
    const ConstraintEquation& eq = model.equations[i];
    visitForm(eq.form, [&](auto form) { form.hessian(view, eq, weights(i), triplets); });
  }
  Eigen::SparseMatrix<double> hessian(model.numCoordinates(), model.numCoordinates());
  hessian.setFromTriplets(triplets.begin(), triplets.end());
  return hessian;
}

}  // namespace mobility_analysis
