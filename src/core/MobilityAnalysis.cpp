#include "mobility_analysis/MobilityAnalysis.hpp"

#include <set>

#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/Kinematics.hpp"
#include "mobility_analysis/Tolerances.hpp"
#include "mobility_analysis/TreeMotion.hpp"

namespace mobility_analysis {

namespace {

/// Work above which the redundant-link search (one elimination per candidate link) is skipped [nonzeros].
constexpr double kRedundantLinkWorkLimit = 5e8;

/// The Jacobian without @p link: its coordinates, its rigid equations and the equations of its connections.
SparseJacobian removeLink(const CoordinateModel& model, const Mechanism& mechanism, const SparseJacobian& J, int link) {
  std::vector<int> columnMap(model.numCoordinates(), 0);
  for (int e : model.bodyElements[link]) {
    for (int i = 0; i < model.dim; ++i) columnMap[model.elements[e].offset + i] = -1;
  }
  int columns = 0;
  for (int& c : columnMap) c = c < 0 ? -1 : columns++;
  std::vector<Eigen::Triplet<double>> triplets;
  int rows = 0;
  for (int r = 0; r < J.rows(); ++r) {
    const ConstraintEquation& eq = model.equations[r];
    const bool removed = (eq.source == EquationSource::Link && eq.element == link) ||
                         (eq.source == EquationSource::Joint && (mechanism.joints[eq.element].link1 == link ||
                                                                 mechanism.joints[eq.element].link2 == link));
    if (removed) continue;
    for (SparseJacobian::InnerIterator it(J, r); it; ++it) {
      if (columnMap[it.col()] >= 0) triplets.emplace_back(rows, columnMap[it.col()], it.value());
    }
    ++rows;
  }
  SparseJacobian reduced(rows, columns);
  reduced.setFromTriplets(triplets.begin(), triplets.end());
  return reduced;
}

}  // namespace

int computeGrublerKutzbach(const Mechanism& mechanism, const CoordinateModel& model) {
  // lambda (N - J - 1) + sum F_i = lambda (N - 1) - sum (lambda - F_i), over the connections that constrain.
  int count = model.lambda * (static_cast<int>(mechanism.links.size()) - 1);
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    if (model.jointActive[j]) count -= model.lambda - model.jointFreedom[j];
  }
  return count;
}

Result<MobilityAnalysis> analyzeMechanism(const Mechanism& mechanism, const AnalysisOptions& options) {
  auto progress = [&](const std::string& phase, double fraction) {
    if (options.progress) options.progress(phase, fraction);
  };
  progress("assembly", 0.0);
  Result<AssembledMechanism> assembled =
      assembleMechanism(mechanism, computeTreePoses(mechanism, options.positions), options.mode);
  if (!isOk(assembled)) return diagnosticOf(assembled);
  MobilityAnalysis analysis;
  analysis.assembled = valueOf(std::move(assembled));
  const CoordinateModel& model = analysis.assembled.model;

  progress("jacobian", 0.2);
  const SparseJacobian J = computeConstraintJacobian(model, analysis.assembled.q);
  const double tolerance = options.rankTolerance > 0.0 ? options.rankTolerance : tolerances::kRank;
  progress("ordered rank", 0.3);
  // The tree factored out keeps the elimination as local as the loops; the direct elimination is the fallback.
  std::optional<OrderedRank> overTree =
      computeOrderedRankOverTree(mechanism, model, analysis.assembled.q, J, tolerance);
  const OrderedRank ranks = overTree ? std::move(*overTree) : computeOrderedRank(J, tolerance, true);

  MobilityReport& report = analysis.report;
  report.robot = mechanism.name;
  report.file = mechanism.file;
  report.mode = toString(model.mode);
  report.lambda = model.lambda;
  report.dof = ranks.dof();
  report.grublerKutzbachDof = computeGrublerKutzbach(mechanism, model);
  report.numCoordinates = model.numCoordinates();
  report.numConstraints = model.numConstraints();
  report.rank = ranks.rank;
  report.nullityTrace = ranks.nullityTrace;
  report.characteristicLength = model.characteristicLength;
  report.closureResidualBefore = analysis.assembled.initialResidual;
  report.closureResidualAfter = analysis.assembled.finalResidual;
  report.rankMargin.tolerance = tolerance;
  report.rankMargin.smallestKeptPivot = ranks.smallestKeptPivot;
  report.rankMargin.largestDroppedResidual = ranks.largestDroppedResidual;
  report.rankMargin.nearTolerance =
      (ranks.smallestKeptPivot > 0.0 && ranks.smallestKeptPivot < tolerance * tolerances::kNearDecisionFactor) ||
      (ranks.largestDroppedResidual > tolerance / tolerances::kNearDecisionFactor);

  auto elementName = [&](const ConstraintEquation& eq) {
    return eq.source == EquationSource::Joint ? mechanism.joints[eq.element].name : mechanism.links[eq.element].name;
  };
  std::vector<int> jointEquations(mechanism.joints.size(), 0), jointRedundant(mechanism.joints.size(), 0);
  std::set<std::string> redundantBoundaries;
  for (int r = 0; r < model.numConstraints(); ++r) {
    const ConstraintEquation& eq = model.equations[r];
    if (eq.source == EquationSource::Joint) ++jointEquations[eq.element];
    if (!ranks.redundant[r]) continue;
    report.redundantConstraints.push_back(
        RedundantConstraint{r, toString(eq.source), elementName(eq), toString(eq.kind), eq.text});
    if (eq.source == EquationSource::Joint) ++jointRedundant[eq.element];
    if (eq.source == EquationSource::Boundary) redundantBoundaries.insert(elementName(eq));
  }
  report.numRedundant = static_cast<int>(report.redundantConstraints.size());
  report.redundantBoundaries.assign(redundantBoundaries.begin(), redundantBoundaries.end());
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    if (jointRedundant[j] > 0) {
      report.redundantJoints.push_back(RedundantJoint{mechanism.joints[j].name, jointRedundant[j], jointEquations[j]});
    }
  }

  // Elements of an over-constrained loop: the sources of every equation in some redundant equation's dependency.
  std::vector<bool> linkInLoop(mechanism.links.size(), false), jointInLoop(mechanism.joints.size(), false);
  for (const std::vector<int>& dependency : ranks.dependencies) {
    for (int r : dependency) {
      const ConstraintEquation& eq = model.equations[r];
      if (eq.source == EquationSource::Joint) {
        jointInLoop[eq.element] = true;
        linkInLoop[mechanism.joints[eq.element].link1] = true;
        linkInLoop[mechanism.joints[eq.element].link2] = true;
      } else {
        linkInLoop[eq.element] = true;
      }
    }
  }

  // Redundant links (DESIGN.md §3): removing the link and its connections keeps the DOF and lowers the number of
  // redundant equations. Only links in an over-constrained loop can lower it (a self-stress elsewhere survives).
  std::vector<bool> linkRedundant(mechanism.links.size(), false);
  std::vector<int> candidates;
  for (size_t l = 0; l < mechanism.links.size(); ++l) {
    if (static_cast<int>(l) != mechanism.rootLink && linkInLoop[l]) candidates.push_back(static_cast<int>(l));
  }
  const double work = static_cast<double>(candidates.size()) * static_cast<double>(J.nonZeros());
  report.redundantLinksComputed =
      report.numRedundant == 0 ||
      (model.numConstraints() <= options.redundantLinkSearchLimit && work <= kRedundantLinkWorkLimit);
  if (report.numRedundant > 0 && report.redundantLinksComputed) {
    for (size_t i = 0; i < candidates.size(); ++i) {
      progress("redundant links", 0.5 + 0.5 * static_cast<double>(i) / static_cast<double>(candidates.size()));
      const SparseJacobian reduced = removeLink(model, mechanism, J, candidates[i]);
      const OrderedRank without = computeOrderedRank(reduced, tolerance, false);
      const int redundantWithout = static_cast<int>(reduced.rows()) - without.rank;
      if (without.dof() == report.dof && redundantWithout < report.numRedundant) {
        linkRedundant[candidates[i]] = true;
        report.redundantLinks.push_back(mechanism.links[candidates[i]].name);
      }
    }
  }

  for (size_t l = 0; l < mechanism.links.size(); ++l) {
    const ElementClass c = linkRedundant[l]  ? ElementClass::Redundant
                           : linkInLoop[l]   ? ElementClass::OverConstrainedLoop
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
      const double distance =
          ((poses[joint.link1] * joint.frame1.translation()) - (poses[joint.link2] * joint.frame2.translation())).norm();
      const std::string state =
          joint.cableType == CableType::Active ? "driving" : (model.jointActive[j] ? "taut" : "slack");
      report.cables.push_back(CableState{joint.name, joint.cableType == CableType::Active ? "active" : "passive", state,
                                         joint.length, distance});
    }
  }
  progress("done", 1.0);
  return analysis;
}

}  // namespace mobility_analysis
