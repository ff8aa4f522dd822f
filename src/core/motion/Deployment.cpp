#include "mobility_analysis/motion/Deployment.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include <Eigen/SparseCholesky>

#include "mobility_analysis/Assembly.hpp"
#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/Kinematics.hpp"
#include "mobility_analysis/SelfStressBasis.hpp"
#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

/// Newton converged when max |Phi| is below this [Lc] (the assembly's closure). On a 1000-unit mast J is so
/// ill-conditioned that Newton gets no further, and the stop is then located to ~3e-7 relative (within the
/// cables' taut tolerance tolerances::kCableTaut); small models land within 1e-12.
constexpr double kStepClosure = tolerances::kClosure;
constexpr int kStepIterations = 30;
/// A located crossing leaves every passive cable's relative gap in [0, kCrossingGap].
constexpr double kCrossingGap = 1e-9;
/// A step that does not converge is halved at most this many times before the deployment stops.
constexpr int kMaxHalvings = 10;
/// Models up to this many coordinates get their DOF computed at every step.
constexpr int kDofEveryStepCoordinates = 5000;
/// Larger models: about this many steps get their DOF computed.
constexpr int kDofSamples = 20;
/// Added to the diagonal of J J^T [Lc^2]: keeps it factorable when rows are (consistently) dependent.
constexpr double kDamping = 1e-13;

double maxAbs(const Eigen::VectorXd& v) {
  return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff();
}

/// The driven model: one distance equation whose value is the active cable's length.
struct DrivenModel {
  CoordinateModel model;
  int driverRow = -1;
  double lc = 1.0;

  void setLength(double length) { model.equations[driverRow].value = (length / lc) * (length / lc); }
};

/// Newton from @p q to Phi(q) = 0 with minimum-norm steps (a tiny damping makes consistent redundant
/// equations harmless) and backtracking when a step would more than double |Phi|.
/// The factorisation of J J^T, whose pattern is the same at every step: ordered once, refactored per iteration.
struct NewtonWorkspace {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  Eigen::Index analysedNonZeros = -1;
};

bool solve(const CoordinateModel& model, Eigen::VectorXd& q, NewtonWorkspace& workspace) {
  Eigen::VectorXd phi;
  computeConstraintResidual(model, q, phi);
  for (int iteration = 0; iteration < kStepIterations; ++iteration) {
    if (maxAbs(phi) <= kStepClosure)
      return true;
    // Rows scaled to unit norm: the same Newton step (the solution set of J dq = -Phi is unchanged), but the
    // driving row of a long mast, whose length moves a thousand bars, no longer dwarfs J J^T's conditioning.
    const SparseJacobian raw = computeConstraintJacobian(model, q);
    Eigen::VectorXd rowScale(raw.rows());
    for (int r = 0; r < raw.rows(); ++r) {
      const double norm = raw.row(r).norm();
      rowScale(r) = norm > 0.0 ? 1.0 / norm : 1.0;
    }
    const SparseJacobian J = rowScale.asDiagonal() * raw;
    const Eigen::SparseMatrix<double> jt = J.transpose();
    const Eigen::SparseMatrix<double> normal = (J * jt).eval();
    Eigen::SparseMatrix<double> damped = normal;
    for (int i = 0; i < damped.rows(); ++i)
      damped.coeffRef(i, i) += kDamping;
    if (damped.nonZeros() != workspace.analysedNonZeros) {
      workspace.ldlt.analyzePattern(damped);
      workspace.analysedNonZeros = damped.nonZeros();
    }
    workspace.ldlt.factorize(damped);
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& ldlt = workspace.ldlt;
    if (ldlt.info() != Eigen::Success)
      return false;
    // Minimum-norm step J^T (J J^T)^-1 Phi, refined against the undamped J J^T.
    const Eigen::VectorXd scaledPhi = rowScale.cwiseProduct(phi);
    Eigen::VectorXd multipliers = ldlt.solve(scaledPhi);
    for (int refinement = 0; refinement < 2; ++refinement)
      multipliers += ldlt.solve((scaledPhi - normal * multipliers).eval());
    const Eigen::VectorXd step = jt * multipliers;
    const double norm = phi.norm();
    bool accepted = false;
    for (double alpha = 1.0; alpha > 1e-3 && !accepted; alpha *= 0.5) {
      const Eigen::VectorXd candidate = q - alpha * step;
      Eigen::VectorXd candidatePhi;
      computeConstraintResidual(model, candidate, candidatePhi);
      if (candidatePhi.allFinite() && candidatePhi.norm() <= 2.0 * norm) {
        q = candidate;
        phi = candidatePhi;
        accepted = true;
      }
    }
    if (!accepted)
      return false;
  }
  return maxAbs(phi) <= kStepClosure;
}

double cableDistance(const Joint& joint, const LinkPoses& poses) {
  return ((poses[joint.link1] * joint.frame1.translation()) -
          (poses[joint.link2] * joint.frame2.translation()))
      .norm();
}

/// Smallest relative gap (length − distance) / length over the passive cables; +inf when there are none.
double smallestGap(const Mechanism& mechanism, const LinkPoses& poses) {
  double gap = std::numeric_limits<double>::infinity();
  for (const Joint& joint : mechanism.joints) {
    if (joint.kind == ConnectionKind::Cable && joint.cableType == CableType::Passive)
      gap = std::min(gap, (joint.length - cableDistance(joint, poses)) / joint.length);
  }
  return gap;
}

}  // namespace

Result<MobilityAnalysis> deployMechanism(const Mechanism& mechanism, const DeploymentOptions& options) {
  const std::optional<int> found = mechanism.findJoint(options.cable);
  if (!found || mechanism.joints[*found].kind != ConnectionKind::Cable)
    return makeDiagnostic(mechanism.file, "cable", options.cable, "--deploy names no cable of the mechanism");
  const int cable = *found;
  if (mechanism.joints[cable].cableType != CableType::Active)
    return makeDiagnostic(mechanism.file, "cable", options.cable,
                          "is a passive cable; deployment shortens an active cable");
  if (options.steps < 1)
    return makeDiagnostic(mechanism.file, "cable", options.cable, "--steps must be at least 1");
  const AnalysisOptions& start = options.analysis;
  Result<AssembledMechanism> assembled = assembleMechanism(
      mechanism, start.startPoses ? *start.startPoses : computeTreePoses(mechanism, start.positions),
      start.mode);
  if (!isOk(assembled))
    return diagnosticOf(assembled);
  LinkPoses poses = valueOf(assembled).poses;

  // Every cable but the driver is ignored by the model: passive cables are watched, not imposed.
  Mechanism driven = mechanism;
  for (Joint& joint : driven.joints) {
    if (joint.kind == ConnectionKind::Cable)
      joint.cableType = CableType::Active;
  }
  driven.joints[cable].kind = ConnectionKind::DistanceConstraint;
  DrivenModel dm;
  dm.lc = valueOf(assembled).model.characteristicLength;
  Result<CoordinateModel> model = buildCoordinateModel(driven, poses, valueOf(assembled).model.mode, dm.lc);
  if (!isOk(model))
    return diagnosticOf(model);
  dm.model = valueOf(std::move(model));
  for (int r = 0; r < dm.model.numConstraints(); ++r) {
    const ConstraintEquation& eq = dm.model.equations[r];
    if (eq.source == EquationSource::Joint && eq.element == cable && eq.kind == EquationKind::Distance)
      dm.driverRow = r;
  }
  Eigen::VectorXd q = computeCoordinates(dm.model, poses);

  DeploymentInfo info;
  info.cable = options.cable;
  info.initialLength = cableDistance(mechanism.joints[cable], poses);
  info.targetLength = options.targetLength ? *options.targetLength : 0.0;
  JointPositions previousPositions = computeJointPositions(mechanism, poses, start.positions);

  // DOF per step: the rank of J without the driving row, by the same sweep as the report (every step on
  // small models, else at about kDofSamples evenly spaced steps, the others carrying the last value).
  const int dofEvery =
      dm.model.numCoordinates() <= kDofEveryStepCoordinates ? 1 : std::max(1, options.steps / kDofSamples);
  int lastDof = -1;
  auto dofAt = [&](const Eigen::VectorXd& coordinates) {
    SparseJacobian J = computeConstraintJacobian(dm.model, coordinates);
    J.row(dm.driverRow) *= 0.0;
    const double tolerance = start.rankTolerance > 0.0 ? start.rankTolerance : tolerances::kRank;
    const SelfStressBasis basis = computeSelfStressBasis(driven, dm.model, J, tolerance);
    return basis.numCoordinates - basis.rank;
  };
  auto record = [&](double length, bool final) {
    DeploymentStep step;
    step.activeLength = length;
    const bool due = lastDof < 0 || final || info.steps.size() % static_cast<size_t>(dofEvery) == 0;
    step.dof = due ? (lastDof = dofAt(q)) : lastDof;
    for (size_t j = 0; j < mechanism.joints.size(); ++j) {
      const Joint& joint = mechanism.joints[j];
      if (joint.kind != ConnectionKind::Cable)
        continue;
      const double distance = cableDistance(joint, poses);
      std::string state = "driving";
      if (joint.cableType == CableType::Passive)
        state = (joint.length - distance) <= tolerances::kCableTaut * joint.length ? "taut" : "slack";
      step.cables.push_back(CableState{joint.name,
                                       joint.cableType == CableType::Active ? "active" : "passive", state,
                                       joint.length, distance});
    }
    previousPositions = computeJointPositions(mechanism, poses, previousPositions);
    for (const Joint& joint : mechanism.joints) {
      if (static_cast<int>(step.joints.size()) >= options.recordedJoints)
        break;
      const auto value = previousPositions.find(joint.name);
      if (joint.kind == ConnectionKind::TreeJoint && value != previousPositions.end())
        step.joints.push_back(JointValue{joint.name, value->second});
    }
    if (options.onStep)
      options.onStep(step, poses);
    info.steps.push_back(std::move(step));
  };

  dm.setLength(info.initialLength);
  NewtonWorkspace workspace;
  if (!solve(dm.model, q, workspace))
    return makeDiagnostic(mechanism.file, "cable", options.cable,
                          "the start pose does not close with the cable");
  record(info.initialLength, false);

  double length = info.initialLength;
  Eigen::VectorXd previousQ = q;
  double previousLength = length;
  const double step = (info.targetLength - info.initialLength) / options.steps;
  info.reason = "reached the target length without a passive cable going taut";
  // Solves at length L from the state (qa, La), predicting along the secant through (qb, Lb).
  auto solveAt = [&](double target, const Eigen::VectorXd& qa, double la, const Eigen::VectorXd& qb,
                     double lb, Eigen::VectorXd& out) {
    out = lb != la ? (qa + (qb - qa) * ((target - la) / (lb - la))).eval() : qa;
    dm.setLength(target);
    return solve(dm.model, out, workspace);
  };
  bool stopped = false;
  for (int k = 1; k <= options.steps && !stopped; ++k) {
    const double targetK = info.initialLength + step * k;
    Eigen::VectorXd next;
    double reached = targetK;
    bool ok = solveAt(targetK, q, length, previousQ, previousLength, next);
    for (int halving = 0; !ok && halving < kMaxHalvings; ++halving) {
      reached = 0.5 * (length + reached);
      ok = solveAt(reached, q, length, previousQ, previousLength, next);
    }
    if (!ok || reached != targetK) {
      if (ok) {
        // Keep the part of the step that worked, then stop: beyond it the cable cannot be shortened.
        q = next;
        length = reached;
        poses = recoverPoses(dm.model, q, poses);
      }
      char what[160];
      std::snprintf(what, sizeof(what), "no assembly beyond active length %.9g m (a dead point or a limit)",
                    length);
      info.reason = what;
      if (ok)
        record(length, true);
      break;
    }
    LinkPoses nextPoses = recoverPoses(dm.model, next, poses);
    const double gap = smallestGap(mechanism, nextPoses);
    if (gap >= 0.0) {
      previousQ = q;
      previousLength = length;
      q = next;
      length = targetK;
      poses = std::move(nextPoses);
      stopped = gap <= kCrossingGap;
      record(length, stopped || k == options.steps);
      continue;
    }
    // A passive cable went taut inside (length, targetK]: regula falsi (Illinois) on the smallest gap.
    double la = length, lb = targetK;
    double ga = smallestGap(mechanism, poses), gb = gap;
    Eigen::VectorXd qa = q, qb = next;
    int side = 0;
    for (int iteration = 0; iteration < 200; ++iteration) {
      double lm = (la * gb - lb * ga) / (gb - ga);
      if (!(lm > std::min(la, lb) && lm < std::max(la, lb)))
        lm = 0.5 * (la + lb);
      Eigen::VectorXd qm;
      if (!solveAt(lm, qa, la, qb, lb, qm))
        break;
      const LinkPoses posesM = recoverPoses(dm.model, qm, poses);
      const double gm = smallestGap(mechanism, posesM);
      if (gm >= 0.0) {
        la = lm, ga = gm, qa = qm;
        if (side == -1)
          gb *= 0.5;
        side = -1;
        if (gm <= kCrossingGap)
          break;
      } else {
        lb = lm, gb = gm, qb = qm;
        if (side == 1)
          ga *= 0.5;
        side = 1;
      }
      if (std::abs(lb - la) <= 1e-15 * std::max(1.0, std::abs(la)))
        break;
    }
    q = qa;
    length = la;
    poses = recoverPoses(dm.model, q, poses);
    stopped = true;
    record(length, true);
  }
  if (stopped) {
    for (const Joint& joint : mechanism.joints) {
      if (joint.kind == ConnectionKind::Cable && joint.cableType == CableType::Passive &&
          joint.length - cableDistance(joint, poses) <= tolerances::kCableTaut * joint.length)
        info.stoppedBy.push_back(joint.name);
    }
    info.reason =
        "stopped when passive cable " + (info.stoppedBy.empty() ? std::string("?") : info.stoppedBy[0]) +
        (info.stoppedBy.size() > 1 ? " and " + std::to_string(info.stoppedBy.size() - 1) + " more" : "") +
        " went taut";
  }
  info.finalLength = length;

  AnalysisOptions finalOptions = start;
  finalOptions.positions.clear();
  finalOptions.startPoses = poses;
  // The final report shows the active cable at the length it was shortened to.
  Mechanism deployed = mechanism;
  deployed.joints[cable].length = length;
  Result<MobilityAnalysis> analysis = analyzeMechanism(deployed, finalOptions);
  if (!isOk(analysis))
    return analysis;
  MobilityAnalysis result = valueOf(std::move(analysis));
  info.finalDof = result.report.dof;
  result.report.deployment = std::move(info);
  return result;
}

}  // namespace mobility_analysis
