#include "mobility_analysis/motion/DrivenAssembly.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/SVD>

#include "mobility_analysis/Tolerances.hpp"
#include "mobility_analysis/motion/LoopClosure.hpp"
#include "mobility_analysis/motion/TreeCoordinates.hpp"

namespace mobility_analysis {

namespace {

double maxAbs(const Eigen::VectorXd& v) {
  return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff();
}

/// One driven joint: where it starts, where it goes, in the unknowns' units (rad or Lc).
struct Driver {
  int joint = -1;
  int unknown = -1;
  double start = 0.0;   ///< [rad] or [m]
  double target = 0.0;  ///< [rad] or [m]
  double scale = 1.0;   ///< 1 for angles, Lc for slides: (target - start) / scale is in unknown units.
};

/// The relative motion of a one-freedom tree joint at @p value.
Eigen::Isometry3d motionAt(const Joint& joint, double value) {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  if (joint.type == JointType::Prismatic)
    motion.translation() = value * joint.axis;
  else
    motion.linear() = Eigen::AngleAxisd(value, joint.axis).toRotationMatrix();
  return motion;
}

std::string unitOf(const Joint& joint) {
  return joint.type == JointType::Prismatic ? "m" : "rad";
}

/// Singular values of the closure Jacobian, largest first. The events are only watched up to
/// DrivenAssemblySettings::eventSearchLimit (120) unknowns, where Jacobi SVD is fast enough; BDCSVD's
/// divide and conquer cost over a minute of compile time (three quarters of this file's) and nothing at run time.
Eigen::VectorXd singularValues(const Eigen::MatrixXd& dense) {
  return Eigen::JacobiSVD<Eigen::MatrixXd>(dense).singularValues();
}

/// The smallest of the leading `rank` singular values relative to the largest (0 when rank is 0).
double conditionIndicator(const Eigen::MatrixXd& dense, int rank) {
  if (rank <= 0 || dense.size() == 0)
    return 1.0;
  const Eigen::VectorXd sigma = singularValues(dense);
  if (sigma.size() < rank || sigma(0) <= 0.0)
    return 1.0;
  return sigma(rank - 1) / sigma(0);
}

int numericalRank(const Eigen::MatrixXd& dense) {
  if (dense.size() == 0)
    return 0;
  const Eigen::VectorXd sigma = singularValues(dense);
  int rank = 0;
  for (int i = 0; i < sigma.size(); ++i)
    rank += sigma(i) > 1e-8 * sigma(0) ? 1 : 0;
  return rank;
}

/// Watches a conditioning indicator along the motion and reports its dips: local minima below a tenth of its
/// value at the start (so a model that is poorly conditioned everywhere, a long mast, reports nothing).
struct DipWatch {
  double start = -1.0, previous = -1.0, beforePrevious = -1.0;
  bool dipped(double current) {
    if (start < 0.0)
      start = current;
    const bool dip = beforePrevious >= 0.0 && previous < kRelativeThreshold * start &&
                     previous < beforePrevious && previous < current;
    beforePrevious = previous;
    previous = current;
    return dip;
  }
  static constexpr double kRelativeThreshold = 0.1;
};

}  // namespace

Result<DrivenMotion> followDrivenPositions(const Mechanism& mechanism, const LinkPoses& start,
                                           const JointPositions& targets,
                                           const DrivenMotionSettings& settings) {
  const double lc =
      settings.lengthScale > 0.0 ? settings.lengthScale : computeCharacteristicLength(mechanism, start);
  const ClosureLayout layout = makeClosureLayout(mechanism, start, lc);
  DrivenMotion motion;

  // The drivers, and the columns of the unknowns left free.
  std::vector<Driver> drivers;
  for (const auto& [name, value] : targets) {
    const std::optional<int> j = mechanism.findJoint(name);
    const Joint* joint = j ? &mechanism.joints[*j] : nullptr;
    if (joint == nullptr || joint->kind != ConnectionKind::TreeJoint || layout.unknownCount[*j] != 1)
      return makeDiagnostic(
          mechanism.file, "positions", name,
          "is not a revolute, continuous or prismatic tree joint of '" + mechanism.name + "'");
    if (!std::isfinite(value))
      return makeDiagnostic(mechanism.file, "positions", name, "value is not finite");
    if (joint->type == JointType::Prismatic && std::abs(value) > tolerances::kMaxDrivenTravel * lc) {
      char what[240];
      std::snprintf(
          what, sizeof(what),
          "value %.6g m is outside the accepted range |x| <= %.0f Lc = %.6g m of this model (Lc, its "
          "characteristic length, is %.6g m)",
          value, tolerances::kMaxDrivenTravel, tolerances::kMaxDrivenTravel * lc, lc);
      return makeDiagnostic(mechanism.file, "positions", name, what);
    }
    Driver driver;
    driver.joint = *j;
    driver.unknown = layout.unknownOffset[*j];
    driver.target = value;
    driver.scale = joint->type == JointType::Prismatic ? lc : 1.0;
    drivers.push_back(driver);
  }
  int numAll = 0;
  const std::vector<int> all = allColumns(layout, numAll);
  std::vector<int> free(layout.numUnknowns, 0);
  for (const Driver& d : drivers)
    free[d.unknown] = -1;
  int numFree = 0;
  for (int k = 0; k < layout.numUnknowns; ++k)
    free[k] = free[k] < 0 ? -1 : numFree++;

  // Close the loops at the start first (all joints free: the start need not close with its written values).
  Result<ClosedConfiguration> closed =
      closeLoops(mechanism, layout, configurationFromPoses(mechanism, layout, start), all, numAll);
  if (!isOk(closed))
    return diagnosticOf(closed);
  TreeConfiguration configuration = valueOf(closed).configuration;
  motion.iterations = valueOf(closed).iterations;
  LinkPoses poses = valueOf(closed).poses;

  // Start values: each driven joint's representative nearest its target; the others near the reference.
  JointPositions values = computeJointPositions(mechanism, poses, settings.reference);
  const JointPositions nearTargets = computeJointPositions(mechanism, poses, targets);
  double span = 0.0;  // largest driven change [rad or Lc]
  for (Driver& d : drivers) {
    d.start = nearTargets.at(mechanism.joints[d.joint].name);
    span = std::max(span, std::abs(d.target - d.start) / d.scale);
  }
  Eigen::VectorXd rate(numAll);  // d(unknowns)/ds of the drivers, unknown units
  rate.setZero();
  for (const Driver& d : drivers)
    rate(d.unknown) = (d.target - d.start) / d.scale;

  const bool watchEvents =
      settings.eventSearchLimit > 0 && numAll <= settings.eventSearchLimit && !drivers.empty();
  int rankAll = 0, rankFree = 0;
  DipWatch allWatch, freeWatch;
  Eigen::VectorXd residual;
  Eigen::SparseMatrix<double> jacobian;
  auto drivenText = [&](double s) {
    std::string text;
    for (size_t i = 0; i < drivers.size(); ++i) {
      const Driver& d = drivers[i];
      char item[96];
      std::snprintf(item, sizeof(item), "%s%s = %.6g %s", i ? ", " : "",
                    mechanism.joints[d.joint].name.c_str(), d.start + s * (d.target - d.start),
                    unitOf(mechanism.joints[d.joint]).c_str());
      text += item;
    }
    return text;
  };
  auto watch = [&](double s, double previousS, bool first) {
    if (!watchEvents)
      return;
    evaluateClosure(mechanism, layout, poses, all, numAll, residual, &jacobian);
    const Eigen::MatrixXd dense = Eigen::MatrixXd(jacobian);
    Eigen::MatrixXd reduced(dense.rows(), numFree);
    for (int k = 0; k < numAll; ++k)
      if (free[k] >= 0)
        reduced.col(free[k]) = dense.col(k);
    if (first) {
      rankAll = numericalRank(dense);
      rankFree = numericalRank(reduced);
    }
    const bool allDip = allWatch.dipped(conditionIndicator(dense, rankAll));
    const bool freeDip = freeWatch.dipped(conditionIndicator(reduced, rankFree));
    if (allDip)
      motion.events.push_back("branch point (the constraint Jacobian nearly loses rank) near " +
                              drivenText(previousS));
    else if (freeDip)
      motion.events.push_back("dead point of the driven joints (they nearly stop moving the others) near " +
                              drivenText(previousS));
    (void)s;
  };

  watch(0.0, 0.0, true);
  const double maxStep = settings.maxStep;
  double s = 0.0, previousS = 0.0;
  double h = span > 0.0 ? std::min(1.0, maxStep / span) : 1.0;
  const double hMin = span > 0.0 ? 1e-10 / span : 1.0;
  Eigen::VectorXd tangent, change;
  // Steps creep near a singular point (the tangent grows without bound); past this many tries the motion is
  // reported as stopped there.
  constexpr int kMaxAttempts = 100000;
  int attempts = 0;
  while (s < 1.0 && span > 0.0) {
    h = std::min(h, 1.0 - s);
    if (1.0 - s - h < 0.25 * h)
      h = 1.0 - s;  // no sliver of a last step (it could fall below hMin)
    // Predictor: the least-change motion of the free joints that keeps the loops closed to first order.
    evaluateClosure(mechanism, layout, poses, all, numAll, residual, &jacobian);
    const Eigen::VectorXd drive = jacobian * rate;
    Eigen::SparseMatrix<double> freeJacobian;
    evaluateClosure(mechanism, layout, poses, free, numFree, residual, &freeJacobian);
    tangent = Eigen::VectorXd::Zero(numFree);
    if (numFree > 0 && !solveDampedLeastSquares(freeJacobian, drive, 1e-14, tangent))
      tangent.setZero();
    const double freeSpeed = maxAbs(tangent);
    if (freeSpeed * h > maxStep)
      h = std::max(maxStep / freeSpeed, hMin * 0.5);
    bool accepted = false;
    while (!accepted) {
      if ((h < hMin && h < 1.0 - s) || ++attempts > kMaxAttempts) {
        // The target lies beyond a dead point of this assembly mode (or the drivers contradict each other).
        const Driver* worst = &drivers.front();
        for (const Driver& d : drivers)
          if (std::abs(d.target - d.start) / d.scale > std::abs(worst->target - worst->start) / worst->scale)
            worst = &d;
        const Joint& joint = mechanism.joints[worst->joint];
        char what[240];
        std::snprintf(
            what, sizeof(what),
            "%.6g %s cannot be reached in this assembly mode: the motion stops at %.6g %s (a dead point, "
            "or the driven joints contradict each other)",
            worst->target, unitOf(joint).c_str(), worst->start + s * (worst->target - worst->start),
            unitOf(joint).c_str());
        return makeDiagnostic(mechanism.file, toString(joint.kind), joint.name, what);
      }
      TreeConfiguration trial = configuration;
      applyIncrement(mechanism, layout, free, h * tangent, trial);
      for (const Driver& d : drivers)
        trial.motions[d.joint] =
            motionAt(mechanism.joints[d.joint], d.start + (s + h) * (d.target - d.start));
      change = Eigen::VectorXd::Zero(numFree);
      const ClosureSolve corrector = solveClosure(mechanism, layout, free, numFree, trial, 12, &change);
      motion.iterations += corrector.iterations;
      // The correction must stay small beside the step, or the corrector has jumped to another mode.
      const double stepSize = h * std::max(freeSpeed, span);
      if (corrector.converged && maxAbs(change) <= 0.25 * stepSize + 1e-12) {
        accepted = true;
        configuration = std::move(trial);
        poses = posesOf(mechanism, layout, configuration);
        previousS = s;
        s = std::min(1.0, s + h);
        ++motion.steps;
        values = computeJointPositions(mechanism, poses, values);  // unwrap continuously
        if (corrector.iterations <= 3)
          h *= 1.5;
        watch(s, previousS, false);
      } else {
        h *= 0.5;
      }
    }
  }
  // Driven joints end exactly where asked (their motions were set from the values, not solved for).
  for (const Driver& d : drivers) {
    configuration.motions[d.joint] = motionAt(mechanism.joints[d.joint], d.target);
  }
  motion.poses = posesOf(mechanism, layout, configuration);
  evaluateClosure(mechanism, layout, motion.poses, all, numAll, residual, nullptr);
  motion.residual = maxAbs(residual);
  motion.positions = computeJointPositions(mechanism, motion.poses, values);
  for (const Driver& d : drivers)
    motion.positions[mechanism.joints[d.joint].name] = d.target;
  return motion;
}

}  // namespace mobility_analysis
