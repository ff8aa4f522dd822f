#include "mobility_analysis/analysis/FiniteMobility.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>

#include "mobility_analysis/Tolerances.hpp"
#include "mobility_analysis/coordinates/EquationForms.hpp"

namespace mobility_analysis {

namespace {

/// Step along a first-order motion before projecting back [normalised length].
constexpr double kStep = 1e-4;
/// The largest residual a projected step may keep [normalised] (near the model's origin).
constexpr double kProjected = 1e-13;
/// A quadratic form Q_ω whose entries are below this fraction of its scale (Σ |ω_i| |H_i| |x|^2) vanishes
/// [-].
constexpr double kSecondOrder = 1e-6;
/// Q_ω is measured against the larger of its scale and this fraction of Σ|ω_i| (what unit Hessians and unit
/// motions would give) [-]. Why: a stress over equations the motions leave still (or whose Hessians vanish)
/// has a scale of rounding, 1e-17, and its Q_ω of rounding too; their ratio came out of order 1 and read as
/// a second-order obstruction. A triangular-prism scissor mast, which deploys, was then called singular,
/// and its finite DOF left to stepping, which read 0 when its elements were written in another order.
constexpr double kFormScaleFloor = 1e-9;
/// A projected step that ends closer to the pose than this fraction of the step came back: no motion there
/// [-].
constexpr double kReturned = 0.25;
/// A projection that moves the stepped point less than this fraction of the step: the direction extends [-].
constexpr double kExtends = 0.05;
/// Random combinations of first-order motions sampled at a singular pose, beyond the basis directions.
constexpr int kRandomSamples = 4;
/// The share of a random combination added to each basis direction sampled at a singular pose [-]: enough to
/// leave the singular set by far more than the rank tolerance after one step (kStep times this).
constexpr double kGenericShare = 0.3;
/// Stresses are split into structural and configuration ones densely up to this many.
constexpr int kMaxDenseStresses = 2000;

double maxAbs(const Eigen::VectorXd& v) {
  return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff();
}

}  // namespace

std::pair<Eigen::VectorXd, bool> projectOntoConstraints(const CoordinateModel& model,
                                                        const Eigen::Ref<const Eigen::VectorXd>& start,
                                                        double closure, int maxIterations) {
  Eigen::VectorXd q = start, phi;
  computeConstraintResidual(model, q, phi);
  double norm = phi.norm();
  double mu = 1e-12;
  for (int iteration = 0; iteration < maxIterations && maxAbs(phi) > closure; ++iteration) {
    const SparseJacobian J = computeConstraintJacobian(model, q);
    const Eigen::SparseMatrix<double> jt = J.transpose();
    const Eigen::SparseMatrix<double> normal = (J * jt).eval();
    bool improved = false;
    for (int attempt = 0; attempt < 12 && !improved; ++attempt) {
      Eigen::SparseMatrix<double> damped = normal;
      for (int i = 0; i < damped.rows(); ++i)
        damped.coeffRef(i, i) += mu;
      const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(damped);
      if (solver.info() != Eigen::Success) {
        mu *= 100.0;
        continue;
      }
      const Eigen::VectorXd candidate = q - jt * solver.solve(phi);
      Eigen::VectorXd candidatePhi;
      computeConstraintResidual(model, candidate, candidatePhi);
      if (candidatePhi.norm() < norm) {
        q = candidate;
        phi = candidatePhi;
        norm = phi.norm();
        mu = std::max(mu / 10.0, 1e-16);
        improved = true;
      } else {
        mu *= 100.0;
      }
    }
    if (!improved)
      break;
  }
  return {q, maxAbs(phi) <= closure};
}

FiniteMobility analyzeFiniteMobility(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                                     const SparseJacobian& J, const SelfStressBasis& basis,
                                     const OrderedRank& ranks, double tolerance) {
  const int m = model.numConstraints();
  const int n = model.numCoordinates();
  FiniteMobility result;
  result.finiteDof = ranks.dof();
  result.configurationCause.assign(m, false);
  result.structuralStresses = basis.stresses;
  const int numStresses = static_cast<int>(basis.stresses.size());
  // No self-stress: J has full row rank, the configuration set is a manifold of dimension nullity.
  if (numStresses == 0 || ranks.dof() == 0)
    return result;
  // The sweep keeps the motions only up to the number this test forms Q_ω for (SelfStressBasis::kMaxMotions).
  if (!basis.motionsComputed) {
    result.note = "too many first-order motions for the second-order test; finite_dof is the nullity";
    return result;
  }
  const int d = static_cast<int>(basis.motions.size());
  std::vector<Eigen::VectorXd> x = basis.motions;
  for (Eigen::VectorXd& v : x)
    v /= std::max(maxAbs(v), 1e-300);

  // h_i(a, b) = x_a^T H_i x_b for every equation some stress uses, with its scale Σ |H| |x_a| |x_b|.
  const int pairs = d * (d + 1) / 2;
  std::vector<int> slot(m, -1);
  std::vector<int> used;
  for (const SelfStress& stress : basis.stresses) {
    for (const auto& entry : stress) {
      if (slot[entry.first] < 0) {
        slot[entry.first] = static_cast<int>(used.size());
        used.push_back(entry.first);
      }
    }
  }
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(pairs, static_cast<Eigen::Index>(used.size()));
  Eigen::VectorXd magnitude = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(used.size()));
  const ElementView view(model, q);
  HessianSink entries;
  for (size_t u = 0; u < used.size(); ++u) {
    const ConstraintEquation& eq = model.equations[used[u]];
    entries.clear();
    visitForm(eq.form, [&](auto form) { form.hessian(view, eq, 1.0, entries); });
    for (const Eigen::Triplet<double>& t : entries) {
      double largestR = 0.0, largestC = 0.0;
      for (int a = 0, p = 0; a < d; ++a) {
        largestR = std::max(largestR, std::abs(x[a](t.row())));
        largestC = std::max(largestC, std::abs(x[a](t.col())));
        for (int b = a; b < d; ++b, ++p)
          h(p, static_cast<Eigen::Index>(u)) += t.value() * x[a](t.row()) * x[b](t.col());
      }
      magnitude(static_cast<Eigen::Index>(u)) += std::abs(t.value()) * largestR * largestC;
    }
  }
  // Q_ω per stress, relative to its scale. Stress coefficients refer to unit-norm rows: ω_i = y_i / |J_i|.
  Eigen::MatrixXd forms = Eigen::MatrixXd::Zero(numStresses, pairs);
  for (int s = 0; s < numStresses; ++s) {
    double scale = 0.0, weight = 0.0;
    for (const auto& [row, y] : basis.stresses[s]) {
      const double norm = J.row(row).norm();
      if (norm <= 0.0)
        continue;
      const double omega = y / norm;
      forms.row(s) += omega * h.col(slot[row]).transpose();
      scale += std::abs(omega) * magnitude(slot[row]);
      weight += std::abs(omega);
    }
    scale = std::max(scale, kFormScaleFloor * weight);
    forms.row(s) = scale > 0.0 ? (forms.row(s) / scale).eval() : Eigen::RowVectorXd::Zero(pairs).eval();
  }
  int configurationRank = 0;
  if (forms.cwiseAbs().maxCoeff() > kSecondOrder) {
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(forms);
    qr.setThreshold(kSecondOrder);
    configurationRank = static_cast<int>(qr.rank());
  }

  // Orthonormal first-order motions for stepping.
  const bool canStep = n <= kFiniteMobilityStepLimit;
  if (!canStep) {
    result.note = configurationRank == 0 ? "second-order test only (step-and-project skipped above " +
                                               std::to_string(kFiniteMobilityStepLimit) + " coordinates)"
                                         : "singular to second order; step-and-project skipped above " +
                                               std::to_string(kFiniteMobilityStepLimit) + " coordinates";
  }
  Eigen::MatrixXd N(n, d);
  for (int a = 0; a < d; ++a)
    N.col(a) = x[a];
  const Eigen::MatrixXd directions =
      canStep ? Eigen::MatrixXd(Eigen::HouseholderQR<Eigen::MatrixXd>(N).householderQ() *
                                Eigen::MatrixXd::Identity(n, d))
              : Eigen::MatrixXd();
  // Projected to 1e-13, or to the rounding of the coordinates where they are far larger than 1 (a mechanism
  // 10^3 Lc off its model's origin never projected below 1e-13, and its every direction read as no motion).
  const double largest = canStep && q.size() > 0 ? q.cwiseAbs().maxCoeff() : 0.0;
  const double closure = tolerances::reachableTarget(kProjected, largest);
  auto step = [&](const Eigen::VectorXd& direction) {
    const Eigen::VectorXd stepped = q + kStep * direction.normalized();
    return std::make_pair(stepped, projectOntoConstraints(model, stepped, closure, 60));
  };

  bool extends = true;
  if (configurationRank == 0) {
    if (!canStep)
      return result;
    result.steppedAndProjected = true;
    for (int a = 0; a < d && extends; ++a) {
      const auto [stepped, projected] = step(directions.col(a));
      extends = projected.second && (projected.first - stepped).norm() < kExtends * kStep;
    }
    if (extends)
      return result;
  }

  // Singular: measure the dimension of the configuration set by stepping and projecting.
  if (canStep) {
    result.steppedAndProjected = true;
    std::mt19937 random(1);
    std::normal_distribution<double> normal;
    int finite = 0;
    for (int sample = 0; sample < d + kRandomSamples; ++sample) {
      // Every direction is generic: a basis direction, with a random combination of all of them added. A step
      // along a basis direction alone may stay on the singular set, whose nullity is not the dimension of the
      // branch around it: a floating base's rigid motion carries a flat four-bar to another flat pose
      // (nullity 2 + 3, the branches 1 + 3), and one flat four-bar's own motion leaves a second one flat (two
      // flat four-bars: nullity 1 + 2, the branches 1 + 1). A generic step lands off it, where the nullity is
      // the dimension of the branch it reached.
      Eigen::VectorXd c(d);
      for (int a = 0; a < d; ++a)
        c(a) = normal(random);
      Eigen::VectorXd direction = directions * c.normalized();
      if (sample < d)
        direction = directions.col(sample) + kGenericShare * direction;
      const auto [stepped, projected] = step(direction);
      (void)stepped;
      if ((projected.first - q).norm() < kReturned * kStep)
        continue;  // came back: no configuration that way
      if (!projected.second)
        continue;
      const int dimension =
          computeOrderedRank(computeConstraintJacobian(model, projected.first), tolerance, false).dof();
      finite = std::max(finite, std::min(dimension, ranks.dof()));
    }
    result.finiteDof = finite;
  } else {
    result.finiteDof = ranks.dof() - configurationRank;  // the second-order count alone
  }
  result.singular = result.finiteDof != ranks.dof();
  if (!result.singular)
    return result;

  // Causes: the stresses whose Q_ω vanishes persist (structural); the rest exist only at this pose.
  result.configurationStresses = configurationRank;
  if (configurationRank == 0 || numStresses > kMaxDenseStresses)
    return result;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(forms.transpose());
  lu.setThreshold(kSecondOrder);
  std::vector<SelfStress> structural;
  if (lu.dimensionOfKernel() > 0) {
    const Eigen::MatrixXd kernel = lu.kernel();
    for (int k = 0; k < kernel.cols(); ++k) {
      std::map<int, double> combined;
      for (int s = 0; s < numStresses; ++s) {
        if (kernel(s, k) == 0.0)
          continue;
        for (const auto& [row, y] : basis.stresses[s])
          combined[row] += kernel(s, k) * y;
      }
      double largest = 0.0;
      for (const auto& entry : combined)
        largest = std::max(largest, std::abs(entry.second));
      SelfStress stress;
      for (const auto& [row, y] : combined) {
        if (std::abs(y) > 1e-10 * largest)
          stress.emplace_back(row, y / largest);
      }
      structural.push_back(std::move(stress));
    }
  }
  SelfStressBasis persistent;
  persistent.stresses = structural;
  persistent.numConstraints = m;
  persistent.numCoordinates = n;
  persistent.rank = ranks.rank;
  const std::optional<OrderedRank> structuralRanks = computeOrderedRankFromStresses(persistent, tolerance);
  for (int r = 0; r < m; ++r) {
    const bool structuralRedundant = structuralRanks ? bool(structuralRanks->redundant[r]) : false;
    result.configurationCause[r] = ranks.redundant[r] && !structuralRedundant;
  }
  result.structuralStresses = std::move(structural);
  return result;
}

}  // namespace mobility_analysis
