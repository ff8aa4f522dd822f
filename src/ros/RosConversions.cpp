#include "mobility_analysis/ros/RosConversions.hpp"

#include <algorithm>
#include <cmath>

#include "mobility_analysis/UrdfLoader.hpp"
#include "mobility_analysis/ElementClassification.h"

namespace mobility_analysis {

namespace {

// Marker sizes as fractions of the mechanism's characteristic length [-].
constexpr double kLinkWidth = 0.025;
constexpr double kJointDiameter = 0.07;
constexpr double kJointLength = 0.25;
constexpr double kSphereDiameter = 0.1;
constexpr double kTextHeight = 0.07;
constexpr double kTitleHeight = 0.1;
/// Two joint points closer than this fraction of the characteristic length are one point [-].
constexpr double kSamePoint = 1e-6;

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
  if (to.norm() < 1e-12) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond::FromTwoVectors(from, to.normalized());
}

/// Joint-frame origins of connection @p j on both sides, in the root frame.
std::pair<Eigen::Vector3d, Eigen::Vector3d> jointPoints(const Mechanism& mechanism, const LinkPoses& poses, int j) {
  const Joint& joint = mechanism.joints[j];
  return {(poses[joint.link1] * joint.frame1).translation(), (poses[joint.link2] * joint.frame2).translation()};
}

/// Distinct points where link @p l meets its connections, in the root frame; its origin when it has none.
std::vector<Eigen::Vector3d> linkPoints(const Mechanism& mechanism, const LinkPoses& poses, int l, double scale) {
  std::vector<Eigen::Vector3d> points;
  auto add = [&](const Eigen::Vector3d& p) {
    for (const Eigen::Vector3d& q : points) {
      if ((q - p).norm() < kSamePoint * scale) return;
    }
    points.push_back(p);
  };
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const Joint& joint = mechanism.joints[j];
    if (joint.type == JointType::Floating && joint.kind == ConnectionKind::TreeJoint) continue;
    if (joint.link1 == l) add((poses[l] * joint.frame1).translation());
    if (joint.link2 == l) add((poses[l] * joint.frame2).translation());
  }
  if (points.empty()) add(poses[l].translation());
  return points;
}

visualization_msgs::Marker makeMarker(const std::string& frame, const ros::Time& stamp, const char* ns, int id,
                                      int type, const std_msgs::ColorRGBA& color) {
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
  response.nullity_trace.assign(report.nullityTrace.begin(), report.nullityTrace.end());
}


std::vector<ElementClassification> toStatusMessages(
    const std::vector<ElementStatus>& statuses) {
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
  if (request.joint_names.empty() && request.positions.empty()) return JointPositions{};
  return makeJointPositions(request.joint_names, request.positions, mechanism);
}

}  // namespace

std_msgs::ColorRGBA toColor(ElementClass elementClass, bool isLink) {
  switch (elementClass) {
    case ElementClass::Redundant: return makeColor(1.0f, 0.0f, 0.0f);
    case ElementClass::OverConstrainedLoop: return makeColor(1.0f, 0.5f, 0.0f);
    case ElementClass::Neutral: break;
  }
  return isLink ? makeColor(0.65f, 0.65f, 0.7f) : makeColor(0.2f, 0.45f, 0.95f);
}

ElementClass fromClassName(const std::string& name) {
  if (name == toString(ElementClass::Redundant)) return ElementClass::Redundant;
  if (name == toString(ElementClass::OverConstrainedLoop)) return ElementClass::OverConstrainedLoop;
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
  out.translation() = Eigen::Vector3d(transform.translation.x, transform.translation.y, transform.translation.z);
  out.linear() =
      Eigen::Quaterniond(transform.rotation.w, transform.rotation.x, transform.rotation.y, transform.rotation.z)
          .normalized()
          .toRotationMatrix();
  return out;
}

void toResponse(const MobilityReport& report, GetDof::Response& response) { toDofFields(report, response); }

void toResponse(const MobilityReport& report, GetRedundancy::Response& response) {
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
  response.cables.clear();
  for (const CableState& c : report.cables) {
    CableStatus m;
    m.name = c.name;
    m.type = c.type;
    m.state = c.state;
    m.length = c.length;
    m.distance = c.distance;
    response.cables.push_back(m);
  }
  response.rank_margin.tolerance = report.rankMargin.tolerance;
  response.rank_margin.smallest_kept_pivot = report.rankMargin.smallestKeptPivot;
  response.rank_margin.largest_dropped_residual = report.rankMargin.largestDroppedResidual;
  response.rank_margin.near_tolerance = report.rankMargin.nearTolerance;
  response.characteristic_length = report.characteristicLength;
  response.closure_residual_before = report.closureResidualBefore;
  response.closure_residual_after = report.closureResidualAfter;
}

void toResponse(const MobilityReport& report, LoadRobot::Response& response) {
  response.success = true;
  response.message.clear();
  response.robot = report.robot;
  response.dof = report.dof;
  response.grubler_kutzbach_dof = report.grublerKutzbachDof;
  response.num_redundant = report.numRedundant;
}

MobilityReport fromResponse(const GetRedundancy::Response& response) {
  MobilityReport report;
  report.robot = response.robot;
  report.file = response.file;
  report.mode = response.mode;
  report.lambda = response.lambda;
  report.dof = response.dof;
  report.grublerKutzbachDof = response.grubler_kutzbach_dof;
  report.numCoordinates = response.num_coordinates;
  report.numConstraints = response.num_constraints;
  report.rank = response.rank;
  report.numRedundant = response.num_redundant;
  report.nullityTrace.assign(response.nullity_trace.begin(), response.nullity_trace.end());
  for (const auto& c : response.redundant_constraints) {
    report.redundantConstraints.push_back(RedundantConstraint{c.index, c.source, c.name, c.kind, c.equation});
  }
  for (const auto& j : response.redundant_joints) {
    report.redundantJoints.push_back(RedundantJoint{j.name, j.redundant_equations, j.equations});
  }
  report.redundantLinks = response.redundant_links;
  report.redundantLinksComputed = response.redundant_links_computed;
  report.redundantBoundaries = response.redundant_boundaries;
  for (const auto& s : response.links) report.links.push_back(fromStatus(s));
  for (const auto& s : response.joints) report.joints.push_back(fromStatus(s));
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
  return report;
}

Result<JointPositions> fromRequest(const GetDof::Request& request, const Mechanism& mechanism) {
  return positionsOf(request, mechanism);
}

Result<JointPositions> fromRequest(const GetRedundancy::Request& request, const Mechanism& mechanism) {
  return positionsOf(request, mechanism);
}

visualization_msgs::MarkerArray toMarkerArray(const Mechanism& mechanism, const LinkPoses& poses,
                                              const MobilityReport& report, const ros::Time& stamp) {
  using visualization_msgs::Marker;
  const double scale = report.characteristicLength > 0.0 && std::isfinite(report.characteristicLength)
                           ? report.characteristicLength
                           : 1.0;
  const std::string frame = mechanism.links.empty() ? std::string() : mechanism.links[mechanism.rootLink].name;
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
  auto label = [&](int id, const std::string& text, const Eigen::Vector3d& at, const std_msgs::ColorRGBA& color) {
    Marker m = makeMarker(frame, stamp, kLabelsNamespace, id, Marker::TEXT_VIEW_FACING, color);
    m.pose.position = toPoint(at);
    m.scale.x = m.scale.y = m.scale.z = kTextHeight * scale;
    m.text = text;
    labels.push_back(m);
  };

  for (int l = 0; l < numLinks; ++l) {
    const std_msgs::ColorRGBA color = toColor(classOf(report.links, l), true);
    const std::vector<Eigen::Vector3d> points = linkPoints(mechanism, poses, l, scale);
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
      // Every pair of joint points: a binary link is one bar, a ternary link a triangle (the lecture's plates).
      Marker m = makeMarker(frame, stamp, kLinksNamespace, l, Marker::LINE_LIST, color);
      m.scale.x = m.scale.y = m.scale.z = kLinkWidth * scale;
      for (size_t a = 0; a < points.size(); ++a) {
        for (size_t b = a + 1; b < points.size(); ++b) {
          m.points.push_back(toPoint(points[a]));
          m.points.push_back(toPoint(points[b]));
        }
      }
      array.markers.push_back(m);
    }
    label(l, mechanism.links[l].name, centroid + Eigen::Vector3d(0, 0, 0.6 * kTextHeight * scale), color);
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
    const bool isRod = joint.kind == ConnectionKind::DistanceConstraint || joint.kind == ConnectionKind::Cable;
    if (isRod && (p1 - p2).norm() > kSamePoint * scale) {
      m.type = Marker::LINE_LIST;
      m.pose.position = geometry_msgs::Point();
      m.scale.x = m.scale.y = m.scale.z = 0.5 * kLinkWidth * scale;
      m.points = {toPoint(p1), toPoint(p2)};
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
          m.pose.orientation = toQuaternion(Eigen::Quaterniond((poses[joint.link2] * joint.frame2).rotation()));
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
    label(numLinks + id, joint.name, p2 + Eigen::Vector3d(0, 0, 1.2 * kSphereDiameter * scale), color);
  }
  array.markers.insert(array.markers.end(), labels.begin(), labels.end());

  if (!mechanism.links.empty()) {
    char text[160];
    std::snprintf(text, sizeof(text), "%s: DOF %d (Gr\xC3\xBC"
                  "bler %d), %d redundant",
                  report.robot.c_str(), report.dof, report.grublerKutzbachDof, report.numRedundant);
    Marker title = makeMarker(frame, stamp, kTitleNamespace, 0, Marker::TEXT_VIEW_FACING,
                              makeColor(1.0f, 1.0f, 1.0f));
    title.pose.position = toPoint(Eigen::Vector3d(0.5 * (lower.x() + upper.x()), 0.5 * (lower.y() + upper.y()),
                                                  upper.z() + 2.5 * kTitleHeight * scale));
    title.scale.x = title.scale.y = title.scale.z = kTitleHeight * scale;
    title.text = text;
    array.markers.push_back(title);
  }
  return array;
}

std::vector<geometry_msgs::TransformStamped> toTransforms(const Mechanism& mechanism, const LinkPoses& poses,
                                                          const std::string& fixedFrame, const ros::Time& stamp) {
  std::vector<geometry_msgs::TransformStamped> transforms;
  if (mechanism.links.empty()) return transforms;
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
  if (!fixedFrame.empty() && !fixedIsLink) add(fixedFrame, root, Eigen::Isometry3d::Identity());
  for (size_t l = 0; l < mechanism.links.size(); ++l) {
    if (static_cast<int>(l) == mechanism.rootLink) continue;
    add(root, mechanism.links[l].name, poses[l]);
  }
  return transforms;
}

}  // namespace mobility_analysis
