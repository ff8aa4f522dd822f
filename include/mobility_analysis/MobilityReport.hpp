#pragma once

#include <string>
#include <vector>

namespace mobility_analysis {

/// One redundant equation, named by its source (DESIGN.md §4).
struct RedundantConstraint {
  int index = 0;          ///< Position in the contract order.
  std::string source;     ///< "link", "joint" or "boundary".
  std::string name;       ///< Element name (link or connection).
  std::string kind;       ///< Equation kind ("coincident_point", …).
  std::string equation;   ///< Readable form.
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
};

/// @return The report as one JSON object (DESIGN.md §4), keys in a fixed order, numbers with 9 significant digits.
std::string toJson(const MobilityReport& report);

/// @return The readable report the CLI prints by default.
std::string toText(const MobilityReport& report);

}  // namespace mobility_analysis
