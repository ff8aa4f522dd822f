#pragma once

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "mobility_analysis/Diagnostic.hpp"

namespace mobility_analysis {

/// One redundant equation, named by its source (DESIGN.md §4).
struct RedundantConstraint {
  int index = 0;          ///< Position in the contract order.
  std::string source;     ///< "link", "joint" or "boundary".
  std::string name;       ///< Element name (link or connection).
  std::string kind;       ///< Equation kind ("coincident_point", …).
  std::string equation;   ///< Readable form.
  /// "structural" (the design makes it dependent) or "configuration" (only this pose does: it is independent
  /// at nearby poses the mechanism reaches).
  std::string cause = "structural";
};

/// A connection with redundant equations: "k of n equations".
struct RedundantJoint {
  std::string name;
  int redundantEquations = 0;
  int equations = 0;
};

/// How an element is shown: red when redundant, orange when part of an over-constrained loop, else neutral.
enum class ElementClass { Neutral, OverConstrainedLoop, Redundant };
/// @return "neutral", "over_constrained_loop" or "redundant".
const char* toString(ElementClass elementClass);

/// The class of one link or connection, for markers and the JSON.
struct ElementStatus {
  std::string name;
  std::string kind;   ///< "link", "joint", "loop_joint", "distance_constraint", "cable".
  std::string type;   ///< Joint type ("revolute", …) or "link".
  ElementClass elementClass = ElementClass::Neutral;
};

/// State of one cable (DESIGN.md §2).
struct CableState {
  std::string name;
  std::string type;    ///< "passive" or "active".
  std::string state;   ///< "taut", "slack" or "driving".
  double length = 0.0;    ///< Declared [m].
  double distance = 0.0;  ///< Between its ends at the assembled pose [m].
};

/// The rank decision's margin: what separated kept from dropped (relative to each row's norm).
struct RankMargin {
  double tolerance = 0.0;
  double smallestKeptPivot = 0.0;       ///< 0 when nothing was kept.
  double largestDroppedResidual = 0.0;  ///< 0 when nothing was dropped.
  bool nearTolerance = false;           ///< A decision within tolerances::kNearDecisionFactor of the threshold.
};

/// A motion of an idle group of links while every other link stays put (Tsai 1999): a rod spinning between
/// two ball joints, a slider sliding along the line of two parallel prismatic joints.
struct PassiveMotion {
  std::vector<std::string> links;  ///< The links of the group.
  std::string description;         ///< "rod leg3 spins about the line through its two ball joints".
};

/// One tree joint's value at the analysed pose.
struct JointValue {
  std::string name;
  double value = 0.0;  ///< [rad] or [m]
};

/// How the analysed pose was reached from the written (or previous) pose.
struct AssemblyInfo {
  double residual = 0.0;            ///< max |Phi| at the analysed pose [m].
  int steps = 0;                    ///< Continuation steps taken towards the driven positions.
  int iterations = 0;               ///< Newton iterations, all steps together.
  std::vector<std::string> events;  ///< Branch points or dead points met, one readable line each.
};

/// One element's share of a state of self-stress (or of a prestress), relative to the largest.
struct ElementForce {
  std::string name;
  std::string kind;    ///< "link", "joint", "loop_joint", "distance_constraint", "cable" or "boundary".
  /// Relative force in [-1, 1]: cables and distance constraints signed (tension positive, the axial force
  /// 2 y L of the equation |p2 - p1|^2 = L^2 with multiplier y); links, joints and boundaries the magnitude
  /// (norm of their equations' multipliers), >= 0.
  double force = 0.0;
};

/// One state of self-stress: the elements that carry it (its support).
struct SelfStressState {
  std::vector<ElementForce> elements;
};

/**
 * @brief States of self-stress and prestress (Calladine–Maxwell: m = num_coordinates − rank is the dof,
 * s = num_constraints − rank the count; Guest & Fowler 2005).
 */
struct SelfStressInfo {
  int count = 0;                        ///< s = num_constraints − rank = number of redundant equations.
  int mechanismModes = 0;               ///< m = num_coordinates − rank = dof.
  std::vector<SelfStressState> states;  ///< On the local basis of SelfStressBasis (at most kMaxListedStates).
  bool statesListed = true;             ///< False when count exceeded the listing limit.
  int tautCables = 0;                   ///< Taut passive cables (and locked active ones).
  bool prestressable = false;           ///< Some combination of the states puts every taut cable in tension.
  std::vector<ElementForce> prestress;  ///< The tension pattern found, every element of it (largest 1).
  bool prestressStable = false;         ///< That prestress makes the stress matrix positive on the m modes.
  std::string stability;                ///< How prestressStable was decided, one readable line.
};

/// One step of a deployment: the active cable's length and where everything is.
struct DeploymentStep {
  double activeLength = 0.0;        ///< [m]
  int dof = 0;                      ///< Nullity at this step (active cable ignored, slack cables ignored).
  std::vector<CableState> cables;   ///< Every cable (passive: taut/slack; active: driving).
  std::vector<JointValue> joints;   ///< A few tree joints' values.
};

/// A deployment driven by shortening an active cable (DESIGN.md §4 `deployment`).
struct DeploymentInfo {
  std::string cable;                    ///< The active cable.
  double initialLength = 0.0;           ///< [m]
  double targetLength = 0.0;            ///< Where the continuation was headed [m].
  double finalLength = 0.0;             ///< Where it stopped [m].
  int finalDof = 0;                     ///< DOF of the final report (taut cables counted).
  std::vector<std::string> stoppedBy;   ///< Passive cables that went taut (empty: none did).
  std::string reason;                   ///< Why it stopped, one readable line.
  std::vector<DeploymentStep> steps;
};

/// Everything the CLI prints and the services return; field names follow the JSON keys.
struct MobilityReport {
  std::string robot;
  std::string file;
  std::string mode;            ///< "planar" or "spatial".
  int lambda = 6;
  int dof = 0;
  int grublerKutzbachDof = 0;
  int numCoordinates = 0;
  int numConstraints = 0;
  int rank = 0;
  int numRedundant = 0;
  int finiteDof = 0;      ///< Dimension of the configuration set near the pose (how it really moves).
  bool singular = false;  ///< finiteDof != dof: the pose, not the design, adds first-order freedom.
  int passiveDof = 0;     ///< Freedoms of idle groups (passiveMotions).
  int outputDof = 0;      ///< finiteDof - passiveDof.
  std::vector<PassiveMotion> passiveMotions;
  std::vector<int> nullityTrace;
  std::vector<RedundantConstraint> redundantConstraints;
  std::vector<RedundantJoint> redundantJoints;
  std::vector<std::string> redundantLinks;
  std::vector<std::string> redundantBoundaries;  ///< Names of ground links whose boundary equations are redundant.
  bool redundantLinksComputed = true;            ///< False when skipped for size (see README).
  std::vector<ElementStatus> links;
  std::vector<ElementStatus> joints;
  std::vector<CableState> cables;
  RankMargin rankMargin;
  double characteristicLength = 1.0;   ///< [m]
  double closureResidualBefore = 0.0;  ///< [m]
  double closureResidualAfter = 0.0;   ///< [m]
  std::vector<JointValue> positions;   ///< Every tree joint with a single value, in document order.
  AssemblyInfo assembly;
  std::vector<std::string> warnings;   ///< What was read but not understood (one line each).
  SelfStressInfo selfStress;           ///< States of self-stress and prestress (`self_stress`).
  std::optional<DeploymentInfo> deployment;  ///< With --deploy: how the final pose was reached.
};

/**
 * @brief The report as one JSON object (DESIGN.md §4), keys in a fixed order, numbers with 9 significant digits.
 * @note Never writes inf or nan (JSON has neither): a non-finite number becomes null. Callers that publish a
 *       report use writeJson, which refuses such a report instead.
 */
std::string toJson(const MobilityReport& report);
/// toJson, written on the caller's thread alone when @p sideThread is false (a large report is otherwise
/// written in two halves on two threads; the text is the same).
std::string toJson(const MobilityReport& report, bool sideThread);

/**
 * @brief The report's own invariants: every number finite, characteristic length positive,
 *        num_coordinates - rank == dof, num_constraints - rank == num_redundant == |redundant_constraints|,
 *        output_dof == finite_dof - passive_dof.
 * @return Nothing when they hold, else the Diagnostic naming the first that does not.
 */
std::optional<Diagnostic> checkReport(const MobilityReport& report);

/// @return toJson(report, sideThread) once checkReport holds, else its Diagnostic: a report is only written
/// when sound.
Result<std::string> writeJson(const MobilityReport& report, bool sideThread = true);
/**
 * @brief writeJson to @p out, written as it is made: the text never exists whole in memory (a 10^6-link
 *        chain's is 215 MB), and nothing is written when checkReport refuses the report.
 * @return Nothing once written (the stream's own state tells whether it took it all), else checkReport's
 *         Diagnostic.
 */
std::optional<Diagnostic> writeJson(const MobilityReport& report, std::ostream& out, bool sideThread = true);

/// @return toText(report) once checkReport holds, else its Diagnostic.
Result<std::string> writeText(const MobilityReport& report);

/// @return The readable report the CLI prints by default.
std::string toText(const MobilityReport& report);

}  // namespace mobility_analysis
