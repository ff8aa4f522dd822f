#include "mobility_analysis/ros/RosConversions.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

#include "mobility_analysis/ElementClassification.h"
#include "mobility_analysis/Tolerances.hpp"
#include "mobility_analysis/UrdfLoader.hpp"

namespace mobility_analysis {

namespace {

// Marker sizes as fractions of the mechanism's characteristic length [-].
constexpr double kLinkWidth = 0.025;
constexpr double kJointDiameter = 0.07;
constexpr double kJointLength = 0.25;
constexpr double kSphereDiameter = 0.1;
constexpr double kTextHeight = 0.07;
constexpr double kTitleHeight = 0.1;
/// A link with more joint points than this is drawn as a star from its centroid, not as all pairs.
constexpr size_t kMaxPlateCorners = 6;
/// A label that meets others moves at most this many lines down (then stays: the search stays linear).
constexpr int kMaxLabelShifts = 4;
/// Labels remembered per grid cell of the overlap search (more pile up unchecked: the search stays linear).
constexpr size_t kMaxLabelsPerCell = 16;
/// Two joint points closer than this fraction of the characteristic length are one point [-].
constexpr double kSamePoint = 1e-6;
/// A slack cable is drawn as dashes about this long, with gaps as long [-].
constexpr double kDashLength = 0.03;
/// Most dashes a slack cable is drawn with (a long cable gets longer dashes).
constexpr int kMaxDashes = 100;
/// Width of a cable's line [link widths] (a distance constraint keeps 0.5).
constexpr double kCableWidth = 0.6;
/// Width of an element in ns `forces`: (kForceWidth + kForceWidthGain sqrt|force|) link widths.
constexpr double kForceWidth = 1.0;
constexpr double kForceWidthGain = 2.0;

std_msgs::ColorRGBA makeColor(float r, float g, float b) {
  std_msgs::ColorRGBA color;
  color.r = r;
  color.g = g;
  color.b = b;
  color.a = 1.0f;
  return color;
}

geometry_msgs::Point toPoint(const Eigen::Vector3d& p) {
  geometry_msgs::Point point;
  point.x = p.x();
  point.y = p.y();
  point.z = p.z();
  return point;
}

geometry_msgs::Quaternion toQuaternion(const Eigen::Quaterniond& q) {
  const Eigen::Quaterniond n = q.normalized();
  geometry_msgs::Quaternion out;
  out.x = n.x();
  out.y = n.y();
  out.z = n.z();
  out.w = n.w();
  return out;
}

/// Rotation taking @p from onto the unit direction @p to (identity for a zero @p to).
Eigen::Quaterniond rotationOnto(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  if (to.norm() < 1e-12)
    return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond::FromTwoVectors(from, to.normalized());
}

/// Joint-frame origins of connection @p j on both sides, in the root frame.
std::pair<Eigen::Vector3d, Eigen::Vector3d> jointPoints(const Mechanism& mechanism, const LinkPoses& poses,
                                                        int j) {
  const Joint& joint = mechanism.joints[j];
  return {(poses[joint.link1] * joint.frame1).translation(),
          (poses[joint.link2] * joint.frame2).translation()};
}

/**
 * Distinct points where each link meets its connections, in the root frame (its origin when it has none): one
 * pass over the connections, then per link a sort on the points' grid cells, so the whole is
 * O(J log J) whatever the number of links (the marker builder of a 10^4-unit mast used to loop over every
 * joint for every link).
 */
std::vector<std::vector<Eigen::Vector3d>> linkPoints(const Mechanism& mechanism, const LinkPoses& poses,
                                                     double scale) {
  std::vector<std::vector<Eigen::Vector3d>> points(mechanism.links.size());
  for (const Joint& joint : mechanism.joints) {
    if (joint.type == JointType::Floating && joint.kind == ConnectionKind::TreeJoint)
      continue;
    points[joint.link1].push_back((poses[joint.link1] * joint.frame1).translation());
    points[joint.link2].push_back((poses[joint.link2] * joint.frame2).translation());
  }
  const double cell = kSamePoint * scale;
  for (size_t l = 0; l < points.size(); ++l) {
    std::vector<Eigen::Vector3d>& p = points[l];
    if (p.empty()) {
      p.push_back(poses[l].translation());
      continue;
    }
    // Keep the first of the points that fall into one grid cell (points kSamePoint apart are one point).
    auto key = [cell](const Eigen::Vector3d& v) {
      return std::array<long long, 3>{std::llround(v.x() / cell), std::llround(v.y() / cell),
                                      std::llround(v.z() / cell)};
    };
    std::vector<size_t> order(p.size());
    for (size_t i = 0; i < order.size(); ++i)
      order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return key(p[a]) < key(p[b]); });
    std::vector<bool> keep(p.size(), false);
    size_t kept = order.front();
    keep[kept] = true;
    for (size_t i = 1; i < order.size(); ++i) {
      const Eigen::Vector3d& q = p[order[i]];
      if (key(q) != key(p[order[i - 1]]) && (q - p[kept]).norm() >= cell) {
        kept = order[i];
        keep[kept] = true;
      }
    }
    std::vector<Eigen::Vector3d> distinct;
    for (size_t i = 0; i < p.size(); ++i) {
      if (keep[i])
        distinct.push_back(p[i]);
    }
    p.swap(distinct);
  }
  return points;
}

visualization_msgs::Marker makeMarker(const std::string& frame, const ros::Time& stamp, const char* ns,
                                      int id, int type, const std_msgs::ColorRGBA& color) {
  visualization_msgs::Marker marker;
  marker.header.frame_id = frame;
  marker.header.stamp = stamp;
  marker.ns = ns;
  marker.id = id;
  marker.type = type;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose.orientation.w = 1.0;
  marker.scale.x = marker.scale.y = marker.scale.z = 1.0;
  marker.color = color;
  marker.frame_locked = false;
  return marker;
}

template <class Response>
void toDofFields(const MobilityReport& report, Response& response) {
  response.success = true;
  response.message.clear();
  response.robot = report.robot;
  response.mode = report.mode;
  response.lambda = report.lambda;
  response.dof = report.dof;
  response.grubler_kutzbach_dof = report.grublerKutzbachDof;
  response.num_coordinates = report.numCoordinates;
  response.num_constraints = report.numConstraints;
  response.rank = report.rank;
  response.num_redundant = report.numRedundant;
  response.finite_dof = report.finiteDof;
  response.singular = report.singular;
  response.passive_dof = report.passiveDof;
  response.output_dof = report.outputDof;
  response.passive_motions.clear();
  for (const PassiveMotion& p : report.passiveMotions) {
    PassiveGroup m;
    m.links = p.links;
    m.description = p.description;
    response.passive_motions.push_back(m);
  }
  response.nullity_trace.assign(report.nullityTrace.begin(), report.nullityTrace.end());
  response.positions.clear();
  response.positions.reserve(report.positions.size());
  for (const JointValue& v : report.positions) {
    TreeJointValue m;
    m.name = v.name;
    m.value = v.value;
    response.positions.push_back(m);
  }
  response.assembly.residual = report.assembly.residual;
  response.assembly.steps = report.assembly.steps;
  response.assembly.iterations = report.assembly.iterations;
  response.assembly.events = report.assembly.events;
  response.warnings = report.warnings;
}

template <class Response>
void fromDofFields(const Response& response, MobilityReport& report) {
  report.robot = response.robot;
  report.mode = response.mode;
  report.lambda = response.lambda;
  report.dof = response.dof;
  report.grublerKutzbachDof = response.grubler_kutzbach_dof;
  report.numCoordinates = response.num_coordinates;
  report.numConstraints = response.num_constraints;
  report.rank = response.rank;
  report.numRedundant = response.num_redundant;
  report.finiteDof = response.finite_dof;
  report.singular = response.singular;
  report.passiveDof = response.passive_dof;
  report.outputDof = response.output_dof;
  report.passiveMotions.clear();
  for (const auto& p : response.passive_motions)
    report.passiveMotions.push_back(PassiveMotion{p.links, p.description});
  report.nullityTrace.assign(response.nullity_trace.begin(), response.nullity_trace.end());
  report.positions.clear();
  for (const auto& v : response.positions)
    report.positions.push_back(JointValue{v.name, v.value});
  report.assembly.residual = response.assembly.residual;
  report.assembly.steps = response.assembly.steps;
  report.assembly.iterations = response.assembly.iterations;
  report.assembly.events = response.assembly.events;
  report.warnings = response.warnings;
}

std::vector<StressedElement> toForceMessages(const std::vector<ElementForce>& forces) {
  std::vector<StressedElement> out;
  out.reserve(forces.size());
  for (const ElementForce& f : forces) {
    StressedElement m;
    m.name = f.name;
    m.kind = f.kind;
    m.force = f.force;
    out.push_back(m);
  }
  return out;
}

std::vector<ElementForce> fromForceMessages(const std::vector<StressedElement>& forces) {
  std::vector<ElementForce> out;
  out.reserve(forces.size());
  for (const auto& f : forces)
    out.push_back(ElementForce{f.name, f.kind, f.force});
  return out;
}

void toSelfStressMessage(const SelfStressInfo& info, SelfStressSummary& message) {
  message.count = info.count;
  message.mechanism_modes = info.mechanismModes;
  message.states_listed = info.statesListed;
  message.states.clear();
  for (const SelfStressState& state : info.states) {
    StressState m;
    m.elements = toForceMessages(state.elements);
    message.states.push_back(m);
  }
  message.taut_cables = info.tautCables;
  message.prestressable = info.prestressable;
  message.prestress = toForceMessages(info.prestress);
  message.prestress_stable = info.prestressStable;
  message.stability = info.stability;
}

SelfStressInfo fromSelfStressMessage(const SelfStressSummary& message) {
  SelfStressInfo info;
  info.count = message.count;
  info.mechanismModes = message.mechanism_modes;
  info.statesListed = message.states_listed;
  for (const auto& state : message.states)
    info.states.push_back(SelfStressState{fromForceMessages(state.elements)});
  info.tautCables = message.taut_cables;
  info.prestressable = message.prestressable;
  info.prestress = fromForceMessages(message.prestress);
  info.prestressStable = message.prestress_stable;
  info.stability = message.stability;
  return info;
}

std::vector<CableStatus> toCableMessages(const std::vector<CableState>& cables) {
  std::vector<CableStatus> out;
  out.reserve(cables.size());
  for (const CableState& c : cables) {
    CableStatus m;
    m.name = c.name;
    m.type = c.type;
    m.state = c.state;
    m.length = c.length;
    m.distance = c.distance;
    out.push_back(m);
  }
  return out;
}

std::vector<ElementClassification> toStatusMessages(const std::vector<ElementStatus>& statuses) {
  std::vector<ElementClassification> out;
  out.reserve(statuses.size());
  for (const ElementStatus& s : statuses) {
    ElementClassification m;
    m.name = s.name;
    m.kind = s.kind;
    m.type = s.type;
    m.element_class = toString(s.elementClass);
    out.push_back(m);
  }
  return out;
}

ElementStatus fromStatus(const ElementClassification& status) {
  return ElementStatus{status.name, status.kind, status.type, fromClassName(status.element_class)};
}

template <class Request>
Result<JointPositions> positionsOf(const Request& request, const Mechanism& mechanism) {
  if (request.joint_names.empty() && request.positions.empty())
    return JointPositions{};
  return makeJointPositions(request.joint_names, request.positions, mechanism);
}

/// Bounds of every link point, and the direction "up" the screen (y for a model that lies flat in xy, as
/// mobility_viewer then looks down on it; else z).
struct ModelBounds {
  Eigen::Vector3d lower = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d upper = Eigen::Vector3d::Constant(-std::numeric_limits<double>::max());
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
};

ModelBounds boundsOf(const std::vector<std::vector<Eigen::Vector3d>>& points) {
  ModelBounds bounds;
  for (const auto& link : points) {
    for (const Eigen::Vector3d& p : link) {
      bounds.lower = bounds.lower.cwiseMin(p);
      bounds.upper = bounds.upper.cwiseMax(p);
    }
  }
  if ((bounds.upper.array() < bounds.lower.array()).any()) {
    bounds.lower = bounds.upper = Eigen::Vector3d::Zero();
  }
  const Eigen::Vector3d extent = bounds.upper - bounds.lower;
  if (extent.z() < 0.2 * std::max(extent.x(), extent.y()))
    bounds.up = Eigen::Vector3d::UnitY();
  return bounds;
}

/// Dashes from @p a to @p b for a LINE_LIST: about kDashLength * scale long with equal gaps, at most
/// kMaxDashes, at least two; the first starts at @p a and the last ends at @p b.
std::vector<geometry_msgs::Point> dashes(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double scale) {
  const double length = (b - a).norm();
  const int count =
      std::clamp(static_cast<int>(std::lround(length / (2.0 * kDashLength * scale))), 2, kMaxDashes);
  // count dashes and count - 1 gaps of equal length.
  const double piece = 1.0 / (2 * count - 1);
  std::vector<geometry_msgs::Point> points;
  points.reserve(2 * count);
  for (int i = 0; i < count; ++i) {
    points.push_back(toPoint(a + (2 * i * piece) * (b - a)));
    points.push_back(toPoint(a + (std::min(1.0, (2 * i + 1) * piece)) * (b - a)));
  }
  return points;
}

std_msgs::ColorRGBA mix(const std::array<float, 3>& from, const std::array<float, 3>& to, double t) {
  const float u = static_cast<float>(std::clamp(t, 0.0, 1.0));
  return makeColor(from[0] + u * (to[0] - from[0]), from[1] + u * (to[1] - from[1]),
                   from[2] + u * (to[2] - from[2]));
}

}  // namespace

std_msgs::ColorRGBA toCableColor(const std::string& state, ElementClass elementClass, bool& dashed) {
  dashed = state == "slack";
  if (dashed)
    return makeColor(0.55f, 0.55f, 0.55f);
  if (state == "driving")
    return makeColor(0.85f, 0.2f, 0.85f);
  return toColor(elementClass, false);
}

std_msgs::ColorRGBA toForceColor(double force, bool isSigned) {
  const double f = std::isfinite(force) ? std::clamp(force, -1.0, 1.0) : 0.0;
  const double t = std::sqrt(std::abs(f));  // Small forces (a tenth of the largest) still read as their sign.
  if (!isSigned)
    return mix({0.6f, 0.8f, 0.6f}, {0.1f, 0.8f, 0.2f}, t);
  if (f >= 0.0)
    return mix({0.6f, 0.65f, 0.8f}, {0.1f, 0.35f, 1.0f}, t);
  return mix({0.8f, 0.6f, 0.6f}, {1.0f, 0.1f, 0.05f}, t);
}

ForcesSelection selectForces(const SelfStressInfo& info, int choice) {
  ForcesSelection selection;
  if (choice == kForcesAuto)
    choice = info.prestressable && !info.prestress.empty() ? kForcesPrestress : 0;
  if (choice == kForcesPrestress) {
    if (info.prestressable && !info.prestress.empty()) {
      selection.title = "prestress";
      selection.forces = info.prestress;
    } else {
      selection.title = "no prestress (not prestressable)";
    }
    return selection;
  }
  const int listed = static_cast<int>(info.states.size());
  if (choice >= 0 && choice < listed) {
    selection.title = "state of self-stress " + std::to_string(choice) + " of " + std::to_string(info.count);
    selection.forces = info.states[choice].elements;
  } else if (info.count == 0) {
    selection.title = "no state of self-stress";
  } else {
    selection.title = "no state " + std::to_string(choice) + " (" + std::to_string(info.count) + " states, " +
                      std::to_string(listed) + " listed)";
  }
  return selection;
}

std::vector<visualization_msgs::Marker> toForceMarkers(const Mechanism& mechanism, const LinkPoses& poses,
                                                       const MobilityReport& report, int choice,
                                                       const ros::Time& stamp) {
  using visualization_msgs::Marker;
  std::vector<Marker> markers;
  if (mechanism.links.empty())
    return markers;
  const double scale = report.characteristicLength > 0.0 && std::isfinite(report.characteristicLength)
                           ? report.characteristicLength
                           : 1.0;
  const std::string& frame = mechanism.links[mechanism.rootLink].name;
  const int numLinks = static_cast<int>(mechanism.links.size());
  const int numJoints = static_cast<int>(mechanism.joints.size());
  const ForcesSelection selection = selectForces(report.selfStress, choice);
  const std::vector<std::vector<Eigen::Vector3d>> points = linkPoints(mechanism, poses, scale);

  const ModelBounds bounds = boundsOf(points);
  Marker legend =
      makeMarker(frame, stamp, kForcesNamespace, 0, Marker::TEXT_VIEW_FACING, makeColor(1.0f, 1.0f, 1.0f));
  Eigen::Vector3d at = 0.5 * (bounds.lower + bounds.upper);
  // Below the model and the labels that part downwards beneath it.
  at += (bounds.lower.dot(bounds.up) - at.dot(bounds.up) - 7.0 * kTitleHeight * scale) * bounds.up;
  legend.pose.position = toPoint(at);
  legend.scale.x = legend.scale.y = legend.scale.z = 0.8 * kTitleHeight * scale;
  legend.text = "forces: " + selection.title;
  if (!selection.forces.empty())
    legend.text += " (blue tension, red compression, green |force| of links and joints)";
  markers.push_back(legend);

  for (const ElementForce& f : selection.forces) {
    const bool isSigned = f.kind == "cable" || f.kind == "distance_constraint";
    const std_msgs::ColorRGBA color = toForceColor(f.force, isSigned);
    const double width =
        (kForceWidth + kForceWidthGain * std::sqrt(std::min(1.0, std::abs(f.force)))) * kLinkWidth * scale;
    if (f.kind == "link" || f.kind == "boundary") {
      const std::optional<int> l = mechanism.findLink(f.name);
      if (!l)
        continue;
      const int id = 1 + (f.kind == "link" ? *l : numLinks + numJoints + *l);
      const std::vector<Eigen::Vector3d>& p = points[*l];
      Marker m = makeMarker(frame, stamp, kForcesNamespace, id, Marker::LINE_LIST, color);
      if (p.size() < 2) {
        m.type = Marker::SPHERE;
        m.pose.position = toPoint(p.front());
        m.scale.x = m.scale.y = m.scale.z = 0.8 * kSphereDiameter * scale;
      } else {
        m.scale.x = m.scale.y = m.scale.z = width;
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        for (const Eigen::Vector3d& q : p)
          centroid += q;
        centroid /= static_cast<double>(p.size());
        for (size_t a = 0; a < p.size(); ++a) {
          if (p.size() > kMaxPlateCorners) {
            m.points.push_back(toPoint(centroid));
            m.points.push_back(toPoint(p[a]));
            continue;
          }
          for (size_t b = a + 1; b < p.size(); ++b) {
            m.points.push_back(toPoint(p[a]));
            m.points.push_back(toPoint(p[b]));
          }
        }
      }
      markers.push_back(m);
      continue;
    }
    const std::optional<int> j = mechanism.findJoint(f.name);
    if (!j)
      continue;
    const auto [p1, p2] = jointPoints(mechanism, poses, *j);
    Marker m = makeMarker(frame, stamp, kForcesNamespace, 1 + numLinks + *j, Marker::SPHERE, color);
    if (isSigned && (p1 - p2).norm() > kSamePoint * scale) {
      m.type = Marker::LINE_LIST;
      m.scale.x = m.scale.y = m.scale.z = width;
      // A model lying flat is seen from above: its cables a little above the plane, so one that runs along a
      // bar (a base cable along the ground) is not hidden under the bar's colour.
      const Eigen::Vector3d lift =
          bounds.up.z() == 0.0 ? Eigen::Vector3d(0.0, 0.0, 2.0 * kLinkWidth * scale) : Eigen::Vector3d::Zero();
      m.points = {toPoint(p1 + lift), toPoint(p2 + lift)};
    } else {
      m.pose.position = toPoint(p2);
      m.scale.x = m.scale.y = m.scale.z =
          (1.1 + 0.5 * std::min(1.0, std::abs(f.force))) * kSphereDiameter * scale;
    }
    markers.push_back(m);
  }
  return markers;
}

std_msgs::ColorRGBA toColor(ElementClass elementClass, bool isLink) {
  switch (elementClass) {
    case ElementClass::Redundant:
      return makeColor(1.0f, 0.0f, 0.0f);
    case ElementClass::OverConstrainedLoop:
      return makeColor(1.0f, 0.5f, 0.0f);
    case ElementClass::Neutral:
      break;
  }
  return isLink ? makeColor(0.65f, 0.65f, 0.7f) : makeColor(0.2f, 0.45f, 0.95f);
}

ElementClass fromClassName(const std::string& name) {
  if (name == toString(ElementClass::Redundant))
    return ElementClass::Redundant;
  if (name == toString(ElementClass::OverConstrainedLoop))
    return ElementClass::OverConstrainedLoop;
  return ElementClass::Neutral;
}

geometry_msgs::Pose toPose(const Eigen::Isometry3d& pose) {
  geometry_msgs::Pose out;
  out.position = toPoint(pose.translation());
  out.orientation = toQuaternion(Eigen::Quaterniond(pose.rotation()));
  return out;
}

Eigen::Isometry3d fromTransform(const geometry_msgs::Transform& transform) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.translation() =
      Eigen::Vector3d(transform.translation.x, transform.translation.y, transform.translation.z);
  out.linear() = Eigen::Quaterniond(transform.rotation.w, transform.rotation.x, transform.rotation.y,
                                    transform.rotation.z)
                     .normalized()
                     .toRotationMatrix();
  return out;
}

void toResponse(const MobilityReport& report, GetDof::Response& response) {
  toDofFields(report, response);
}

namespace {

template <class Response>
void toReportFields(const MobilityReport& report, Response& response) {
  toDofFields(report, response);
  response.file = report.file;
  response.redundant_constraints.clear();
  response.redundant_constraints.reserve(report.redundantConstraints.size());
  for (const RedundantConstraint& c : report.redundantConstraints) {
    RedundantEquation m;
    m.index = c.index;
    m.source = c.source;
    m.name = c.name;
    m.kind = c.kind;
    m.equation = c.equation;
    m.cause = c.cause;
    response.redundant_constraints.push_back(m);
  }
  response.redundant_joints.clear();
  for (const RedundantJoint& j : report.redundantJoints) {
    JointRedundancy m;
    m.name = j.name;
    m.redundant_equations = j.redundantEquations;
    m.equations = j.equations;
    response.redundant_joints.push_back(m);
  }
  response.redundant_links = report.redundantLinks;
  response.redundant_links_computed = report.redundantLinksComputed;
  response.redundant_boundaries = report.redundantBoundaries;
  response.links = toStatusMessages(report.links);
  response.joints = toStatusMessages(report.joints);
  response.cables = toCableMessages(report.cables);
  response.rank_margin.tolerance = report.rankMargin.tolerance;
  response.rank_margin.smallest_kept_pivot = report.rankMargin.smallestKeptPivot;
  response.rank_margin.largest_dropped_residual = report.rankMargin.largestDroppedResidual;
  response.rank_margin.near_tolerance = report.rankMargin.nearTolerance;
  response.characteristic_length = report.characteristicLength;
  response.closure_residual_before = report.closureResidualBefore;
  response.closure_residual_after = report.closureResidualAfter;
  toSelfStressMessage(report.selfStress, response.self_stress);
}

template <class Response>
MobilityReport fromReportFields(const Response& response) {
  MobilityReport report;
  fromDofFields(response, report);
  report.file = response.file;
  for (const auto& c : response.redundant_constraints) {
    report.redundantConstraints.push_back(
        RedundantConstraint{c.index, c.source, c.name, c.kind, c.equation, c.cause});
  }
  for (const auto& j : response.redundant_joints) {
    report.redundantJoints.push_back(RedundantJoint{j.name, j.redundant_equations, j.equations});
  }
  report.redundantLinks = response.redundant_links;
  report.redundantLinksComputed = response.redundant_links_computed;
  report.redundantBoundaries = response.redundant_boundaries;
  for (const auto& s : response.links)
    report.links.push_back(fromStatus(s));
  for (const auto& s : response.joints)
    report.joints.push_back(fromStatus(s));
  for (const auto& c : response.cables) {
    report.cables.push_back(CableState{c.name, c.type, c.state, c.length, c.distance});
  }
  report.rankMargin.tolerance = response.rank_margin.tolerance;
  report.rankMargin.smallestKeptPivot = response.rank_margin.smallest_kept_pivot;
  report.rankMargin.largestDroppedResidual = response.rank_margin.largest_dropped_residual;
  report.rankMargin.nearTolerance = response.rank_margin.near_tolerance;
  report.characteristicLength = response.characteristic_length;
  report.closureResidualBefore = response.closure_residual_before;
  report.closureResidualAfter = response.closure_residual_after;
  report.selfStress = fromSelfStressMessage(response.self_stress);
  return report;
}

}  // namespace

void toResponse(const MobilityReport& report, GetRedundancy::Response& response) {
  toReportFields(report, response);
}

void toResponse(const MobilityReport& report, LoadRobot::Response& response) {
  toReportFields(report, response);
}

void toResponse(const MobilityReport& report, Deploy::Response& response) {
  response.success = true;
  response.message.clear();
  response.stopped_by.clear();
  response.active_lengths.clear();
  response.step_dof.clear();
  response.steps = 0;
  if (report.deployment) {
    const DeploymentInfo& d = *report.deployment;
    response.cable = d.cable;
    response.initial_length = d.initialLength;
    response.target_length = d.targetLength;
    response.final_length = d.finalLength;
    response.final_dof = d.finalDof;
    response.stopped_by = d.stoppedBy;
    response.reason = d.reason;
    response.steps = static_cast<int>(d.steps.size());
    response.active_lengths.reserve(d.steps.size());
    response.step_dof.reserve(d.steps.size());
    for (const DeploymentStep& step : d.steps) {
      response.active_lengths.push_back(step.activeLength);
      response.step_dof.push_back(step.dof);
    }
  }
  response.cables = toCableMessages(report.cables);
  toSelfStressMessage(report.selfStress, response.self_stress);
}

DeploymentInfo fromResponse(const Deploy::Response& response) {
  DeploymentInfo d;
  d.cable = response.cable;
  d.initialLength = response.initial_length;
  d.targetLength = response.target_length;
  d.finalLength = response.final_length;
  d.finalDof = response.final_dof;
  d.stoppedBy = response.stopped_by;
  d.reason = response.reason;
  for (size_t i = 0; i < response.active_lengths.size(); ++i) {
    DeploymentStep step;
    step.activeLength = response.active_lengths[i];
    step.dof = i < response.step_dof.size() ? response.step_dof[i] : 0;
    d.steps.push_back(step);
  }
  return d;
}

MobilityReport fromResponse(const GetDof::Response& response) {
  MobilityReport report;
  fromDofFields(response, report);
  return report;
}

MobilityReport fromResponse(const GetRedundancy::Response& response) {
  return fromReportFields(response);
}

MobilityReport fromResponse(const LoadRobot::Response& response) {
  return fromReportFields(response);
}

Result<JointPositions> fromRequest(const GetDof::Request& request, const Mechanism& mechanism) {
  return positionsOf(request, mechanism);
}

Result<JointPositions> fromRequest(const GetRedundancy::Request& request, const Mechanism& mechanism) {
  return positionsOf(request, mechanism);
}

visualization_msgs::MarkerArray toMarkerArray(const Mechanism& mechanism, const LinkPoses& poses,
                                              const MobilityReport& report, const ros::Time& stamp,
                                              int forcesChoice) {
  using visualization_msgs::Marker;
  const double scale = report.characteristicLength > 0.0 && std::isfinite(report.characteristicLength)
                           ? report.characteristicLength
                           : 1.0;
  const std::string frame =
      mechanism.links.empty() ? std::string() : mechanism.links[mechanism.rootLink].name;
  const int numLinks = static_cast<int>(mechanism.links.size());
  auto classOf = [](const std::vector<ElementStatus>& statuses, size_t i) {
    return i < statuses.size() ? statuses[i].elementClass : ElementClass::Neutral;
  };

  visualization_msgs::MarkerArray array;
  Marker deleteAll = makeMarker(frame, stamp, "", 0, Marker::CUBE, makeColor(1.0f, 1.0f, 1.0f));
  deleteAll.action = Marker::DELETEALL;
  array.markers.push_back(deleteAll);

  std::vector<Marker> labels;
  Eigen::Vector3d lower = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d upper = -lower;
  auto label = [&](int id, const std::string& text, const Eigen::Vector3d& at,
                   const std_msgs::ColorRGBA& color) {
    Marker m = makeMarker(frame, stamp, kLabelsNamespace, id, Marker::TEXT_VIEW_FACING, color);
    m.pose.position = toPoint(at);
    m.scale.x = m.scale.y = m.scale.z = kTextHeight * scale;
    m.text = text;
    labels.push_back(m);
  };

  const std::vector<std::vector<Eigen::Vector3d>> allPoints = linkPoints(mechanism, poses, scale);
  std::map<std::string, const CableState*> cableStates;
  for (const CableState& c : report.cables)
    cableStates[c.name] = &c;
  // Labels are pushed away from the model's centre (and joint labels off the joint's axis), so that they
  // stand beside the geometry rather than inside it, and neighbouring labels part.
  Eigen::Vector3d modelCentre = Eigen::Vector3d::Zero();
  size_t numPoints = 0;
  for (const auto& points : allPoints) {
    for (const Eigen::Vector3d& p : points)
      modelCentre += p;
    numPoints += points.size();
  }
  if (numPoints > 0)
    modelCentre /= static_cast<double>(numPoints);
  auto outward = [&](const Eigen::Vector3d& at, const Eigen::Vector3d& axis) {
    Eigen::Vector3d d = at - modelCentre;
    if (axis.norm() > 0.0)
      d -= d.dot(axis.normalized()) * axis.normalized();
    if (d.norm() < kSamePoint * scale)
      d = axis.norm() > 0.0 ? axis.unitOrthogonal() : Eigen::Vector3d::UnitZ();
    return Eigen::Vector3d(d.normalized());
  };
  auto halfWidth = [&](const std::string& text) { return 0.3 * kTextHeight * scale * text.size(); };
  for (int l = 0; l < numLinks; ++l) {
    const std_msgs::ColorRGBA color = toColor(classOf(report.links, l), true);
    const std::vector<Eigen::Vector3d>& points = allPoints[l];
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : points) {
      centroid += p;
      lower = lower.cwiseMin(p);
      upper = upper.cwiseMax(p);
    }
    centroid /= static_cast<double>(points.size());
    if (points.size() < 2) {
      Marker m = makeMarker(frame, stamp, kLinksNamespace, l, Marker::SPHERE, color);
      m.pose.position = toPoint(points.front());
      m.scale.x = m.scale.y = m.scale.z = 0.6 * kSphereDiameter * scale;
      array.markers.push_back(m);
    } else {
      // Every pair of joint points: a binary link is one bar, a ternary link a triangle (the lecture's
      // plates). Beyond kMaxPlateCorners points a star from the centroid, so the marker stays linear in the
      // points.
      Marker m = makeMarker(frame, stamp, kLinksNamespace, l, Marker::LINE_LIST, color);
      m.scale.x = m.scale.y = m.scale.z = kLinkWidth * scale;
      if (points.size() <= kMaxPlateCorners) {
        for (size_t a = 0; a < points.size(); ++a) {
          for (size_t b = a + 1; b < points.size(); ++b) {
            m.points.push_back(toPoint(points[a]));
            m.points.push_back(toPoint(points[b]));
          }
        }
      } else {
        for (const Eigen::Vector3d& p : points) {
          m.points.push_back(toPoint(centroid));
          m.points.push_back(toPoint(p));
        }
      }
      array.markers.push_back(m);
    }
    label(l, mechanism.links[l].name,
          centroid +
              (kJointDiameter * scale + kTextHeight * scale) * outward(centroid, Eigen::Vector3d::Zero()),
          color);
  }

  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const Joint& joint = mechanism.joints[j];
    const std_msgs::ColorRGBA color = toColor(classOf(report.joints, j), false);
    const auto [p1, p2] = jointPoints(mechanism, poses, static_cast<int>(j));
    const Eigen::Vector3d axis = (poses[joint.link2] * joint.frame2).linear() * joint.axis;
    const int id = static_cast<int>(j);
    Marker m = makeMarker(frame, stamp, kJointsNamespace, id, Marker::SPHERE, color);
    m.pose.position = toPoint(p2);
    m.scale.x = m.scale.y = m.scale.z = kSphereDiameter * scale;
    const bool isRod =
        joint.kind == ConnectionKind::DistanceConstraint || joint.kind == ConnectionKind::Cable;
    if (isRod && (p1 - p2).norm() > kSamePoint * scale) {
      m.type = Marker::LINE_LIST;
      m.pose.position = geometry_msgs::Point();
      m.scale.x = m.scale.y = m.scale.z = 0.5 * kLinkWidth * scale;
      m.points = {toPoint(p1), toPoint(p2)};
      if (joint.kind == ConnectionKind::Cable) {
        // As the report says; a cable it does not list is taut when its ends are its length apart.
        const auto listed = cableStates.find(joint.name);
        std::string state = listed != cableStates.end() ? listed->second->state : std::string();
        if (state.empty()) {
          state = joint.cableType == CableType::Active                                       ? "driving"
                  : joint.length - (p1 - p2).norm() <= tolerances::kCableTaut * joint.length ? "taut"
                                                                                             : "slack";
        }
        bool dashed = false;
        m.color = toCableColor(state, classOf(report.joints, j), dashed);
        m.scale.x = m.scale.y = m.scale.z = kCableWidth * kLinkWidth * scale;
        if (dashed)
          m.points = dashes(p1, p2, scale);
      }
    } else if (!isRod) {
      switch (joint.type) {
        case JointType::Revolute:
        case JointType::Continuous:
        case JointType::Cylindrical:
          m.type = Marker::CYLINDER;
          m.pose.orientation = toQuaternion(rotationOnto(Eigen::Vector3d::UnitZ(), axis));
          m.scale.x = m.scale.y = kJointDiameter * scale;
          m.scale.z = (joint.type == JointType::Cylindrical ? 1.6 : 1.0) * kJointLength * scale;
          break;
        case JointType::Prismatic:
          m.type = Marker::ARROW;  // Along the slide, starting at the joint point.
          m.pose.position = toPoint(p1);
          m.pose.orientation = toQuaternion(rotationOnto(Eigen::Vector3d::UnitX(), axis));
          m.scale.x = 1.5 * kJointLength * scale;
          m.scale.y = 0.5 * kJointDiameter * scale;
          m.scale.z = kJointDiameter * scale;
          break;
        case JointType::Universal:
        case JointType::Fixed:
        case JointType::Planar:
          m.type = Marker::CUBE;
          m.pose.orientation =
              toQuaternion(Eigen::Quaterniond((poses[joint.link2] * joint.frame2).rotation()));
          m.scale.x = m.scale.y = m.scale.z = 0.8 * kSphereDiameter * scale;
          break;
        case JointType::Spherical:
        case JointType::Floating:
          break;  // SPHERE.
      }
    }
    if (joint.kind == ConnectionKind::TreeJoint && joint.type == JointType::Floating) {
      m.color.a = 0.3f;  // Constrains nothing (DESIGN.md §2): drawn faint.
    }
    array.markers.push_back(m);
    lower = lower.cwiseMin(p2);
    upper = upper.cwiseMax(p2);
    // Beside the joint, off its axis (a label on a hinge's axis hides in its cylinder).
    const bool hasAxis = joint.type == JointType::Revolute || joint.type == JointType::Continuous ||
                         joint.type == JointType::Cylindrical || joint.type == JointType::Prismatic;
    label(numLinks + id, joint.name,
          p2 + (kSphereDiameter * scale + halfWidth(joint.name)) *
                   outward(p2, hasAxis ? axis : Eigen::Vector3d::Zero()),
          color);
  }
  // Labels that fall on one another (a door and its frame share their joint points) part downwards: the first
  // keeps its place, the next moves one line down until its cell is free.
  const Eigen::Vector3d extent = upper - lower;
  const bool flat = extent.z() < 0.2 * std::max(extent.x(), extent.y());  // Viewed from above, +y up.
  const Eigen::Vector3d up = flat ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
  const double line = kTextHeight * scale;
  // Two labels overlap when they are less than a line apart along `up` and their texts (about 0.6 text
  // heights per character, centred) meet across it. Cells of the widest text keep the search local.
  size_t longest = 1;
  for (const Marker& m : labels)
    longest = std::max(longest, m.text.size());
  const double cellSize = std::max(line, 2.0 * halfWidth(std::string(longest, 'x')));
  struct Placed {
    Eigen::Vector3d at;
    double halfWidth;
  };
  std::map<std::array<long long, 3>, std::vector<Placed>> taken;  // Placed labels by grid cell.
  auto cellOf = [&](const Eigen::Vector3d& at) {
    return std::array<long long, 3>{std::llround(at.x() / cellSize), std::llround(at.y() / cellSize),
                                    std::llround(at.z() / cellSize)};
  };
  auto isFree = [&](const Eigen::Vector3d& at, double width) {
    const std::array<long long, 3> c = cellOf(at);
    for (long long dx = -1; dx <= 1; ++dx) {
      for (long long dy = -1; dy <= 1; ++dy) {
        for (long long dz = -1; dz <= 1; ++dz) {
          const auto found = taken.find({c[0] + dx, c[1] + dy, c[2] + dz});
          if (found == taken.end())
            continue;
          for (const Placed& other : found->second) {
            const Eigen::Vector3d d = other.at - at;
            const double along = d.dot(up);
            if (std::abs(along) < 0.9 * line && (d - along * up).norm() < width + other.halfWidth)
              return false;
          }
        }
      }
    }
    return true;
  };
  double top = -std::numeric_limits<double>::max();
  for (Marker& m : labels) {
    Eigen::Vector3d at(m.pose.position.x, m.pose.position.y, m.pose.position.z);
    const double width = halfWidth(m.text);
    for (int i = 0; i < kMaxLabelShifts && !isFree(at, width); ++i)
      at -= 1.2 * line * up;
    std::vector<Placed>& cell = taken[cellOf(at)];
    if (cell.size() < kMaxLabelsPerCell)
      cell.push_back(Placed{at, width});  // A pile beyond: checks stay bounded.
    m.pose.position = toPoint(at);
    top = std::max(top, at.dot(up));
  }
  array.markers.insert(array.markers.end(), labels.begin(), labels.end());

  if (!mechanism.links.empty()) {
    char text[160];
    std::snprintf(text, sizeof(text),
                  "%s: DOF %d (Gr\xC3\xBC"
                  "bler %d), %d redundant",
                  report.robot.c_str(), report.dof, report.grublerKutzbachDof, report.numRedundant);
    Marker title =
        makeMarker(frame, stamp, kTitleNamespace, 0, Marker::TEXT_VIEW_FACING, makeColor(1.0f, 1.0f, 1.0f));
    // Above the model and its labels: over its top, or beyond its +y edge when it lies flat (mobility_viewer
    // then looks down with +y up the screen).
    Eigen::Vector3d at = 0.5 * (lower + upper);
    if (flat)
      at.z() = upper.z();
    const double height = std::max(top, upper.dot(up)) + 1.5 * kTitleHeight * scale;
    at += (height - at.dot(up)) * up;
    title.pose.position = toPoint(at);
    title.scale.x = title.scale.y = title.scale.z = kTitleHeight * scale;
    title.text = text;
    array.markers.push_back(title);
  }
  const std::vector<Marker> forces = toForceMarkers(mechanism, poses, report, forcesChoice, stamp);
  array.markers.insert(array.markers.end(), forces.begin(), forces.end());
  return array;
}

sensor_msgs::JointState toJointState(const MobilityReport& report, const ros::Time& stamp) {
  sensor_msgs::JointState state;
  state.header.stamp = stamp;
  state.name.reserve(report.positions.size());
  state.position.reserve(report.positions.size());
  for (const JointValue& v : report.positions) {
    state.name.push_back(v.name);
    state.position.push_back(v.value);
  }
  return state;
}

std::vector<geometry_msgs::TransformStamped> toTransforms(const Mechanism& mechanism, const LinkPoses& poses,
                                                          const std::string& fixedFrame,
                                                          const ros::Time& stamp, LinkFrames frames) {
  std::vector<geometry_msgs::TransformStamped> transforms;
  if (mechanism.links.empty())
    return transforms;
  const std::string& root = mechanism.links[mechanism.rootLink].name;
  auto add = [&](const std::string& parent, const std::string& child, const Eigen::Isometry3d& pose) {
    geometry_msgs::TransformStamped t;
    t.header.stamp = stamp;
    t.header.frame_id = parent;
    t.child_frame_id = child;
    const geometry_msgs::Pose p = toPose(pose);
    t.transform.translation.x = p.position.x;
    t.transform.translation.y = p.position.y;
    t.transform.translation.z = p.position.z;
    t.transform.rotation = p.orientation;
    transforms.push_back(t);
  };
  const bool fixedIsLink = mechanism.findLink(fixedFrame).has_value();
  if (!fixedFrame.empty() && !fixedIsLink)
    add(fixedFrame, root, Eigen::Isometry3d::Identity());
  if (frames == LinkFrames::All) {
    transforms.reserve(mechanism.links.size() + 1);
    for (size_t l = 0; l < mechanism.links.size(); ++l) {
      if (static_cast<int>(l) == mechanism.rootLink)
        continue;
      add(root, mechanism.links[l].name, poses[l]);
    }
    return transforms;
  }
  for (const Joint& joint : mechanism.joints) {
    if (joint.kind != ConnectionKind::TreeJoint || joint.type != JointType::Floating)
      continue;
    add(mechanism.links[joint.link1].name, mechanism.links[joint.link2].name,
        poses[joint.link1].inverse() * poses[joint.link2]);
  }
  return transforms;
}

}  // namespace mobility_analysis
