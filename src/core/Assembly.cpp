#include "mobility_analysis/Assembly.hpp"

#include <cmath>
#include <cstdio>

#include <Eigen/SparseCholesky>

#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

double maxAbs(const Eigen::VectorXd& v) { return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff(); }

/// The loop-closing connection (loop joint, distance constraint, cable) furthest from holding, with that
/// residual; a tree joint only when no loop element is violated.
std::pair<int, double> worstJoint(const Mechanism& mechanism, const CoordinateModel& model,
                                  const Eigen::VectorXd& phi) {
  int worst = -1;
  double residual = 0.0;
  for (const bool loopsOnly : {true, false}) {
    for (int i = 0; i < model.numConstraints(); ++i) {
      const ConstraintEquation& eq = model.equations[i];
      if (eq.source != EquationSource::Joint || std::abs(phi(i)) <= residual) continue;
      if (loopsOnly && mechanism.joints[eq.element].kind == ConnectionKind::TreeJoint) continue;
      residual = std::abs(phi(i));
      worst = eq.element;
    }
    if (worst >= 0) break;
  }
  return {worst, residual};
}

}  // namespace

Result<AssembledMechanism> assembleMechanism(const Mechanism& mechanism, const LinkPoses& startPoses,
                                             AnalysisMode mode) {
  const double lc = computeCharacteristicLength(mechanism, startPoses);
  Result<CoordinateModel> spatial = buildCoordinateModel(mechanism, startPoses, AnalysisMode::Spatial, lc);
  if (!isOk(spatial)) return diagnosticOf(spatial);
  const CoordinateModel& model3 = valueOf(spatial);

  AssembledMechanism assembled;
  Eigen::VectorXd q = model3.q0;
  Eigen::VectorXd phi;
  computeConstraintResidual(model3, q, phi);
  assembled.initialResidual = maxAbs(phi) * lc;
  // Levenberg-Marquardt in the minimum-norm form: dq = -J^T (J J^T + mu I)^-1 Phi. Consistent redundant
  // equations make J J^T singular, which the damping absorbs; each step is the least change that closes.
  double mu = 1e-10;
  double norm = phi.norm();
  int iteration = 0;
  for (; iteration < tolerances::kAssemblyMaxIterations && maxAbs(phi) > tolerances::kClosure; ++iteration) {
    const SparseJacobian J = computeConstraintJacobian(model3, q);
    const Eigen::SparseMatrix<double> jt = J.transpose();
    Eigen::SparseMatrix<double> normal = (J * jt).eval();
    bool improved = false;
    for (int attempt = 0; attempt < 12 && !improved; ++attempt) {
      Eigen::SparseMatrix<double> damped = normal;
      for (int i = 0; i < damped.rows(); ++i) damped.coeffRef(i, i) += mu;
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(damped);
      if (solver.info() != Eigen::Success) {
        mu *= 100.0;
        continue;
      }
      const Eigen::VectorXd multipliers = solver.solve(phi);
      const Eigen::VectorXd candidate = q - jt * multipliers;
      Eigen::VectorXd candidatePhi;
      computeConstraintResidual(model3, candidate, candidatePhi);
      if (candidatePhi.norm() < norm) {
        q = candidate;
        phi = candidatePhi;
        norm = phi.norm();
        mu = std::max(mu / 10.0, 1e-14);
        improved = true;
      } else {
        mu *= 100.0;
      }
    }
    if (!improved) break;
  }
  assembled.iterations = iteration;
  if (maxAbs(phi) > tolerances::kAssemblyFailure) {
    const auto [joint, residual] = worstJoint(mechanism, model3, phi);
    char what[200];
    std::snprintf(what, sizeof(what),
                  "the loop cannot be closed: residual %.3g m after %d Newton iterations (from %.3g m)", residual * lc,
                  iteration, assembled.initialResidual);
    if (joint < 0) return makeDiagnostic(mechanism.file, "robot", mechanism.name, what);
    return makeDiagnostic(mechanism.file, toString(mechanism.joints[joint].kind), mechanism.joints[joint].name, what);
  }
  assembled.poses = recoverPoses(model3, q, startPoses);

  Result<CoordinateModel> model = buildCoordinateModel(mechanism, assembled.poses, mode, lc);
  if (!isOk(model)) return diagnosticOf(model);
  assembled.model = valueOf(std::move(model));
  assembled.q = computeCoordinates(assembled.model, assembled.poses);
  computeConstraintResidual(assembled.model, assembled.q, phi);
  assembled.finalResidual = maxAbs(phi) * lc;
  if (maxAbs(phi) > tolerances::kAssemblyFailure) {
    const auto [joint, residual] = worstJoint(mechanism, assembled.model, phi);
    char what[160];
    std::snprintf(what, sizeof(what), "the assembled pose does not satisfy the constraints (residual %.3g m)",
                  residual * lc);
    const std::string name = joint < 0 ? mechanism.name : mechanism.joints[joint].name;
    return makeDiagnostic(mechanism.file, joint < 0 ? "robot" : toString(mechanism.joints[joint].kind), name, what);
  }
  return assembled;
}

}  // namespace mobility_analysis
