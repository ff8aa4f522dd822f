#include "mobility_analysis/UrdfLoader.hpp"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <unordered_map>

#include <console_bridge/console.h>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>

#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

/// Link index by name: mechanisms with 10^5 links are looked up once per connection end.
using LinkIndex = std::unordered_map<std::string, int>;

/// Reads the XML once; every check names the file and the element.
class LoopElementReader {
 public:
  explicit LoopElementReader(std::string file) : file_(std::move(file)) {}

  Diagnostic error(const std::string& kind, const std::string& name, const std::string& what) const {
    return makeDiagnostic(file_, kind, name, what);
  }

  /// Parses "a b c" strictly: three finite numbers.
  Result<Eigen::Vector3d> parseVector(const char* text, const std::string& kind, const std::string& name,
                                      const std::string& attribute) const {
    if (text == nullptr) {
      return Eigen::Vector3d::Zero().eval();
    }
    std::istringstream stream(text);
    Eigen::Vector3d v;
    std::string token;
    int count = 0;
    while (stream >> token) {
      if (count == 3) {
        return error(kind, name, attribute + " has more than 3 numbers: '" + text + "'");
      }
      char* end = nullptr;
      const double value = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0') {
        return error(kind, name, attribute + " '" + text + "' is not a number triple ('" + token + "')");
      }
      if (!std::isfinite(value)) {
        return error(kind, name, attribute + " '" + text + "' is not finite");
      }
      v[count++] = value;
    }
    if (count != 3) {
      return error(kind, name,
                   attribute + " needs 3 numbers, got " + std::to_string(count) + ": '" + text + "'");
    }
    return v;
  }

  Result<double> parseNumber(const char* text, const std::string& kind, const std::string& name,
                             const std::string& attribute) const {
    if (text == nullptr) {
      return error(kind, name, "missing attribute " + attribute);
    }
    char* end = nullptr;
    const double value = std::strtod(text, &end);
    if (end == text || !std::isfinite(value)) {
      return error(kind, name, attribute + " '" + text + "' is not a finite number");
    }
    while (*end == ' ') {
      ++end;
    }
    if (*end != '\0') {
      return error(kind, name, attribute + " '" + text + "' is not a number");
    }
    return value;
  }

  Result<Eigen::Vector3d> parseAxis(const tinyxml2::XMLElement* element, const char* tag,
                                    const std::string& kind, const std::string& name) const {
    const tinyxml2::XMLElement* axisElement = element->FirstChildElement(tag);
    if (axisElement == nullptr) {
      return std::string(tag) == "axis" ? Eigen::Vector3d::UnitX().eval() : Eigen::Vector3d::UnitY().eval();
    }
    const char* xyz = axisElement->Attribute("xyz");
    if (xyz == nullptr) {
      return error(kind, name, std::string("<") + tag + "> has no xyz");
    }
    Result<Eigen::Vector3d> axis = parseVector(xyz, kind, name, std::string(tag) + " xyz");
    if (!isOk(axis)) {
      return axis;
    }
    const double norm = valueOf(axis).norm();
    if (norm < tolerances::kZeroVector) {
      return error(kind, name, std::string(tag) + " xyz '" + xyz + "' is the zero vector");
    }
    return (valueOf(axis) / norm).eval();
  }

  /// Reads <link1 link=".." xyz=".." rpy=".."/> (or link2) and resolves the link.
  Result<std::pair<int, Eigen::Isometry3d>> parseEnd(const tinyxml2::XMLElement* element, const char* tag,
                                                     const std::string& kind, const std::string& name,
                                                     const LinkIndex& links) const {
    const tinyxml2::XMLElement* end = element->FirstChildElement(tag);
    if (end == nullptr) {
      return error(kind, name, std::string("missing <") + tag + ">");
    }
    const char* linkName = end->Attribute("link");
    if (linkName == nullptr) {
      return error(kind, name, std::string("<") + tag + "> has no link attribute");
    }
    const auto link = links.find(linkName);
    if (link == links.end()) {
      return error(kind, name, std::string(tag) + " '" + linkName + "' is not a link");
    }
    Result<Eigen::Vector3d> xyz = parseVector(end->Attribute("xyz"), kind, name, std::string(tag) + " xyz");
    if (!isOk(xyz)) {
      return diagnosticOf(xyz);
    }
    Result<Eigen::Vector3d> rpy = parseVector(end->Attribute("rpy"), kind, name, std::string(tag) + " rpy");
    if (!isOk(rpy)) {
      return diagnosticOf(rpy);
    }
    // URDF fixed-axis roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll).
    Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
    frame.linear() = (Eigen::AngleAxisd(valueOf(rpy).z(), Eigen::Vector3d::UnitZ()) *
                      Eigen::AngleAxisd(valueOf(rpy).y(), Eigen::Vector3d::UnitY()) *
                      Eigen::AngleAxisd(valueOf(rpy).x(), Eigen::Vector3d::UnitX()))
                         .toRotationMatrix();
    frame.translation() = valueOf(xyz);
    return std::make_pair(link->second, frame);
  }

 private:
  std::string file_;
};

Result<JointType> parseLoopJointType(const char* text) {
  const std::string type = text == nullptr ? "" : text;
  if (type == "revolute")
    return JointType::Revolute;
  if (type == "continuous")
    return JointType::Continuous;
  if (type == "prismatic")
    return JointType::Prismatic;
  if (type == "cylindrical")
    return JointType::Cylindrical;
  if (type == "spherical")
    return JointType::Spherical;
  if (type == "universal")
    return JointType::Universal;
  if (type == "fixed")
    return JointType::Fixed;
  return Diagnostic{};
}

std::string baseName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

Eigen::Isometry3d toIsometry(const urdf::Pose& pose) {
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.linear() = Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
                       .normalized()
                       .toRotationMatrix();
  frame.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  return frame;
}

/// Checks the <link>/<joint> tree before urdfdom sees it, so every problem gets a name.
Result<Mechanism> readTree(const tinyxml2::XMLElement* robot, const LoopElementReader& reader,
                           const std::string& file) {
  Mechanism mechanism;
  mechanism.file = file;
  const char* robotName = robot->Attribute("name");
  mechanism.name = robotName == nullptr ? "" : robotName;
  LinkIndex index;
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement("link"); e;
       e = e->NextSiblingElement("link")) {
    const char* name = e->Attribute("name");
    if (name == nullptr || std::string(name).empty()) {
      return reader.error("link", "", "has no name");
    }
    if (!index.emplace(name, static_cast<int>(mechanism.links.size())).second) {
      return reader.error("link", name, "is defined twice");
    }
    mechanism.links.push_back(Link{name});
  }
  auto findLink = [&](const char* name) -> std::optional<int> {
    const auto it = index.find(name);
    return it == index.end() ? std::nullopt : std::optional<int>(it->second);
  };
  if (mechanism.links.empty()) {
    return reader.error("robot", mechanism.name, "has no <link>");
  }
  std::vector<int> parentOf(mechanism.links.size(), -1);
  std::set<std::string> names;
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement("joint"); e;
       e = e->NextSiblingElement("joint")) {
    const char* name = e->Attribute("name");
    if (name == nullptr || std::string(name).empty()) {
      return reader.error("joint", "", "has no name");
    }
    if (!names.insert(name).second) {
      return reader.error("joint", name, "is defined twice");
    }
    const tinyxml2::XMLElement* parent = e->FirstChildElement("parent");
    const tinyxml2::XMLElement* child = e->FirstChildElement("child");
    if (parent == nullptr || parent->Attribute("link") == nullptr) {
      return reader.error("joint", name, "has no <parent link=\"...\">");
    }
    if (child == nullptr || child->Attribute("link") == nullptr) {
      return reader.error("joint", name, "has no <child link=\"...\">");
    }
    const std::optional<int> parentLink = findLink(parent->Attribute("link"));
    const std::optional<int> childLink = findLink(child->Attribute("link"));
    if (!parentLink) {
      return reader.error("joint", name,
                          std::string("parent '") + parent->Attribute("link") + "' is not a link");
    }
    if (!childLink) {
      return reader.error("joint", name,
                          std::string("child '") + child->Attribute("link") + "' is not a link");
    }
    if (*parentLink == *childLink) {
      return reader.error("joint", name, "joins link '" + mechanism.links[*childLink].name + "' to itself");
    }
    if (parentOf[*childLink] >= 0) {
      return reader.error("joint", name,
                          "link '" + mechanism.links[*childLink].name +
                              "' already has a parent joint; close loops with <loop_joint>");
    }
    const char* type = e->Attribute("type");
    const std::string typeText = type == nullptr ? "" : type;
    static const std::set<std::string> kTreeTypes = {"revolute", "continuous", "prismatic",
                                                     "fixed",    "floating",   "planar"};
    if (kTreeTypes.count(typeText) == 0) {
      return reader.error(
          "joint", name,
          "type '" + typeText +
              "' is not a URDF tree type (revolute, continuous, prismatic, fixed, floating, planar)");
    }
    if (const tinyxml2::XMLElement* origin = e->FirstChildElement("origin")) {
      for (const char* attribute : {"xyz", "rpy"}) {
        Result<Eigen::Vector3d> v = reader.parseVector(origin->Attribute(attribute), "joint", name,
                                                       std::string("origin ") + attribute);
        if (!isOk(v)) {
          return diagnosticOf(v);
        }
      }
    }
    if (typeText != "fixed" && typeText != "floating") {
      Result<Eigen::Vector3d> axis = reader.parseAxis(e, "axis", "joint", name);
      if (!isOk(axis)) {
        return diagnosticOf(axis);
      }
    }
    parentOf[*childLink] = *parentLink;
    Joint joint;
    joint.name = name;
    joint.kind = ConnectionKind::TreeJoint;
    joint.link1 = *parentLink;
    joint.link2 = *childLink;
    mechanism.joints.push_back(joint);
  }
  // Exactly one root, and every link reaches it.
  int root = -1;
  for (size_t i = 0; i < mechanism.links.size(); ++i) {
    if (parentOf[i] < 0) {
      if (root >= 0) {
        return reader.error("link", mechanism.links[i].name,
                            "is not connected to the ground '" + mechanism.links[root].name +
                                "' by the <joint> tree (two roots)");
      }
      root = static_cast<int>(i);
    }
  }
  if (root < 0) {
    return reader.error("robot", mechanism.name, "the <joint> elements form a cycle; there is no root link");
  }
  // Walk each link up until a link known to reach the root: every link is walked once (a chain of 10^5 links
  // would otherwise cost 10^10 steps).
  enum : char { kUnknown, kOnPath, kReachesRoot };
  std::vector<char> state(mechanism.links.size(), kUnknown);
  state[root] = kReachesRoot;
  std::vector<int> path;
  for (size_t i = 0; i < mechanism.links.size(); ++i) {
    path.clear();
    int link = static_cast<int>(i);
    while (state[link] == kUnknown) {
      state[link] = kOnPath;
      path.push_back(link);
      link = parentOf[link];
    }
    if (state[link] == kOnPath) {
      return reader.error("link", mechanism.links[i].name, "is on a cycle of <joint> elements");
    }
    for (int l : path)
      state[l] = kReachesRoot;
  }
  mechanism.rootLink = root;
  return mechanism;
}

/// Fills the tree joints' origins, axes and types from urdfdom's model.
Result<Mechanism> readTreeJointsFromUrdfdom(Mechanism mechanism, const std::string& urdfText,
                                            const LoopElementReader& reader) {
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(urdfText);
  if (!model) {
    return reader.error("robot", mechanism.name, "urdfdom rejected the <link>/<joint> tree");
  }
  for (Joint& joint : mechanism.joints) {
    if (joint.kind != ConnectionKind::TreeJoint) {
      continue;
    }
    const urdf::JointConstSharedPtr urdfJoint = model->getJoint(joint.name);
    if (!urdfJoint) {
      return reader.error("joint", joint.name, "was not read by urdfdom");
    }
    switch (urdfJoint->type) {
      case urdf::Joint::REVOLUTE:
        joint.type = JointType::Revolute;
        break;
      case urdf::Joint::CONTINUOUS:
        joint.type = JointType::Continuous;
        break;
      case urdf::Joint::PRISMATIC:
        joint.type = JointType::Prismatic;
        break;
      case urdf::Joint::FLOATING:
        joint.type = JointType::Floating;
        break;
      case urdf::Joint::PLANAR:
        joint.type = JointType::Planar;
        break;
      case urdf::Joint::FIXED:
        joint.type = JointType::Fixed;
        break;
      default:
        return reader.error("joint", joint.name, "has an unknown type");
    }
    joint.frame1 = toIsometry(urdfJoint->parent_to_joint_origin_transform);
    joint.frame2 = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d axis(urdfJoint->axis.x, urdfJoint->axis.y, urdfJoint->axis.z);
    if (axis.norm() > tolerances::kZeroVector) {
      joint.axis = axis.normalized();
    }
  }
  return mechanism;
}

}  // namespace

Result<Mechanism> loadMechanismFromString(const std::string& urdfText, const std::string& fileName) {
  const std::string file = baseName(fileName);
  const LoopElementReader reader(file);
  tinyxml2::XMLDocument document;
  if (document.Parse(urdfText.c_str(), urdfText.size()) != tinyxml2::XML_SUCCESS) {
    return reader.error("xml", "", std::string("not well-formed XML: ") + document.ErrorStr());
  }
  const tinyxml2::XMLElement* robot = document.FirstChildElement("robot");
  if (robot == nullptr) {
    return reader.error("xml", "", "the root element is not <robot>");
  }
  Result<Mechanism> tree = readTree(robot, reader, file);
  if (!isOk(tree)) {
    return tree;
  }
  Result<Mechanism> withTree = readTreeJointsFromUrdfdom(valueOf(std::move(tree)), urdfText, reader);
  if (!isOk(withTree)) {
    return withTree;
  }
  Mechanism mechanism = valueOf(std::move(withTree));
  LinkIndex links;
  for (size_t l = 0; l < mechanism.links.size(); ++l)
    links.emplace(mechanism.links[l].name, static_cast<int>(l));

  std::set<std::string> names;
  for (const Joint& joint : mechanism.joints) {
    names.insert(joint.name);
  }
  auto readEnds = [&](const tinyxml2::XMLElement* e, const std::string& kind,
                      Joint& joint) -> std::optional<Diagnostic> {
    for (int side = 1; side <= 2; ++side) {
      Result<std::pair<int, Eigen::Isometry3d>> end =
          reader.parseEnd(e, side == 1 ? "link1" : "link2", kind, joint.name, links);
      if (!isOk(end)) {
        return diagnosticOf(end);
      }
      (side == 1 ? joint.link1 : joint.link2) = valueOf(end).first;
      (side == 1 ? joint.frame1 : joint.frame2) = valueOf(end).second;
    }
    if (joint.link1 == joint.link2) {
      return reader.error(kind, joint.name,
                          "joins link '" + mechanism.links[joint.link1].name + "' to itself");
    }
    return std::nullopt;
  };
  auto readName = [&](const tinyxml2::XMLElement* e, const std::string& kind) -> Result<std::string> {
    const char* name = e->Attribute("name");
    if (name == nullptr || std::string(name).empty()) {
      return reader.error(kind, "", "has no name");
    }
    if (!names.insert(name).second) {
      return reader.error(kind, name, "has the name of another joint or constraint");
    }
    return std::string(name);
  };

  // Equation order of DESIGN.md §3: tree joints, distance constraints, (cables), loop joints.
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement("distance_constraint"); e;
       e = e->NextSiblingElement("distance_constraint")) {
    Result<std::string> name = readName(e, "distance_constraint");
    if (!isOk(name))
      return diagnosticOf(name);
    Joint joint;
    joint.name = valueOf(name);
    joint.kind = ConnectionKind::DistanceConstraint;
    joint.type = JointType::Spherical;
    if (std::optional<Diagnostic> d = readEnds(e, "distance_constraint", joint))
      return *d;
    mechanism.joints.push_back(joint);
  }
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement("cable"); e;
       e = e->NextSiblingElement("cable")) {
    Result<std::string> name = readName(e, "cable");
    if (!isOk(name))
      return diagnosticOf(name);
    Joint joint;
    joint.name = valueOf(name);
    joint.kind = ConnectionKind::Cable;
    joint.type = JointType::Spherical;
    const char* type = e->Attribute("type");
    const std::string typeText = type == nullptr ? "passive" : type;
    if (typeText != "passive" && typeText != "active") {
      return reader.error("cable", joint.name, "type '" + typeText + "' is neither passive nor active");
    }
    joint.cableType = typeText == "active" ? CableType::Active : CableType::Passive;
    Result<double> length = reader.parseNumber(e->Attribute("length"), "cable", joint.name, "length");
    if (!isOk(length))
      return diagnosticOf(length);
    if (valueOf(length) <= 0.0) {
      return reader.error("cable", joint.name,
                          "length must be positive, got " + std::string(e->Attribute("length")));
    }
    joint.length = valueOf(length);
    if (std::optional<Diagnostic> d = readEnds(e, "cable", joint))
      return *d;
    mechanism.joints.push_back(joint);
  }
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement("loop_joint"); e;
       e = e->NextSiblingElement("loop_joint")) {
    Result<std::string> name = readName(e, "loop_joint");
    if (!isOk(name))
      return diagnosticOf(name);
    Joint joint;
    joint.name = valueOf(name);
    joint.kind = ConnectionKind::LoopJoint;
    Result<JointType> type = parseLoopJointType(e->Attribute("type"));
    if (!isOk(type)) {
      const char* typeText = e->Attribute("type");
      return reader.error(
          "loop_joint", joint.name,
          std::string("type '") + (typeText ? typeText : "") +
              "' is not one of revolute, continuous, prismatic, cylindrical, spherical, universal, fixed");
    }
    joint.type = valueOf(type);
    if (std::optional<Diagnostic> d = readEnds(e, "loop_joint", joint))
      return *d;
    Result<Eigen::Vector3d> axis = reader.parseAxis(e, "axis", "loop_joint", joint.name);
    if (!isOk(axis))
      return diagnosticOf(axis);
    joint.axis = valueOf(axis);
    Result<Eigen::Vector3d> axis2 = reader.parseAxis(e, "axis2", "loop_joint", joint.name);
    if (!isOk(axis2))
      return diagnosticOf(axis2);
    joint.axis2 = valueOf(axis2);
    if (joint.type == JointType::Universal &&
        joint.axis.cross(joint.axis2).norm() < tolerances::kPlanarAxis) {
      return reader.error("loop_joint", joint.name, "universal joint axes 'axis' and 'axis2' are parallel");
    }
    mechanism.joints.push_back(joint);
  }
  return mechanism;
}

Result<Mechanism> loadMechanismFromFile(const std::string& path) {
  std::ifstream stream(path);
  if (!stream) {
    return makeDiagnostic(path, "", "", "cannot open the file");
  }
  std::stringstream text;
  text << stream.rdbuf();
  return loadMechanismFromString(text.str(), path);
}

Result<JointPositions> makeJointPositions(const std::vector<std::string>& names,
                                          const std::vector<double>& values, const Mechanism& mechanism) {
  if (names.size() != values.size()) {
    return makeDiagnostic(
        mechanism.file, "positions", "",
        std::to_string(values.size()) + " values for " + std::to_string(names.size()) + " joint_names");
  }
  JointPositions positions;
  for (size_t i = 0; i < names.size(); ++i) {
    const std::optional<int> joint = mechanism.findJoint(names[i]);
    if (!joint) {
      return makeDiagnostic(mechanism.file, "positions", names[i],
                            "is not a joint of '" + mechanism.name + "'");
    }
    const Joint& j = mechanism.joints[*joint];
    const bool singleValue =
        j.kind == ConnectionKind::TreeJoint &&
        (j.type == JointType::Revolute || j.type == JointType::Continuous || j.type == JointType::Prismatic);
    if (!singleValue) {
      return makeDiagnostic(mechanism.file, "positions", names[i],
                            std::string("is a ") + toString(j.kind) + " of type " + toString(j.type) +
                                "; only revolute, continuous and prismatic tree joints take a position");
    }
    if (!std::isfinite(values[i])) {
      return makeDiagnostic(mechanism.file, "positions", names[i], "value is not finite");
    }
    if (!positions.emplace(names[i], values[i]).second) {
      return makeDiagnostic(mechanism.file, "positions", names[i], "is given twice");
    }
  }
  return positions;
}

Result<JointPositions> parseJointPositions(const std::string& text, const Mechanism& mechanism) {
  std::vector<std::string> names;
  std::vector<double> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    if (item.empty()) {
      continue;
    }
    const size_t equals = item.find('=');
    if (equals == std::string::npos) {
      return makeDiagnostic(mechanism.file, "positions", item, "expected NAME=VALUE");
    }
    const std::string name = item.substr(0, equals);
    const std::string valueText = item.substr(equals + 1);
    char* end = nullptr;
    const double value = std::strtod(valueText.c_str(), &end);
    if (valueText.empty() || *end != '\0') {
      return makeDiagnostic(mechanism.file, "positions", name, "value '" + valueText + "' is not a number");
    }
    names.push_back(name);
    values.push_back(value);
  }
  return makeJointPositions(names, values, mechanism);
}

}  // namespace mobility_analysis
