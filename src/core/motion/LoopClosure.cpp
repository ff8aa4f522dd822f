#include "mobility_analysis/motion/LoopClosure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>

#include <Eigen/SparseCholesky>

#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

double maxAbs(const Eigen::VectorXd& v) {
  return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff();
}

}  // namespace

bool solveDampedLeastSquares(const Eigen::SparseMatrix<double>& J, const Eigen::VectorXd& r, double mu,
                             Eigen::VectorXd& step) {
  const Eigen::SparseMatrix<double> jt = J.transpose();
  Eigen::SparseMatrix<double> normal =
      J.rows() <= J.cols() ? Eigen::SparseMatrix<double>(J * jt) : Eigen::SparseMatrix<double>(jt * J);
  Eigen::SparseMatrix<double> identity(normal.rows(), normal.cols());
  identity.setIdentity();
  normal += mu * identity;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
  if (solver.info() != Eigen::Success)
    return false;
  if (J.rows() <= J.cols())
    step = -(jt * solver.solve(r));
  else
    step = -solver.solve(jt * r);
  return solver.info() == Eigen::Success && step.allFinite();
}

namespace {

/// A small deterministic generator (the restarts must not depend on the platform's random library).
struct Lcg {
  std::uint64_t state;
  double next() {  // uniform in [-1, 1)
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * (2.0 / 9007199254740992.0) - 1.0;
  }
};

}  // namespace

ClosureSolve solveClosure(const Mechanism& mechanism, const ClosureLayout& layout,
                          const std::vector<int>& columns, int numColumns, TreeConfiguration& configuration,
                          int maxIterations, Eigen::VectorXd* change) {
  ClosureSolve result;
  LinkPoses poses = posesOf(mechanism, layout, configuration);
  Eigen::VectorXd r, trialR, step;
  Eigen::SparseMatrix<double> J;
  // Closed already (the usual case for a written or previous pose): no Jacobian, whose rows walk the tree
  // paths of every loop (long on deep trees such as a mast written as one chain).
  evaluateClosure(mechanism, layout, poses, columns, numColumns, r, nullptr);
  if (maxAbs(r) <= layout.target) {
    result.residual = maxAbs(r);
    result.converged = true;
    result.poses = std::move(poses);
    return result;
  }
  evaluateClosure(mechanism, layout, poses, columns, numColumns, r, &J);
  double cost = r.squaredNorm();
  double mu = -1.0, nu = 2.0;
  // Below the target, a few more steps take the residual down to round-off; then stop.
  const double floor = layout.target * 1e-2;
  int belowTargetSteps = 0;
  while (result.iterations < maxIterations && maxAbs(r) > floor && numColumns > 0) {
    if (maxAbs(r) <= layout.target && ++belowTargetSteps > 3)
      break;
    if (mu < 0.0) {
      double largest = 0.0;
      for (int k = 0; k < J.outerSize(); ++k)
        for (Eigen::SparseMatrix<double>::InnerIterator it(J, k); it; ++it)
          largest = std::max(largest, std::abs(it.value()));
      mu = 1e-10 * std::max(largest * largest, 1e-12);
    }
    ++result.iterations;
    if (!solveDampedLeastSquares(J, r, mu, step)) {
      mu *= nu;
      nu *= 2.0;
      if (mu > 1e20)
        break;
      continue;
    }
    const double stepSize = maxAbs(step);
    if (stepSize > 1.0)
      step /= stepSize;  // trust radius: 1 rad or 1 Lc per step
    const double predicted = cost - (r + J * step).squaredNorm();
    if (!(predicted > 0.0) || stepSize < 1e-15)
      break;  // stationary point of the residual
    TreeConfiguration trial = configuration;
    applyIncrement(mechanism, layout, columns, step, trial);
    const LinkPoses trialPoses = posesOf(mechanism, layout, trial);
    evaluateClosure(mechanism, layout, trialPoses, columns, numColumns, trialR, nullptr);
    const double trialCost = trialR.squaredNorm();
    const double rho = (cost - trialCost) / predicted;
    if (rho > 0.0 && std::isfinite(trialCost)) {
      configuration = std::move(trial);
      poses = trialPoses;
      if (change != nullptr)
        *change += step;
      evaluateClosure(mechanism, layout, poses, columns, numColumns, r, &J);
      cost = r.squaredNorm();
      mu *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      mu = std::max(mu, 1e-30);
      nu = 2.0;
    } else {
      mu *= nu;
      nu *= 2.0;
      if (mu > 1e20)
        break;
    }
  }
  result.residual = maxAbs(r);
  result.converged = result.residual <= layout.target;
  result.poses = std::move(poses);  // r is the residual at these poses: each accepted step set both
  return result;
}

Result<ClosedConfiguration> closeLoops(const Mechanism& mechanism, const ClosureLayout& layout,
                                       const TreeConfiguration& start, const std::vector<int>& columns,
                                       int numColumns) {
  ClosedConfiguration best;
  best.configuration = start;
  int iterations = 0;
  Eigen::VectorXd change = Eigen::VectorXd::Zero(numColumns);
  ClosureSolve first = solveClosure(mechanism, layout, columns, numColumns, best.configuration,
                                    tolerances::kClosureMaxIterations);
  iterations += first.iterations;
  if (first.converged) {
    // The first run's end point is the answer: its poses and residual, not computed a second time.
    best.poses = std::move(first.poses);
    best.residual = first.residual;
    best.iterations = iterations;
    return best;
  }
  double bestResidual = first.residual;
  TreeConfiguration bestAttempt = best.configuration;
  // Restarts from perturbed starts, smallest perturbations first; of the first size that closes, the
  // solution nearest the start (least change) wins.
  Lcg random{0x9E3779B97F4A7C15ULL};
  const double amplitudes[] = {0.1, 0.3, 1.0, 2.0};
  constexpr int kSeedsPerAmplitude = 3;
  bool closed = false;
  int restarts = 0;
  for (const double amplitude : amplitudes) {
    double nearest = std::numeric_limits<double>::infinity();
    for (int seed = 0; seed < kSeedsPerAmplitude; ++seed) {
      ++restarts;
      Eigen::VectorXd perturbation(numColumns);
      for (int k = 0; k < numColumns; ++k)
        perturbation(k) = amplitude * random.next();
      TreeConfiguration attempt = start;
      applyIncrement(mechanism, layout, columns, perturbation, attempt);
      change = perturbation;
      const ClosureSolve solve = solveClosure(mechanism, layout, columns, numColumns, attempt,
                                              tolerances::kClosureMaxIterations, &change);
      iterations += solve.iterations;
      if (solve.converged && change.norm() < nearest) {
        nearest = change.norm();
        best.configuration = attempt;
        best.restarts = restarts;
        closed = true;
      }
      if (!closed && solve.residual < bestResidual) {
        bestResidual = solve.residual;
        bestAttempt = attempt;
      }
    }
    if (closed)
      break;
  }
  if (!closed) {
    const LinkPoses reached = posesOf(mechanism, layout, bestAttempt);
    Eigen::VectorXd r;
    evaluateClosure(mechanism, layout, reached, columns, numColumns, r, nullptr);
    const auto [joint, residual] = largestClosureResidual(mechanism, layout, r);
    std::string pose;
    int listed = 0;
    for (const auto& [name, value] : computeJointPositions(mechanism, reached)) {
      if (listed++ == 8) {
        pose += ", ...";
        break;
      }
      char item[96];
      std::snprintf(item, sizeof(item), "%s%s=%.6g", listed > 1 ? ", " : "", name.c_str(), value);
      pose += item;
    }
    char what[200];
    std::snprintf(
        what, sizeof(what),
        "the loop cannot be closed: residual %.3g m after %d iterations and %d restarts; pose reached: ",
        residual * layout.lengthScale, iterations, restarts);
    if (joint < 0)
      return makeDiagnostic(mechanism.file, "robot", mechanism.name, what + pose);
    return makeDiagnostic(mechanism.file, toString(mechanism.joints[joint].kind),
                          mechanism.joints[joint].name, what + pose);
  }
  best.poses = posesOf(mechanism, layout, best.configuration);
  Eigen::VectorXd r;
  evaluateClosure(mechanism, layout, best.poses, columns, numColumns, r, nullptr);
  best.residual = maxAbs(r);
  best.iterations = iterations;
  return best;
}

}  // namespace mobility_analysis
