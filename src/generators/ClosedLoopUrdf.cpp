#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <deque>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

namespace mobility_analysis {

Eigen::Matrix3d rotationFromRpy(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d rpyFromRotation(const Eigen::Matrix3d& rotation) {
  // Taking yaw first and reading pitch and roll from Rz(-yaw)·R keeps the round trip exact to rounding
  // near pitch = ±90°, where the textbook asin/atan2 formulas lose half the digits and would open the loops.
  const double yaw = std::atan2(rotation(1, 0), rotation(0, 0));
  const Eigen::Matrix3d rest =
      Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * rotation;
  // rest = Ry(pitch) Rx(roll) = [[cp, sp sr, sp cr], [0, cr, -sr], [-sp, cp sr, cp cr]]
  const double pitch = std::atan2(-rest(2, 0), rest(0, 0));
  const double roll = std::atan2(-rest(1, 2), rest(1, 1));
  return {roll, pitch, yaw};
}

Eigen::Isometry3d toIsometry(const UrdfPose& pose) {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  transform.linear() = rotationFromRpy(pose.rpy);
  transform.translation() = pose.xyz;
  return transform;
}

namespace {

constexpr double kSnapTolerance =
    1e-15;  ///< Below this (relative to the model size) a coordinate is printed as 0.

double snap(double value, double scale) {
  return std::abs(value) < kSnapTolerance * scale ? 0.0 : value;
}

UrdfPose toUrdfPose(const Eigen::Isometry3d& transform, double lengthScale) {
  UrdfPose pose;
  for (int i = 0; i < 3; ++i) {
    pose.xyz[i] = snap(transform.translation()[i], lengthScale);
  }
  const Eigen::Vector3d rpy = rpyFromRotation(transform.linear());
  for (int i = 0; i < 3; ++i) {
    pose.rpy[i] = snap(rpy[i], 1.0);
  }
  return pose;
}

Eigen::Vector3d cleanAxis(const Eigen::Vector3d& axis) {
  Eigen::Vector3d clean = axis;
  for (int i = 0; i < 3; ++i) {
    clean[i] = snap(clean[i], 1e2);  // a unit vector: 1e-13 noise from the frame product is no direction
  }
  return clean.normalized();
}

bool isFinite(const Eigen::Isometry3d& frame) {
  return frame.matrix().allFinite();
}

/// Characteristic length of the model, to make snapping relative.
double computeLengthScale(const MechanismDescription& mechanism) {
  double scale = 0.0;
  for (const Connection& connection : mechanism.connections) {
    scale = std::max(scale, connection.frame.translation().cwiseAbs().maxCoeff());
  }
  return std::max(scale, 1e-3);
}

std::vector<CylinderVisual> buildVisuals(const std::vector<Eigen::Vector3d>& worldPath, bool star,
                                         const Eigen::Isometry3d& linkFrame, double radius,
                                         double lengthScale) {
  std::vector<CylinderVisual> cylinders;
  const Eigen::Isometry3d toLink = linkFrame.inverse();
  for (size_t i = 1; i < worldPath.size(); ++i) {
    const Eigen::Vector3d a = toLink * (star ? worldPath.front() : worldPath[i - 1]);
    const Eigen::Vector3d b = toLink * worldPath[i];
    const double length = (b - a).norm();
    if (length < 1e-9) {
      continue;
    }
    CylinderVisual cylinder;
    cylinder.origin = toUrdfPose(frameFromAxis(0.5 * (a + b), b - a), lengthScale);
    cylinder.length = length;
    cylinder.radius = radius;
    cylinders.push_back(cylinder);
  }
  return cylinders;
}

}  // namespace

GeneratorResult<ClosedLoopLayout> computeClosedLoopLayout(const MechanismDescription& mechanism,
                                                          const UrdfWriterOptions& options) {
  const size_t numLinks = mechanism.links.size();
  if (numLinks == 0) {
    return GeneratorError{"mechanism '" + mechanism.name + "': no links (the first link is the ground)"};
  }
  std::unordered_map<std::string, size_t> linkIndex;
  linkIndex.reserve(numLinks);
  for (size_t i = 0; i < numLinks; ++i) {
    if (mechanism.links[i].name.empty() || !linkIndex.emplace(mechanism.links[i].name, i).second) {
      return GeneratorError{"link '" + mechanism.links[i].name + "': empty or duplicate link name"};
    }
  }
  const size_t numConnections = mechanism.connections.size();
  std::vector<std::array<size_t, 2>> ends(numConnections);
  std::unordered_set<std::string> jointNames;
  jointNames.reserve(numConnections);
  for (size_t c = 0; c < numConnections; ++c) {
    const Connection& connection = mechanism.connections[c];
    if (connection.name.empty() || !jointNames.insert(connection.name).second) {
      return GeneratorError{"connection '" + connection.name + "': empty or duplicate joint name"};
    }
    const auto it1 = linkIndex.find(connection.link1);
    const auto it2 = linkIndex.find(connection.link2);
    if (it1 == linkIndex.end() || it2 == linkIndex.end() || it1 == it2) {
      return GeneratorError{"connection '" + connection.name + "': links '" + connection.link1 + "' and '" +
                            connection.link2 + "' must be two different known links"};
    }
    if (!isFinite(connection.frame) || !connection.axis.allFinite() || !connection.point2.allFinite() ||
        connection.axis.norm() < 1e-12 || connection.axis2.norm() < 1e-12) {
      return GeneratorError{"connection '" + connection.name + "': non-finite frame or zero axis"};
    }
    ends[c] = {it1->second, it2->second};
  }

  // Spanning tree in document order (see the header): pending[l] lists connections examined while neither
  // end was attached; they are re-examined when l gets attached.
  std::vector<int> treeConnectionOf(numLinks, -1);
  std::vector<bool> attached(numLinks, false);
  std::vector<bool> isTree(numConnections, false);
  std::vector<std::vector<size_t>> pending(numLinks);
  std::vector<size_t> attachOrder;  // non-root links, parents first
  std::vector<size_t> parentOf(numLinks, 0);
  attachOrder.reserve(numLinks);
  attached[0] = true;

  std::deque<size_t> newlyAttached;
  auto tryConnection = [&](size_t c) {
    if (isTree[c] || !isTreeCapable(mechanism.connections[c].type)) {
      return;
    }
    const size_t a = ends[c][0];
    const size_t b = ends[c][1];
    if (attached[a] == attached[b]) {
      if (!attached[a]) {
        pending[a].push_back(c);
        pending[b].push_back(c);
      }
      return;
    }
    const size_t child = attached[a] ? b : a;
    parentOf[child] = attached[a] ? a : b;
    attached[child] = true;
    isTree[c] = true;
    treeConnectionOf[child] = static_cast<int>(c);
    attachOrder.push_back(child);
    newlyAttached.push_back(child);
  };
  auto drainPending = [&]() {
    while (!newlyAttached.empty()) {
      const size_t link = newlyAttached.front();
      newlyAttached.pop_front();
      std::vector<size_t> waiting;
      waiting.swap(pending[link]);
      for (size_t c : waiting) {
        tryConnection(c);
      }
    }
  };
  for (size_t c = 0; c < numConnections; ++c) {
    tryConnection(c);
    drainPending();
  }
  std::vector<bool> isFloating(numLinks, false);
  for (size_t l = 1; l < numLinks; ++l) {
    if (!attached[l]) {
      attached[l] = true;
      isFloating[l] = true;
      parentOf[l] = 0;
      attachOrder.push_back(l);
      newlyAttached.push_back(l);
      drainPending();
    }
  }

  // World frame of every link: the root is the world; a tree child IS its joint's frame.
  ClosedLoopLayout layout;
  layout.robotName = mechanism.name;
  layout.linkFrames.assign(numLinks, Eigen::Isometry3d::Identity());
  std::vector<std::vector<Eigen::Vector3d>> jointPoints(numLinks);
  for (size_t c = 0; c < numConnections; ++c) {
    const Connection& connection = mechanism.connections[c];
    jointPoints[ends[c][0]].push_back(connection.frame.translation());
    jointPoints[ends[c][1]].push_back(
        connection.type == ConnectionType::Distance ? connection.point2 : connection.frame.translation());
  }
  for (size_t l = 1; l < numLinks; ++l) {
    if (isFloating[l]) {
      const LinkDescription& link = mechanism.links[l];
      Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
      if (link.floatingFrame) {
        frame = *link.floatingFrame;
      } else if (!jointPoints[l].empty()) {
        frame.translation() = jointPoints[l].front();
      }
      layout.linkFrames[l] = frame;
    } else {
      layout.linkFrames[l] = mechanism.connections[static_cast<size_t>(treeConnectionOf[l])].frame;
    }
  }

  const double lengthScale = computeLengthScale(mechanism);
  layout.links.reserve(numLinks);
  layout.visuals.resize(numLinks);
  for (size_t l = 0; l < numLinks; ++l) {
    const LinkDescription& link = mechanism.links[l];
    layout.links.push_back(link.name);
    if (options.visuals) {
      const bool star = link.visualPath.empty();
      layout.visuals[l] = buildVisuals(star ? jointPoints[l] : link.visualPath, star, layout.linkFrames[l],
                                       mechanism.visualRadius, lengthScale);
    }
  }

  layout.treeJoints.reserve(attachOrder.size());
  for (size_t child : attachOrder) {
    TreeJointLayout joint;
    const size_t parent = parentOf[child];
    joint.parent = mechanism.links[parent].name;
    joint.child = mechanism.links[child].name;
    if (isFloating[child]) {
      joint.name = "float_" + joint.child;
      if (jointNames.count(joint.name) != 0) {
        return GeneratorError{"link '" + joint.child + "': its floating joint name '" + joint.name +
                              "' is taken by a connection"};
      }
      joint.type = "floating";
      joint.origin = toUrdfPose(layout.linkFrames[parent].inverse() * layout.linkFrames[child], lengthScale);
    } else {
      const Connection& connection = mechanism.connections[static_cast<size_t>(treeConnectionOf[child])];
      joint.name = connection.name;
      joint.type = toString(connection.type);
      joint.origin = toUrdfPose(layout.linkFrames[parent].inverse() * connection.frame, lengthScale);
      joint.axis = cleanAxis(connection.frame.linear().transpose() * connection.axis);
    }
    layout.treeJoints.push_back(std::move(joint));
  }

  for (size_t c = 0; c < numConnections; ++c) {
    if (isTree[c]) {
      continue;
    }
    const Connection& connection = mechanism.connections[c];
    LoopJointLayout loop;
    loop.name = connection.name;
    loop.type = connection.type;
    loop.link1 = connection.link1;
    loop.link2 = connection.link2;
    const Eigen::Isometry3d& frame1 = layout.linkFrames[ends[c][0]];
    const Eigen::Isometry3d& frame2 = layout.linkFrames[ends[c][1]];
    if (connection.type == ConnectionType::Distance) {
      loop.frame1.xyz = frame1.inverse() * connection.frame.translation();
      loop.frame2.xyz = frame2.inverse() * connection.point2;
    } else {
      loop.frame1 = toUrdfPose(frame1.inverse() * connection.frame, lengthScale);
      loop.frame2 = toUrdfPose(frame2.inverse() * connection.frame, lengthScale);
      loop.axis = cleanAxis(connection.frame.linear().transpose() * connection.axis);
      loop.axis2 = cleanAxis(connection.frame.linear().transpose() * connection.axis2);
    }
    layout.loopJoints.push_back(std::move(loop));
  }
  return layout;
}

namespace {

/// Appends the shortest decimal that reads back as the same double, so the file closes as exactly as memory.
void appendNumber(std::string& out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value == 0.0 ? 0.0 : value);
  out.append(buffer, result.ptr);
}

void appendTriple(std::string& out, const Eigen::Vector3d& v) {
  appendNumber(out, v.x());
  out += ' ';
  appendNumber(out, v.y());
  out += ' ';
  appendNumber(out, v.z());
}

void appendPose(std::string& out, const UrdfPose& pose) {
  out += "xyz=\"";
  appendTriple(out, pose.xyz);
  out += "\" rpy=\"";
  appendTriple(out, pose.rpy);
  out += '"';
}

/// XML comments may not contain "--"; options are therefore quoted with a single dash.
std::string sanitizeComment(const std::string& text) {
  std::string clean;
  clean.reserve(text.size());
  for (char ch : text) {
    if (ch == '-' && !clean.empty() && clean.back() == '-') {
      continue;
    }
    clean += ch;
  }
  if (!clean.empty() && clean.back() == '-') {
    clean += ' ';
  }
  return clean;
}

std::string buildHeaderComment(const MechanismDescription& mechanism, const ClosedLoopLayout& layout,
                               const UrdfWriterOptions& options) {
  std::ostringstream text;
  text << "\n  " << mechanism.name << "\n\n";
  std::istringstream body(mechanism.comment);
  for (std::string line; std::getline(body, line);) {
    text << "  " << line << '\n';
  }
  text << "\n  Links (incl. ground): " << mechanism.links.size()
       << ", joints: " << mechanism.connections.size() << " (tree " << (layout.treeJoints.size())
       << " incl. floating, loop " << layout.loopJoints.size() << ").\n";
  for (const FamilyExpectation& e : mechanism.expectations) {
    text << "  Expected (" << e.mode << ", lambda " << e.lambda << "): DOF " << e.dof << ", Gruebler "
         << e.grubler << ", redundant equations " << e.redundant << ".\n";
  }
  text << "  Every loop closes exactly at the written pose: both sides of each loop joint reference one "
          "world\n"
          "  frame; all joint values are 0.\n";
  if (!options.generatorCommand.empty()) {
    text << "  Generated by: " << options.generatorCommand << "\n";
  }
  return sanitizeComment(text.str());
}

void writeLayout(const MechanismDescription& mechanism, const ClosedLoopLayout& layout, std::ostream& out,
                 const UrdfWriterOptions& options) {
  std::string chunk;
  chunk.reserve(1 << 16);
  auto flush = [&](bool force) {
    if (force || chunk.size() > (1 << 15)) {
      out.write(chunk.data(), static_cast<std::streamsize>(chunk.size()));
      chunk.clear();
    }
  };
  chunk += "<?xml version=\"1.0\"?>\n<!--";
  chunk += buildHeaderComment(mechanism, layout, options);
  chunk += "-->\n<robot name=\"" + layout.robotName + "\">\n";
  for (size_t l = 0; l < layout.links.size(); ++l) {
    if (layout.visuals[l].empty()) {
      chunk += "  <link name=\"" + layout.links[l] + "\"/>\n";
    } else {
      chunk += "  <link name=\"" + layout.links[l] + "\">\n";
      for (const CylinderVisual& cylinder : layout.visuals[l]) {
        chunk += "    <visual><origin ";
        appendPose(chunk, cylinder.origin);
        chunk += "/><geometry><cylinder radius=\"";
        appendNumber(chunk, cylinder.radius);
        chunk += "\" length=\"";
        appendNumber(chunk, cylinder.length);
        // A neutral material: rviz draws a visual without one in red, the colour of a redundant element.
        chunk += "\"/></geometry><material name=\"neutral_grey\"><color rgba=\"0.7 0.7 0.72 1\"/></material></visual>\n";
      }
      chunk += "  </link>\n";
    }
    flush(false);
  }
  std::vector<const TreeJointLayout*> treeJoints;
  treeJoints.reserve(layout.treeJoints.size());
  for (const TreeJointLayout& joint : layout.treeJoints) {
    treeJoints.push_back(&joint);
  }
  if (mechanism.treeJointsLeafFirst) {
    std::reverse(treeJoints.begin(), treeJoints.end());
  }
  for (const TreeJointLayout* jointPointer : treeJoints) {
    const TreeJointLayout& joint = *jointPointer;
    chunk += "  <joint name=\"" + joint.name + "\" type=\"" + joint.type + "\">\n    <parent link=\"" +
             joint.parent + "\"/>\n    <child link=\"" + joint.child + "\"/>\n    <origin ";
    appendPose(chunk, joint.origin);
    chunk += "/>\n";
    if (joint.type != "fixed" && joint.type != "floating") {
      chunk += "    <axis xyz=\"";
      appendTriple(chunk, joint.axis);
      chunk += "\"/>\n";
      if (joint.type == "revolute" || joint.type == "prismatic") {
        // URDF requires limits on these; they are wide so the written pose is never at a stop.
        chunk += "    <limit lower=\"-1e3\" upper=\"1e3\" effort=\"0\" velocity=\"0\"/>\n";
      }
    }
    chunk += "  </joint>\n";
    flush(false);
  }
  for (const LoopJointLayout& loop : layout.loopJoints) {
    if (loop.type == ConnectionType::Distance) {
      chunk +=
          "  <distance_constraint name=\"" + loop.name + "\">\n    <link1 link=\"" + loop.link1 + "\" xyz=\"";
      appendTriple(chunk, loop.frame1.xyz);
      chunk += "\"/>\n    <link2 link=\"" + loop.link2 + "\" xyz=\"";
      appendTriple(chunk, loop.frame2.xyz);
      chunk += "\"/>\n  </distance_constraint>\n";
    } else {
      chunk += "  <loop_joint name=\"" + loop.name + "\" type=\"" + toString(loop.type) +
               "\">\n    <link1 link=\"" + loop.link1 + "\" ";
      appendPose(chunk, loop.frame1);
      chunk += "/>\n    <link2 link=\"" + loop.link2 + "\" ";
      appendPose(chunk, loop.frame2);
      chunk += "/>\n";
      if (loop.type != ConnectionType::Spherical && loop.type != ConnectionType::Fixed) {
        chunk += "    <axis xyz=\"";
        appendTriple(chunk, loop.axis);
        chunk += "\"/>\n";
      }
      if (loop.type == ConnectionType::Universal) {
        chunk += "    <axis2 xyz=\"";
        appendTriple(chunk, loop.axis2);
        chunk += "\"/>\n";
      }
      chunk += "  </loop_joint>\n";
    }
    flush(false);
  }
  std::unordered_map<std::string, size_t> linkIndex;
  if (!mechanism.cables.empty()) {
    for (size_t l = 0; l < layout.links.size(); ++l) linkIndex[layout.links[l]] = l;
  }
  for (const CableDescription& cable : mechanism.cables) {
    // Ends in their links' frames at the written pose (the layout's world frames).
    auto localPoint = [&](const std::string& link, const Eigen::Vector3d& world) {
      const auto it = linkIndex.find(link);
      const size_t index = it == linkIndex.end() ? 0 : it->second;
      return Eigen::Vector3d(layout.linkFrames[index].inverse() * world);
    };
    char length[40];
    std::snprintf(length, sizeof(length), "%.17g", cable.length);
    chunk += "  <cable name=\"" + cable.name + "\" type=\"" + (cable.active ? "active" : "passive") +
             "\" length=\"" + length + "\">\n    <link1 link=\"" + cable.link1 + "\" xyz=\"";
    appendTriple(chunk, localPoint(cable.link1, cable.point1));
    chunk += "\"/>\n    <link2 link=\"" + cable.link2 + "\" xyz=\"";
    appendTriple(chunk, localPoint(cable.link2, cable.point2));
    chunk += "\"/>\n  </cable>\n";
    flush(false);
  }
  chunk += "</robot>\n";
  flush(true);
}

}  // namespace

std::optional<GeneratorError> writeClosedLoopUrdf(const MechanismDescription& mechanism, std::ostream& out,
                                                  const UrdfWriterOptions& options) {
  GeneratorResult<ClosedLoopLayout> layout = computeClosedLoopLayout(mechanism, options);
  if (const auto* error = std::get_if<GeneratorError>(&layout)) {
    return *error;
  }
  writeLayout(mechanism, std::get<ClosedLoopLayout>(layout), out, options);
  return std::nullopt;
}

GeneratorResult<std::string> toClosedLoopUrdf(const MechanismDescription& mechanism,
                                              const UrdfWriterOptions& options) {
  std::ostringstream out;
  if (std::optional<GeneratorError> error = writeClosedLoopUrdf(mechanism, out, options)) {
    return *error;
  }
  return out.str();
}

}  // namespace mobility_analysis
