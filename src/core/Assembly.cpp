#include "mobility_analysis/Assembly.hpp"

#include <cmath>
#include <cstdio>
#include <optional>

#include "SideTask.hpp"
#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/Tolerances.hpp"
#include "mobility_analysis/motion/DrivenAssembly.hpp"
#include "mobility_analysis/motion/LoopClosure.hpp"

namespace mobility_analysis {

namespace {

/// About the fewest equations a model has a link (a planar chain of pins: two); the side thread's threshold
/// (SideTask.hpp, in equations) is counted against the links with it.
constexpr size_t kEquationsPerLink = 2;

double maxAbs(const Eigen::VectorXd& v) {
  return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff();
}

/**
 * assembleMechanism from @p startPoses; @p writtenPoses, when given, is @p startPoses itself and says they
 * are the written pose's (computeTreePoses with no values), which this call may keep (move from).
 */
Result<AssembledMechanism> assembleFrom(const Mechanism& mechanism, const LinkPoses& startPoses,
                                        LinkPoses* writtenPoses, AnalysisMode mode,
                                        const JointPositions& driven, bool sideThread) {
  const double lc = computeCharacteristicLength(mechanism, startPoses);
  AssembledMechanism assembled;
  const ClosureLayout layout = makeClosureLayout(mechanism, startPoses, lc);
  const bool nothingToClose = layout.numResiduals == 0;
  // Without driven joints their values are read off the closed poses (a fifth of the model's building on a
  // 10^5-link chain), which nothing writes once the model is being built: on a large model, beside it.
  bool asWritten = false;  // nothing moved from the written pose: its joint values are the written ones
  const bool positionsBeside =
      driven.empty() && sideThread &&
      static_cast<long>(kEquationsPerLink * mechanism.links.size()) >= core_detail::kSecondThreadEquations;
  if (driven.empty()) {
    // closeLoops begins with the start's poses (reposeTree is posesOf(configurationFromPoses)) and their
    // residual, and stops there when the loops close already: with no residual rows (a tree with no
    // loop-closing connection, coupling or multi-freedom tree joint of its own equations) or at a written
    // pose that closes (a lattice of bars). Those poses are taken directly then, and no configuration is
    // made. The written pose's are the tree's own already (computeTreePoses): re-posed they would come back
    // the same but for rounding, and the joint values read off them would be rounding too (a PUMA 560's
    // joint2 at -5.6e-17 rad). Where it closes, nothing moved: its poses are kept, its values are the written
    // ones, exactly (writtenJointPositions), and a 10^5-link chain skips both passes.
    // (startPoses is *writtenPoses when that is given: moved from here, it is read as `start` only.)
    LinkPoses poses =
        writtenPoses != nullptr ? std::move(*writtenPoses) : reposeTree(mechanism, layout, startPoses);
    const LinkPoses& start = writtenPoses != nullptr ? poses : startPoses;
    bool closed = true;
    if (!nothingToClose) {
      int numColumns = 0;
      const std::vector<int> columns = allColumns(layout, numColumns);
      Eigen::VectorXd residual;
      evaluateClosure(mechanism, layout, poses, columns, numColumns, residual, nullptr);
      assembled.initialResidual = maxAbs(residual) * lc;
      closed = maxAbs(residual) <= layout.target;
      if (!closed) {
        Result<ClosedConfiguration> reached = closeLoops(
            mechanism, layout, configurationFromPoses(mechanism, layout, start), columns, numColumns);
        if (!isOk(reached))
          return diagnosticOf(reached);
        ClosedConfiguration& loops = std::get<ClosedConfiguration>(reached);
        poses = std::move(loops.poses);
        assembled.iterations = loops.iterations;
        assembled.restarts = loops.restarts;
      }
    }
    assembled.poses = std::move(poses);
    asWritten = writtenPoses != nullptr && closed;
    if (!positionsBeside)
      assembled.positions =
          asWritten ? writtenJointPositions(mechanism) : computeJointPositions(mechanism, assembled.poses);
  } else {
    const TreeConfiguration start = configurationFromPoses(mechanism, layout, startPoses);
    int numColumns = 0;
    const std::vector<int> columns = allColumns(layout, numColumns);
    if (!nothingToClose) {
      Eigen::VectorXd residual;
      evaluateClosure(mechanism, layout, posesOf(mechanism, layout, start), columns, numColumns, residual,
                      nullptr);
      assembled.initialResidual = maxAbs(residual) * lc;
    }
    DrivenMotionSettings settings;
    settings.lengthScale = lc;
    Result<DrivenMotion> moved = followDrivenPositions(mechanism, startPoses, driven, settings);
    if (!isOk(moved))
      return diagnosticOf(moved);
    DrivenMotion& motion = std::get<DrivenMotion>(moved);
    assembled.poses = std::move(motion.poses);
    assembled.iterations = motion.iterations;
    assembled.steps = motion.steps;
    assembled.positions = std::move(motion.positions);
    assembled.events = std::move(motion.events);
  }

  std::optional<core_detail::SideTask<JointPositions>> positions;
  if (positionsBeside)
    positions.emplace(true, [&] {
      return asWritten ? writtenJointPositions(mechanism) : computeJointPositions(mechanism, assembled.poses);
    });
  Result<CoordinateModel> model = buildCoordinateModel(mechanism, assembled.poses, mode, lc);
  if (!isOk(model))
    return diagnosticOf(model);
  if (positions)
    assembled.positions = positions->get();
  assembled.model = valueOf(std::move(model));
  // q0 is computeCoordinates at the poses the model was built at, value for value (the same products): a
  // copy, not a second pass over every element and its body's pose.
  assembled.q = assembled.model.q0;
  Eigen::VectorXd phi;
  computeConstraintResidual(assembled.model, assembled.q, phi);
  assembled.finalResidual = maxAbs(phi) * lc;
  if (maxAbs(phi) > tolerances::kClosure) {
    // The closure holds the frames; the analysis model's equations must then hold too.
    int worst = -1;
    double largest = 0.0;
    for (int i = 0; i < assembled.model.numConstraints(); ++i) {
      const ConstraintEquation& eq = assembled.model.equations[i];
      if (eq.source == EquationSource::Joint && std::abs(phi(i)) > largest) {
        largest = std::abs(phi(i));
        worst = eq.element;
      }
    }
    char what[160];
    std::snprintf(what, sizeof(what), "the assembled pose does not satisfy the constraints (residual %.3g m)",
                  maxAbs(phi) * lc);
    if (worst < 0)
      return makeDiagnostic(mechanism.file, "robot", mechanism.name, what);
    return makeDiagnostic(mechanism.file, toString(mechanism.joints[worst].kind),
                          mechanism.joints[worst].name, what);
  }
  return assembled;
}

}  // namespace

Result<AssembledMechanism> assembleMechanism(const Mechanism& mechanism, const LinkPoses& startPoses,
                                             AnalysisMode mode, const JointPositions& driven,
                                             bool sideThread) {
  return assembleFrom(mechanism, startPoses, nullptr, mode, driven, sideThread);
}

Result<AssembledMechanism> assembleMechanism(const Mechanism& mechanism, AnalysisMode mode, bool sideThread) {
  LinkPoses written = computeTreePoses(mechanism, {});
  return assembleFrom(mechanism, written, &written, mode, {}, sideThread);
}

}  // namespace mobility_analysis
