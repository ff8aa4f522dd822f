#include "mobility_analysis/MobilityAnalysis.hpp"

#include <algorithm>
#include <iterator>
#include <set>

#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/EliminationOrder.hpp"
#include "mobility_analysis/Kinematics.hpp"
#include "mobility_analysis/RedundantLinks.hpp"
#include "mobility_analysis/SelfStressBasis.hpp"
#include "mobility_analysis/Tolerances.hpp"
#include "mobility_analysis/analysis/CompositeBalls.hpp"
#include "mobility_analysis/analysis/FiniteMobility.hpp"
#include "mobility_analysis/analysis/PassiveFreedoms.hpp"
#include "mobility_analysis/analysis/SelfStressReport.hpp"

#include "SideTask.hpp"

namespace mobility_analysis {

int computeGrublerKutzbach(const Mechanism& mechanism, const CoordinateModel& model) {
  // lambda (N - J - 1) + sum F_i = lambda (N - 1) - sum (lambda - F_i), over the connections that constrain.
  int count = model.lambda * (static_cast<int>(mechanism.links.size()) - 1);
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    if (model.jointActive[j])
      count -= model.lambda - model.jointFreedom[j];
  }
  return count;
}

namespace {

Result<MobilityAnalysis> analyzeAssembled(const Mechanism& mechanism, const AnalysisOptions& options,
                                          const std::vector<bool>& lockedCables);

/// Whether @p options start from the written pose with nothing driven (assembleMechanism's overload without
/// a start, which keeps that pose and its exact joint values where the loops close there).
bool fromWrittenPose(const AnalysisOptions& options) {
  return !options.startPoses && options.positions.empty();
}

}  // namespace

Result<MobilityAnalysis> analyzeMechanism(const Mechanism& mechanism, const AnalysisOptions& options) {
  const bool hasActive =
      std::any_of(mechanism.joints.begin(), mechanism.joints.end(), [](const Joint& joint) {
        return joint.kind == ConnectionKind::Cable && joint.cableType == CableType::Active;
      });
  if (!options.lockActiveCables || !hasActive)
    return analyzeAssembled(mechanism, options, {});
  // Lock at the pose the free mechanism assembles to, then analyse the locked copy from there.
  Result<AssembledMechanism> free =
      fromWrittenPose(options)
          ? assembleMechanism(mechanism, options.mode)
          : assembleMechanism(
                mechanism,
                options.startPoses ? *options.startPoses : computeTreePoses(mechanism, options.positions),
                options.mode);
  if (!isOk(free))
    return diagnosticOf(free);
  std::vector<bool> locked;
  const Mechanism lockedMechanism = lockActiveCables(mechanism, valueOf(free).poses, locked);
  AnalysisOptions lockedOptions = options;
  // From the free pose; where that is the written pose, closed there without moving, the locked copy (the
  // same tree) starts from its own written pose, the same poses, and keeps its exact joint values.
  if (!fromWrittenPose(options) || valueOf(free).iterations > 0)
    lockedOptions.startPoses = valueOf(free).poses;
  return analyzeAssembled(lockedMechanism, lockedOptions, locked);
}

namespace {

/**
 * Idle groups' motions (Tsai): a rod spinning between two balls, a link sliding between parallel slides.
 * Where balls are written as three revolutes (Gepetto's way, analysis/CompositeBalls.hpp) the search runs on
 * the mechanism with those balls as spherical joints, at the same pose: the two links inside a ball turn with
 * the rod it carries, so in the mechanism as written no group moves while the rest stays put.
 */
PassiveFreedoms findIdleMotions(const Mechanism& mechanism, const AssembledMechanism& assembled,
                                const SparseJacobian& J) {
  const CoordinateModel& model = assembled.model;
  if (model.mode == AnalysisMode::Spatial) {
    const std::vector<CompositeBall> balls =
        findCompositeBalls(mechanism, assembled.poses, model.characteristicLength);
    if (!balls.empty()) {
      const MechanismWithBalls merged = mergeCompositeBalls(mechanism, assembled.poses, balls);
      const Result<CoordinateModel> built = buildCoordinateModel(
          merged.mechanism, merged.poses, AnalysisMode::Spatial, model.characteristicLength);
      if (isOk(built)) {
        const CoordinateModel& withBalls = valueOf(built);
        const Eigen::VectorXd q = computeCoordinates(withBalls, merged.poses);
        return findPassiveFreedoms(merged.mechanism, withBalls, q, computeConstraintJacobian(withBalls, q));
      }
    }
  }
  return findPassiveFreedoms(mechanism, model, assembled.q, J);
}

Result<MobilityAnalysis> analyzeAssembled(const Mechanism& mechanism, const AnalysisOptions& options,
                                          const std::vector<bool>& lockedCables) {
  auto progress = [&](const std::string& phase, double fraction) {
    if (options.progress)
      options.progress(phase, fraction);
  };
  progress("assembly", 0.0);
  // Driven positions are held exactly and reached by continuation from the start (the previous state, else
  // the written pose), so the mechanism stays in the start's assembly mode (motion/DrivenAssembly.hpp).
  Result<AssembledMechanism> assembled =
      fromWrittenPose(options)
          ? assembleMechanism(mechanism, options.mode, options.sideThreads)
          : assembleMechanism(mechanism,
                              options.startPoses ? *options.startPoses : computeTreePoses(mechanism, {}),
                              options.mode, options.positions, options.sideThreads);
  if (!isOk(assembled))
    return diagnosticOf(assembled);
  MobilityAnalysis analysis;
  analysis.assembled = valueOf(std::move(assembled));
  const CoordinateModel& model = analysis.assembled.model;

  progress("jacobian", 0.2);
  const bool sideTasks = options.sideThreads && model.numConstraints() >= core_detail::kSecondThreadEquations;
  const SparseJacobian J = computeConstraintJacobian(model, analysis.assembled.q, sideTasks);
  const double tolerance = options.rankTolerance > 0.0 ? options.rankTolerance : tolerances::kRank;
  // The passive-freedom search reads the Jacobian and the pose only, and the self-stress report the basis
  // besides: on a large model each runs beside the phases that do not feed it (on a braced lattice the report
  // and the redundant links take about as long; on a chain the search and the self-stresses).
  core_detail::SideTask passiveTask(sideTasks,
                                    [&] { return findIdleMotions(mechanism, analysis.assembled, J); });
  // One elimination in sweep order finds a local basis of the self-stresses; the ordered answer, the loops
  // and the redundant links are all read off it (SelfStressBasis.hpp, RedundantLinks.hpp).
  progress("self-stresses", 0.3);
  SelfStressBasis basis = sweepSelfStressBasis(
      mechanism, model, J, tolerance,
      [&](double fraction) { progress("self-stresses", 0.3 + 0.5 * fraction); }, 0, sideTasks);
  // The report reads the stresses and counts, which reduceToContractOrder leaves alone (it writes the
  // basis' echelon members only): on a braced lattice the report then runs beside the contract-order
  // reduction as well.
  core_detail::SideTask stressReportTask(
      sideTasks, [&] { return computeSelfStressInfo(mechanism, model, analysis.assembled.q, J, basis); });
  reduceToContractOrder(mechanism, model, J, tolerance, basis);
  progress("ordered redundancy", 0.8);
  // When the basis is numerically ambiguous, or its reduction to contract order fills past its budget, the
  // lecture's test itself in contract order decides (strict partial pivoting, near-tolerance rows re-checked
  // by their orthogonal distance: RedundancyAnalysis.hpp). Why the budget: on a strip of the continuous-bar
  // grid (2 x 5 000 cells) the stresses share last equations, their reduction passes its budget in
  // reduceToContractOrder, and no patch of links finds a contract-order echelon (the long bars put every pin
  // in one ball); the reduction made again without a limit took 0.9 s and 240 MB of fill, where J's own
  // elimination stores 2.3 times J's entries (the whole report 1.3 s -> 0.43 s; the same redundant
  // equations, the margins of the other method's decisions).
  std::optional<OrderedRank> fromStresses = computeOrderedRankFromStresses(basis, tolerance, true);
  const bool decidedByJ = !fromStresses.has_value();
  const OrderedRank ranks = fromStresses ? std::move(*fromStresses) : computeOrderedRank(J, tolerance, false);

  MobilityReport& report = analysis.report;
  report.robot = mechanism.name;
  report.file = mechanism.file;
  for (const Diagnostic& warning : mechanism.warnings)
    report.warnings.push_back(warning.toString());
  report.mode = toString(model.mode);
  report.lambda = model.lambda;
  report.dof = ranks.dof();
  report.grublerKutzbachDof = computeGrublerKutzbach(mechanism, model);
  report.numCoordinates = model.numCoordinates();
  report.numConstraints = model.numConstraints();
  report.rank = ranks.rank;
  // How it really moves: the second-order test over the self-stresses and a step-and-project check.
  progress("finite mobility", 0.85);
  const FiniteMobility finite =
      analyzeFiniteMobility(model, analysis.assembled.q, J, basis, ranks, tolerance);
  report.finiteDof = finite.finiteDof;
  report.singular = finite.singular;
  report.nullityTrace = ranks.nullityTrace;
  report.characteristicLength = model.characteristicLength;
  report.closureResidualBefore = analysis.assembled.initialResidual;
  report.closureResidualAfter = analysis.assembled.finalResidual;
  const JointPositions& reached = analysis.assembled.positions;
  // Joints are mostly written in the order of their names (the map's order): the entry after the last one
  // found is tried first, so the walk costs one comparison per joint instead of a search of the map.
  auto next = reached.begin();
  report.positions.reserve(reached.size());
  for (const Joint& joint : mechanism.joints) {
    if (joint.kind != ConnectionKind::TreeJoint)
      continue;
    const auto value = next != reached.end() && next->first == joint.name ? next : reached.find(joint.name);
    if (value == reached.end())
      continue;
    report.positions.push_back(JointValue{joint.name, value->second});
    next = std::next(value);
  }
  report.assembly.residual = analysis.assembled.finalResidual;
  report.assembly.steps = analysis.assembled.steps;
  report.assembly.iterations = analysis.assembled.iterations;
  report.assembly.events = analysis.assembled.events;
  report.rankMargin.tolerance = tolerance;
  report.rankMargin.smallestKeptPivot = ranks.smallestKeptPivot;
  report.rankMargin.largestDroppedResidual = ranks.largestDroppedResidual;
  // The margins are those of the decisions the answer came from. When the basis was ambiguous the answer is
  // the contract-order elimination's, whose near-tolerance decisions are re-checked by their orthogonal
  // distance (computeOrderedRank); it is near when one could not be, or when the sweep found another rank.
  report.rankMargin.nearTolerance =
      ranks.uncheckedNearDecisions > 0 || (decidedByJ && basis.rank != ranks.rank) ||
      (ranks.smallestKeptPivot > 0.0 &&
       ranks.smallestKeptPivot < tolerance * tolerances::kNearDecisionFactor) ||
      (ranks.largestDroppedResidual > tolerance / tolerances::kNearDecisionFactor);

  // The loops and the redundant links read the structural stresses only: beside the redundant equations.
  struct LinksAndLoops {
    std::vector<bool> linkInLoop, jointInLoop, linkRedundant;
  };
  core_detail::SideTask linksTask(sideTasks, [&] {
    LinksAndLoops found;
    findOverConstrainedLoops(mechanism, model, finite.structuralStresses, found.linkInLoop,
                             found.jointInLoop);
    found.linkRedundant = findRedundantLinks(mechanism, model, finite.structuralStresses, tolerance);
    return found;
  });
  progress("redundant equations", 0.88);
  auto elementName = [&](const ConstraintEquation& eq) {
    return eq.source == EquationSource::Joint ? mechanism.joints[eq.element].name
                                              : mechanism.links[eq.element].name;
  };
  std::vector<int> jointRedundant(mechanism.joints.size(), 0);
  std::set<std::string> redundantBoundaries;
  for (int r = 0; r < model.numConstraints(); ++r) {
    if (!ranks.redundant[r])
      continue;
    const ConstraintEquation& eq = model.equations[r];
    // A coupling's equation is a joint equation in the phases, but the report names its own source kind.
    const bool coupling =
        eq.source == EquationSource::Joint && mechanism.joints[eq.element].kind == ConnectionKind::Coupling;
    report.redundantConstraints.push_back(RedundantConstraint{r, coupling ? "coupling" : toString(eq.source),
                                                              elementName(eq), toString(eq.kind),
                                                              describeEquation(model, r)});
    // Only the design makes joints and ground constraints redundant, not a pose.
    if (finite.configurationCause[r]) {
      report.redundantConstraints.back().cause = "configuration";
      continue;
    }
    if (eq.source == EquationSource::Joint)
      ++jointRedundant[eq.element];
    if (eq.source == EquationSource::Boundary)
      redundantBoundaries.insert(elementName(eq));
  }
  report.numRedundant = static_cast<int>(report.redundantConstraints.size());
  report.redundantBoundaries.assign(redundantBoundaries.begin(), redundantBoundaries.end());
  // Each redundant joint's number of equations, counted only when there is one: the count reads every
  // equation (a chain of 10^5 links: 5 10^5 of them, 48 MB read in 8 ms).
  std::vector<int> jointEquations(mechanism.joints.size(), 0);
  if (std::any_of(jointRedundant.begin(), jointRedundant.end(), [](int n) { return n > 0; })) {
    for (const ConstraintEquation& eq : model.equations) {
      if (eq.source == EquationSource::Joint)
        ++jointEquations[eq.element];
    }
  }
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    if (jointRedundant[j] > 0) {
      report.redundantJoints.push_back(
          RedundantJoint{mechanism.joints[j].name, jointRedundant[j], jointEquations[j]});
    }
  }

  progress("redundant links", 0.9);
  const auto [linkInLoop, jointInLoop, linkRedundant] = linksTask.get();
  report.redundantLinksComputed = true;
  for (size_t l = 0; l < mechanism.links.size(); ++l) {
    if (linkRedundant[l])
      report.redundantLinks.push_back(mechanism.links[l].name);
  }

  report.links.reserve(mechanism.links.size());
  report.joints.reserve(mechanism.joints.size());
  for (size_t l = 0; l < mechanism.links.size(); ++l) {
    const ElementClass c = linkRedundant[l] ? ElementClass::Redundant
                           : linkInLoop[l]  ? ElementClass::OverConstrainedLoop
                                            : ElementClass::Neutral;
    report.links.push_back(ElementStatus{mechanism.links[l].name, "link", "link", c});
  }
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const Joint& joint = mechanism.joints[j];
    const ElementClass c = jointRedundant[j] > 0 ? ElementClass::Redundant
                           : jointInLoop[j]      ? ElementClass::OverConstrainedLoop
                                                 : ElementClass::Neutral;
    report.joints.push_back(ElementStatus{joint.name, toString(joint.kind),
                                          joint.kind == ConnectionKind::DistanceConstraint ? "distance"
                                          : joint.kind == ConnectionKind::Cable            ? "cable"
                                                                                : toString(joint.type),
                                          c});
    if (joint.kind == ConnectionKind::Cable) {
      const LinkPoses& poses = analysis.assembled.poses;
      const double distance = ((poses[joint.link1] * joint.frame1.translation()) -
                               (poses[joint.link2] * joint.frame2.translation()))
                                  .norm();
      const bool locked = j < lockedCables.size() && lockedCables[j];
      const std::string state = locked                                 ? "locked"
                                : joint.cableType == CableType::Active ? "driving"
                                : model.jointActive[j]                 ? "taut"
                                                                       : "slack";
      report.cables.push_back(
          CableState{joint.name, locked || joint.cableType == CableType::Active ? "active" : "passive", state,
                     joint.length, distance});
    }
  }
  // The passive-freedom search is taken last: on a chain it takes longer than the sweep it runs beside, and
  // the redundant equations, loops and the report's records need nothing from it.
  progress("passive freedoms", 0.93);
  const PassiveFreedoms passive = passiveTask.get();
  report.passiveDof = std::min(passive.dof, report.finiteDof);
  report.passiveMotions = passive.motions;
  report.outputDof = report.finiteDof - report.passiveDof;
  progress("self-stress report", 0.95);
  report.selfStress = stressReportTask.get();
  progress("done", 1.0);
  return analysis;
}

}  // namespace

}  // namespace mobility_analysis
