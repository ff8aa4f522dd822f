#include "mobility_analysis/io/UrdfReader.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <initializer_list>

#include <tinyxml2.h>

#include "NameIndex.hpp"
#include "XmlValues.hpp"
#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

using io_detail::checkRange;
using io_detail::makeFrame;
using io_detail::parseDouble;

/// A refusal inside the reader: thrown at the check that fails, caught in readUrdf and returned as its
/// Diagnostic, so no exception leaves this file (STYLE.md §4) and the ~40 checks stay one line each.
struct ReadFailure {
  Diagnostic diagnostic;
};

/// Top-level elements that carry nothing for mobility and are well known: skipped without a warning.
constexpr std::array<const char*, 6> kIgnoredElements = {
    "gazebo", "transmission", "ros2_control", "material", "sensor", "drake:collision_filter_group"};

/// Top-level elements this reader understands, in the order of their kinds (TopLevel).
constexpr std::array<const char*, 7> kReadElements = {
    "link", "joint", "distance_constraint", "cable", "loop_joint", "loop", "coupling"};

/// What a top-level element is: its index in kReadElements, kIgnored or kUnknown.
enum TopLevel : int { kLink, kJoint, kDistance, kCable, kLoopJoint, kLoop, kCoupling, kIgnored, kUnknown };

TopLevel classify(const char* tag) {
  for (size_t i = 0; i < kReadElements.size(); ++i) {
    if (std::strcmp(tag, kReadElements[i]) == 0)
      return static_cast<TopLevel>(i);
  }
  for (const char* ignored : kIgnoredElements) {
    if (std::strcmp(tag, ignored) == 0)
      return kIgnored;
  }
  return kUnknown;
}

/// kReadElements in alphabetical order: the order the "did you mean" hints are given in.
constexpr std::array<const char*, 7> kKnownSorted = {"cable", "coupling", "distance_constraint", "joint",
                                                     "link",  "loop",     "loop_joint"};

/// Blanks as `std::istream >> std::string` splits on them (the "C" locale's isspace).
bool isBlank(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r';
}

/// @return @p name lower-cased without '_', '-' and ':', so a misspelt `<loopjoint>` can be pointed at.
std::string squashed(const std::string& name) {
  std::string out;
  for (char c : name) {
    if (c != '_' && c != '-' && c != ':')
      out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return out;
}

const char* loopTypeList = "revolute, continuous, prismatic, cylindrical, spherical, universal, fixed";

/// The type spelled @p type among @p allowed, by the dialect's spelling (toString(JointType)).
std::optional<JointType> parseJointType(const std::string& type, std::initializer_list<JointType> allowed) {
  for (const JointType candidate : allowed) {
    if (type == toString(candidate))
      return candidate;
  }
  return std::nullopt;
}

/// Loop elements take every type of the dialect but the URDF tree's own planar and floating.
std::optional<JointType> parseLoopType(const std::string& type) {
  return parseJointType(
      type, {JointType::Revolute, JointType::Continuous, JointType::Prismatic, JointType::Cylindrical,
             JointType::Spherical, JointType::Universal, JointType::Fixed});
}

/// Tree joints take URDF's types.
std::optional<JointType> parseTreeType(const std::string& type) {
  return parseJointType(type, {JointType::Revolute, JointType::Continuous, JointType::Prismatic,
                               JointType::Fixed, JointType::Floating, JointType::Planar});
}

bool needsAxis(JointType type) {
  return type == JointType::Revolute || type == JointType::Continuous || type == JointType::Prismatic ||
         type == JointType::Cylindrical || type == JointType::Universal;
}

bool isOneFreedom(const Joint& joint) {
  return joint.kind == ConnectionKind::TreeJoint &&
         (joint.type == JointType::Revolute || joint.type == JointType::Continuous ||
          joint.type == JointType::Prismatic);
}

/// A coupling as written, resolved once every tree joint is known.
struct PendingCoupling {
  std::string name;
  std::string kind;  ///< "joint" (a mimic) or "coupling", for diagnostics.
  std::string leader, follower;
  double multiplier = 1.0;
  double offset = 0.0;
};

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) { mechanism_.file = file_; }

  Mechanism read(const tinyxml2::XMLElement* robot) {
    const char* robotName = robot->Attribute("name");
    mechanism_.name = robotName == nullptr ? "" : robotName;
    // One walk over the top-level elements sorts them by kind (document order within each kind) and warns
    // about the unknown ones; each kind is then read in the equation order of DESIGN.md §3.
    std::array<std::vector<const tinyxml2::XMLElement*>, kIgnored> byKind;
    for (const tinyxml2::XMLElement* e = robot->FirstChildElement(); e; e = e->NextSiblingElement()) {
      const TopLevel kind = classify(e->Name());
      if (kind == kUnknown)
        warnUnknown(e);
      else if (kind != kIgnored)
        byKind[kind].push_back(e);
    }
    mechanism_.links.reserve(byKind[kLink].size());
    linkIndex_.reserve(byKind[kLink].size());
    size_t connections = 0;
    for (int kind = kJoint; kind < kIgnored; ++kind)
      connections += byKind[kind].size();
    mechanism_.joints.reserve(connections);
    connectionIndex_.reserve(connections);
    readLinks(byKind[kLink]);
    readTreeJoints(byKind[kJoint]);
    checkTree();
    for (const tinyxml2::XMLElement* e : byKind[kDistance])
      readTwoEnded(e, ConnectionKind::DistanceConstraint);
    for (const tinyxml2::XMLElement* e : byKind[kCable])
      readTwoEnded(e, ConnectionKind::Cable);
    // <loop_joint> and <loop> in document order, mixed.
    std::vector<const tinyxml2::XMLElement*>& loops = byKind[kLoopJoint];
    if (!byKind[kLoop].empty()) {
      loops.clear();
      for (const tinyxml2::XMLElement* e = robot->FirstChildElement(); e; e = e->NextSiblingElement()) {
        const TopLevel kind = classify(e->Name());
        if (kind == kLoopJoint || kind == kLoop)
          loops.push_back(e);
      }
    }
    for (const tinyxml2::XMLElement* e : loops)
      readLoop(e);
    for (const tinyxml2::XMLElement* e : byKind[kCoupling])
      readCoupling(e);
    for (const PendingCoupling& coupling : couplings_)
      addCoupling(coupling);
    return std::move(mechanism_);
  }

 private:
  [[noreturn]] void fail(const std::string& kind, const std::string& name, const std::string& what) const {
    throw ReadFailure{makeDiagnostic(file_, kind, name, what)};
  }

  void warn(const std::string& kind, const std::string& name, const std::string& what) {
    mechanism_.warnings.push_back(makeDiagnostic(file_, kind, name, what));
  }

  double number(const char* text, const std::string& kind, const std::string& name,
                const std::string& attribute) const {
    if (text == nullptr)
      fail(kind, name, "missing attribute " + attribute);
    const std::optional<double> value = parseDouble(text);
    if (!value)
      fail(kind, name, attribute + " '" + text + "' is not a number");
    if (const std::optional<std::string> why = checkRange(*value))
      fail(kind, name, attribute + " '" + text + "' " + *why);
    return *value;
  }

  /// "a b c": exactly three finite numbers within range; absent: zero.
  Eigen::Vector3d vector(const char* text, const std::string& kind, const std::string& name,
                         const std::string& attribute) const {
    if (text == nullptr)
      return Eigen::Vector3d::Zero();
    Eigen::Vector3d v;
    int count = 0;
    const char* at = text;
    while (true) {
      while (isBlank(*at))
        ++at;
      if (*at == '\0')
        break;
      const char* tokenEnd = at;
      while (*tokenEnd != '\0' && !isBlank(*tokenEnd))
        ++tokenEnd;
      if (count == 3)
        fail(kind, name, attribute + " has more than 3 numbers: '" + text + "'");
      // A number is the whole token (strtod never reads a blank, so it cannot run past the token).
      char* end = nullptr;
      const double value = std::strtod(at, &end);
      if (end != tokenEnd) {
        fail(kind, name,
             attribute + " '" + text + "' is not a number triple ('" + std::string(at, tokenEnd) + "')");
      }
      if (const std::optional<std::string> why = checkRange(value))
        fail(kind, name, attribute + " '" + text + "' " + *why);
      v[count++] = value;
      at = tokenEnd;
    }
    if (count != 3)
      fail(kind, name, attribute + " needs 3 numbers, got " + std::to_string(count) + ": '" + text + "'");
    return v;
  }

  Eigen::Isometry3d frame(const tinyxml2::XMLElement* e, const std::string& kind, const std::string& name,
                          const std::string& what) const {
    if (e == nullptr)
      return Eigen::Isometry3d::Identity();
    return makeFrame(vector(e->Attribute("xyz"), kind, name, what + " xyz"),
                     vector(e->Attribute("rpy"), kind, name, what + " rpy"));
  }

  /// The unit axis of <tag xyz>; @p fallback when the element is absent.
  Eigen::Vector3d axis(const tinyxml2::XMLElement* parent, const char* tag, const std::string& kind,
                       const std::string& name, const Eigen::Vector3d& fallback) const {
    const tinyxml2::XMLElement* element = parent->FirstChildElement(tag);
    if (element == nullptr)
      return fallback;
    const char* xyz = element->Attribute("xyz");
    if (xyz == nullptr)
      fail(kind, name, std::string("<") + tag + "> has no xyz");
    const Eigen::Vector3d v = vector(xyz, kind, name, std::string(tag) + " xyz");
    if (v.norm() < tolerances::kZeroVector)
      fail(kind, name, std::string(tag) + " xyz '" + xyz + "' is the zero vector");
    return v.normalized();
  }

  std::string elementName(const tinyxml2::XMLElement* e, const std::string& kind) const {
    const char* name = e->Attribute("name");
    if (name == nullptr || *name == '\0')
      fail(kind, "", "has no name");
    return name;
  }

  int link(const char* name, const std::string& kind, const std::string& element,
           const std::string& role) const {
    if (name == nullptr)
      fail(kind, element, "<" + role + "> has no link attribute");
    const int index = linkIndex_.find(name, mechanism_.links);
    if (index < 0)
      fail(kind, element, role + " '" + name + "' is not a link");
    return index;
  }

  /// Warns about every child of a loop element that is not in @p known, and about a repeated known child.
  void checkChildren(const tinyxml2::XMLElement* e, const std::string& kind, const std::string& name,
                     std::initializer_list<const char*> known) {
    unsigned seen = 0;  // bit i: known[i] met
    for (const tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
      const char* tag = c->Name();
      unsigned bit = 0;
      for (size_t i = 0; i < known.size(); ++i) {
        if (std::strcmp(tag, known.begin()[i]) == 0)
          bit = 1u << i;
      }
      if (bit == 0) {
        warn(kind, name, "unknown child <" + std::string(tag) + "> is not read");
      } else if ((seen & bit) != 0) {
        warn(kind, name, "has more than one <" + std::string(tag) + ">; the first is read");
      }
      seen |= bit;
    }
  }

  void warnUnknown(const tinyxml2::XMLElement* e) {
    const std::string tag = e->Name();
    const char* name = e->Attribute("name");
    std::string what = "unknown element <" + tag + "> is not read";
    for (const std::string known : kKnownSorted) {
      if (squashed(known) == squashed(tag))
        what += " (did you mean <" + known + ">?)";
    }
    if (tag == "loop_constraint")
      what += " (the URDF+ form <loop> with <predecessor>/<successor> is read)";
    warn(tag, name == nullptr ? "" : name, what);
  }

  void readLinks(const std::vector<const tinyxml2::XMLElement*>& elements) {
    for (const tinyxml2::XMLElement* e : elements) {
      const char* name = e->Attribute("name");
      if (name == nullptr || *name == '\0')
        fail("link", "", "has no name");
      if (linkIndex_.find(name, mechanism_.links) >= 0)
        fail("link", name, "is defined twice");
      linkIndex_.insert(name, static_cast<int>(mechanism_.links.size()));
      mechanism_.links.push_back(Link{std::string(name)});
    }
    if (mechanism_.links.empty())
      fail("robot", mechanism_.name, "has no <link>");
  }

  /// Refuses @p name when a connection has it already (the connection itself is added by addConnection).
  void claimName(const std::string& kind, const std::string& name) const {
    if (connectionIndex_.find(name, mechanism_.joints) >= 0)
      fail(kind, name, kind == "joint" ? "is defined twice" : "has the name of another joint or constraint");
  }

  /// Appends @p joint to the mechanism's connections, and its name to their index.
  void addConnection(Joint&& joint) {
    connectionIndex_.insert(joint.name, static_cast<int>(mechanism_.joints.size()));
    mechanism_.joints.push_back(std::move(joint));
  }

  void readTreeJoints(const std::vector<const tinyxml2::XMLElement*>& elements) {
    parentOf_.assign(mechanism_.links.size(), -1);
    for (const tinyxml2::XMLElement* e : elements) {
      std::string name = elementName(e, "joint");
      claimName("joint", name);
      const tinyxml2::XMLElement* parent = e->FirstChildElement("parent");
      const tinyxml2::XMLElement* child = e->FirstChildElement("child");
      if (parent == nullptr || parent->Attribute("link") == nullptr)
        fail("joint", name, "has no <parent link=\"...\">");
      if (child == nullptr || child->Attribute("link") == nullptr)
        fail("joint", name, "has no <child link=\"...\">");
      const int parentLink = link(parent->Attribute("link"), "joint", name, "parent");
      const int childLink = link(child->Attribute("link"), "joint", name, "child");
      if (parentLink == childLink)
        fail("joint", name, "joins link '" + mechanism_.links[childLink].name + "' to itself");
      if (parentOf_[childLink] >= 0) {
        fail("joint", name,
             "link '" + mechanism_.links[childLink].name +
                 "' already has a parent joint; close loops with <loop_joint>");
      }
      const char* type = e->Attribute("type");
      const std::optional<JointType> jointType = parseTreeType(type == nullptr ? "" : type);
      if (!jointType) {
        fail("joint", name,
             "type '" + std::string(type == nullptr ? "" : type) +
                 "' is not a URDF tree type (revolute, continuous, prismatic, fixed, floating, planar)");
      }
      Joint joint;
      joint.kind = ConnectionKind::TreeJoint;
      joint.type = *jointType;
      joint.link1 = parentLink;
      joint.link2 = childLink;
      if (const tinyxml2::XMLElement* origin = e->FirstChildElement("origin")) {
        joint.frame1 =
            io_detail::makeOriginFrame(vector(origin->Attribute("xyz"), "joint", name, "origin xyz"),
                                       vector(origin->Attribute("rpy"), "joint", name, "origin rpy"));
      }
      if (joint.type != JointType::Fixed && joint.type != JointType::Floating) {
        // URDF's default, but a forgotten axis turns a planar linkage spatial: said, never silent.
        if (e->FirstChildElement("axis") == nullptr) {
          warn("joint", name,
               std::string("type ") + toString(joint.type) +
                   " has no <axis>; axis defaulted to 1 0 0 (URDF's default)");
        }
        joint.axis = axis(e, "axis", "joint", name, Eigen::Vector3d::UnitX());
      }
      if (const tinyxml2::XMLElement* mimic = e->FirstChildElement("mimic")) {
        PendingCoupling coupling;
        coupling.name = "mimic_" + name;
        coupling.kind = "joint";
        coupling.follower = name;
        const char* leader = mimic->Attribute("joint");
        if (leader == nullptr)
          fail("joint", name, "<mimic> has no joint attribute");
        coupling.leader = leader;
        if (mimic->Attribute("multiplier"))
          coupling.multiplier = number(mimic->Attribute("multiplier"), "joint", name, "mimic multiplier");
        if (mimic->Attribute("offset"))
          coupling.offset = number(mimic->Attribute("offset"), "joint", name, "mimic offset");
        couplings_.push_back(std::move(coupling));
      }
      parentOf_[childLink] = parentLink;
      joint.name = std::move(name);
      addConnection(std::move(joint));
    }
  }

  /// Exactly one root, and every link reaches it; iterative, each link walked once.
  void checkTree() {
    int root = -1;
    for (size_t i = 0; i < mechanism_.links.size(); ++i) {
      if (parentOf_[i] >= 0)
        continue;
      if (root >= 0) {
        fail("link", mechanism_.links[i].name,
             "is not connected to the ground '" + mechanism_.links[root].name +
                 "' by the <joint> tree (two roots)");
      }
      root = static_cast<int>(i);
    }
    if (root < 0)
      fail("robot", mechanism_.name, "the <joint> elements form a cycle; there is no root link");
    enum : char { kUnknown, kOnPath, kReachesRoot };
    std::vector<char> state(mechanism_.links.size(), kUnknown);
    state[root] = kReachesRoot;
    std::vector<int> path;
    for (size_t i = 0; i < mechanism_.links.size(); ++i) {
      path.clear();
      int l = static_cast<int>(i);
      while (state[l] == kUnknown) {
        state[l] = kOnPath;
        path.push_back(l);
        l = parentOf_[l];
      }
      if (state[l] == kOnPath)
        fail("link", mechanism_.links[i].name, "is on a cycle of <joint> elements");
      for (int p : path)
        state[p] = kReachesRoot;
    }
    mechanism_.rootLink = root;
  }

  /// One end of a loop element: <tag link xyz rpy/> (our dialect) or <tag link><origin xyz rpy/></tag>
  /// (URDF+).
  std::pair<int, Eigen::Isometry3d> end(const tinyxml2::XMLElement* e, const char* tag,
                                        const std::string& kind, const std::string& name) const {
    const tinyxml2::XMLElement* endElement = e->FirstChildElement(tag);
    if (endElement == nullptr)
      fail(kind, name, std::string("missing <") + tag + ">");
    const int l = link(endElement->Attribute("link"), kind, name, tag);
    const tinyxml2::XMLElement* origin = endElement->FirstChildElement("origin");
    if (origin != nullptr)
      return {l, frame(origin, kind, name, std::string(tag) + " origin")};
    return {l, makeFrame(vector(endElement->Attribute("xyz"), kind, name, std::string(tag) + " xyz"),
                         vector(endElement->Attribute("rpy"), kind, name, std::string(tag) + " rpy"))};
  }

  void readEnds(const tinyxml2::XMLElement* e, const char* tag1, const char* tag2, const std::string& kind,
                Joint& joint) const {
    std::tie(joint.link1, joint.frame1) = end(e, tag1, kind, joint.name);
    std::tie(joint.link2, joint.frame2) = end(e, tag2, kind, joint.name);
    if (joint.link1 == joint.link2)
      fail(kind, joint.name, "joins link '" + mechanism_.links[joint.link1].name + "' to itself");
  }

  void readTwoEnded(const tinyxml2::XMLElement* e, ConnectionKind kind) {
    const std::string kindName = toString(kind);
    Joint joint;
    joint.name = elementName(e, kindName);
    claimName(kindName, joint.name);
    joint.kind = kind;
    joint.type = JointType::Spherical;
    checkChildren(e, kindName, joint.name, {"link1", "link2"});
    if (kind == ConnectionKind::Cable) {
      const char* type = e->Attribute("type");
      const std::string typeText = type == nullptr ? "passive" : type;
      if (typeText != "passive" && typeText != "active")
        fail("cable", joint.name, "type '" + typeText + "' is neither passive nor active");
      joint.cableType = typeText == "active" ? CableType::Active : CableType::Passive;
      joint.length = number(e->Attribute("length"), "cable", joint.name, "length");
      if (joint.length <= 0.0)
        fail("cable", joint.name, "length must be positive, got " + std::string(e->Attribute("length")));
    }
    readEnds(e, "link1", "link2", kindName, joint);
    addConnection(std::move(joint));
  }

  /// <loop_joint> of our dialect (Isaac Sim, Drake) or URDF+ <loop>: the same connection, two spellings.
  void readLoop(const tinyxml2::XMLElement* e) {
    const std::string kind = e->Name();
    const bool urdfPlus = kind == "loop";
    Joint joint;
    joint.name = elementName(e, kind);
    claimName(kind, joint.name);
    joint.kind = ConnectionKind::LoopJoint;
    const char* type = e->Attribute("type");
    const std::optional<JointType> loopType = parseLoopType(type == nullptr ? "" : type);
    if (!loopType)
      fail(kind, joint.name,
           "type '" + std::string(type == nullptr ? "" : type) + "' is not one of " + loopTypeList);
    joint.type = *loopType;
    if (urdfPlus) {
      checkChildren(e, kind, joint.name, {"predecessor", "successor", "axis", "axis2", "limit", "dynamics"});
      readEnds(e, "predecessor", "successor", kind, joint);
    } else {
      checkChildren(e, kind, joint.name, {"link1", "link2", "axis", "axis2", "limit", "dynamics"});
      readEnds(e, "link1", "link2", kind, joint);
    }
    if (needsAxis(joint.type) && e->FirstChildElement("axis") == nullptr) {
      warn(kind, joint.name,
           std::string("type ") + toString(joint.type) + " has no <axis>; axis defaulted to 1 0 0");
    }
    if (joint.type == JointType::Universal && e->FirstChildElement("axis2") == nullptr) {
      warn(kind, joint.name, "type universal has no <axis2>; axis2 defaulted to 0 1 0");
    }
    joint.axis = axis(e, "axis", kind, joint.name, Eigen::Vector3d::UnitX());
    joint.axis2 = axis(e, "axis2", kind, joint.name, Eigen::Vector3d::UnitY());
    if (joint.type == JointType::Universal && joint.axis.cross(joint.axis2).norm() < tolerances::kPlanarAxis)
      fail(kind, joint.name, "universal joint axes 'axis' and 'axis2' are parallel");
    addConnection(std::move(joint));
  }

  /// URDF+ <coupling>: successor = ratio * predecessor + offset.
  void readCoupling(const tinyxml2::XMLElement* e) {
    PendingCoupling coupling;
    coupling.kind = "coupling";
    coupling.name = elementName(e, "coupling");
    checkChildren(e, "coupling", coupling.name,
                  {"predecessor", "successor", "leader", "follower", "ratio", "offset"});
    auto jointOf = [&](const char* first, const char* second) -> std::string {
      const tinyxml2::XMLElement* c = e->FirstChildElement(first);
      if (c == nullptr)
        c = e->FirstChildElement(second);
      if (c == nullptr)
        fail("coupling", coupling.name,
             std::string("missing <") + first + " joint=\"...\"> (or <" + second + ">)");
      const char* joint = c->Attribute("joint");
      if (joint == nullptr)
        fail("coupling", coupling.name, std::string("<") + c->Name() + "> has no joint attribute");
      return joint;
    };
    coupling.leader = jointOf("predecessor", "leader");
    coupling.follower = jointOf("successor", "follower");
    const tinyxml2::XMLElement* ratio = e->FirstChildElement("ratio");
    if (ratio == nullptr)
      fail("coupling", coupling.name, "missing <ratio value=\"...\">");
    coupling.multiplier = number(ratio->Attribute("value"), "coupling", coupling.name, "ratio value");
    if (const tinyxml2::XMLElement* offset = e->FirstChildElement("offset"))
      coupling.offset = number(offset->Attribute("value"), "coupling", coupling.name, "offset value");
    couplings_.push_back(std::move(coupling));
  }

  void addCoupling(const PendingCoupling& pending) {
    const std::string& element = pending.kind == "joint" ? pending.follower : pending.name;
    auto resolve = [&](const std::string& jointName, const char* role) {
      const int found = connectionIndex_.find(jointName, mechanism_.joints);
      if (found < 0 || mechanism_.joints[found].kind != ConnectionKind::TreeJoint)
        fail(pending.kind, element, std::string(role) + " '" + jointName + "' is not a tree joint");
      if (!isOneFreedom(mechanism_.joints[found])) {
        fail(pending.kind, element,
             std::string(role) + " '" + jointName + "' is " + toString(mechanism_.joints[found].type) +
                 "; only revolute, continuous and prismatic joints can be coupled");
      }
      return found;
    };
    Joint joint;
    joint.name = pending.name;
    claimName("coupling", joint.name);
    joint.kind = ConnectionKind::Coupling;
    joint.leader = resolve(pending.leader, pending.kind == "joint" ? "mimic joint" : "predecessor");
    joint.follower = resolve(pending.follower, "successor");
    if (joint.leader == joint.follower)
      fail(pending.kind, element, "couples joint '" + pending.leader + "' to itself");
    joint.type = mechanism_.joints[joint.follower].type;
    joint.link1 = mechanism_.joints[joint.follower].link2;
    joint.link2 = mechanism_.joints[joint.leader].link2;
    joint.multiplier = pending.multiplier;
    joint.offset = pending.offset;
    addConnection(std::move(joint));
  }

  std::string file_;
  Mechanism mechanism_;
  io_detail::NameIndex linkIndex_;        ///< Link index by name.
  io_detail::NameIndex connectionIndex_;  ///< Connection index (into mechanism_.joints) by name.
  std::vector<int> parentOf_;
  std::vector<PendingCoupling> couplings_;
};

}  // namespace

namespace {

/// The mechanism of a parsed document (@p parsed: the parser's answer).
Result<Mechanism> readDocument(const tinyxml2::XMLDocument& document, tinyxml2::XMLError parsed,
                               const std::string& file) {
  if (parsed != tinyxml2::XML_SUCCESS) {
    const char* error = document.ErrorStr();
    return makeDiagnostic(file, "xml", "", std::string("not well-formed XML: ") + (error ? error : "?"));
  }
  const tinyxml2::XMLElement* robot = document.FirstChildElement("robot");
  if (robot == nullptr)
    return makeDiagnostic(file, "xml", "", "the root element is not <robot>");
  try {
    return Reader(file).read(robot);
  } catch (const ReadFailure& failure) {
    return failure.diagnostic;
  }
}

}  // namespace

Result<Mechanism> readUrdf(const std::string& urdfText, const std::string& fileName) {
  tinyxml2::XMLDocument document;
  const tinyxml2::XMLError parsed = document.Parse(urdfText.c_str(), urdfText.size());
  return readDocument(document, parsed, io_detail::baseName(fileName));
}

Result<Mechanism> readUrdfFile(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr)
    return makeDiagnostic(path, "", "", "cannot open the file");
  tinyxml2::XMLDocument document;
  const tinyxml2::XMLError parsed = document.LoadFile(file);
  std::fclose(file);
  if (parsed == tinyxml2::XML_ERROR_FILE_READ_ERROR || parsed == tinyxml2::XML_ERROR_FILE_COULD_NOT_BE_OPENED)
    return makeDiagnostic(path, "", "", "cannot open the file");  // a directory, an unreadable file
  return readDocument(document, parsed, io_detail::baseName(path));
}

}  // namespace mobility_analysis
