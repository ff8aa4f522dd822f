#include "mobility_analysis/io/UrdfReader.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <optional>
#include <string_view>

#include <pugixml.hpp>

#include "../SideTask.hpp"
#include "NameIndex.hpp"
#include "RefusalLine.hpp"
#include "UrdfHalves.hpp"
#include "XmlHalves.hpp"
#include "XmlValues.hpp"
#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

using io_detail::checkRange;
using io_detail::makeFrame;
using io_detail::parseDouble;
using io_detail::parseNumber;

/// A node of the parsed document (pugixml's handle: one pointer, passed by value).
using Element = pugi::xml_node;

/// The value of attribute @p name of @p e, nullptr when @p e has none.
const char* attributeOf(Element e, const char* name) {
  const pugi::xml_attribute a = e.attribute(name);
  return a ? a.value() : nullptr;
}

/// The first child of @p e that is an element (text and CDATA children are skipped), or a null node.
Element firstChildElement(Element e) {
  Element c = e.first_child();
  while (c && c.type() != pugi::node_element)
    c = c.next_sibling();
  return c;
}

/// The next sibling of @p e that is an element, or a null node.
Element nextSiblingElement(Element e) {
  Element c = e.next_sibling();
  while (c && c.type() != pugi::node_element)
    c = c.next_sibling();
  return c;
}

/**
 * @brief The first child element of @p e named @p tags[i], for each i, from one scan over the children: what
 *        e.child(tags[i]) would give, without a scan of the children (and a strcmp per child) per tag.
 */
template <size_t N>
std::array<Element, N> childrenNamed(Element e, const std::array<const char*, N>& tags) {
  std::array<Element, N> found{};
  unsigned seen = 0;  // bit i: found[i] set (a bit test, not a call into pugixml)
  for (Element c = e.first_child(); c; c = c.next_sibling()) {
    const char* name = c.name();  // "" for text
    for (size_t i = 0; i < N; ++i) {
      if (name[0] == tags[i][0] && std::strcmp(name, tags[i]) == 0) {
        if ((seen & (1u << i)) == 0)
          found[i] = c;
        seen |= 1u << i;
        break;
      }
    }
  }
  return found;
}

/// A refusal inside the reader: thrown at the check that fails, caught in readUrdf and returned as its
/// Diagnostic, so no exception leaves this file (STYLE.md §4) and the ~40 checks stay one line each.
struct ReadFailure {
  Diagnostic diagnostic;
};

/// The label of an attribute in a diagnostic ("link1 origin xyz"), kept in up to three pieces and joined
/// only when a diagnostic needs it: labels are built per attribute read, diagnostics are rare.
struct Label {
  std::string_view a, b, c;
  Label(const char* text) : a(text) {}  // NOLINT: a literal is a label
  Label(std::string_view first, std::string_view second, std::string_view third = {})
      : a(first), b(second), c(third) {}
  /// This label followed by @p suffix (at most three pieces in all).
  Label then(std::string_view suffix) const { return b.empty() ? Label(a, suffix) : Label(a, b, suffix); }
  std::string str() const { return std::string(a).append(b).append(c); }
};

/// Top-level elements that carry nothing for mobility and are well known: skipped without a warning.
constexpr std::array<const char*, 6> kIgnoredElements = {
    "gazebo", "transmission", "ros2_control", "material", "sensor", "drake:collision_filter_group"};

/// Top-level elements this reader understands, in the order of their kinds (TopLevel).
constexpr std::array<const char*, 8> kReadElements = {
    "link",       "joint", "distance_constraint",   "cable",
    "loop_joint", "loop",  "drake:ball_constraint", "coupling"};

/// What a top-level element is: its index in kReadElements, kIgnored or kUnknown.
enum TopLevel : int {
  kLink,
  kJoint,
  kDistance,
  kCable,
  kLoopJoint,
  kLoop,
  kDrakeBall,
  kCoupling,
  kIgnored,
  kUnknown
};

TopLevel classify(const char* tag) {
  // Drake's custom tree joints (ball, universal, planar) are read with the <joint>s, in document order.
  if (tag[0] == 'd' && std::strcmp(tag, "drake:joint") == 0)
    return kJoint;
  for (size_t i = 0; i < kReadElements.size(); ++i) {
    if (tag[0] == kReadElements[i][0] && std::strcmp(tag, kReadElements[i]) == 0)
      return static_cast<TopLevel>(i);
  }
  for (const char* ignored : kIgnoredElements) {
    if (tag[0] == ignored[0] && std::strcmp(tag, ignored) == 0)
      return kIgnored;
  }
  return kUnknown;
}

/// kReadElements in alphabetical order: the order the "did you mean" hints are given in.
constexpr std::array<const char*, 8> kKnownSorted = {
    "cable", "coupling", "distance_constraint", "drake:ball_constraint", "joint",
    "link",  "loop",     "loop_joint"};

/// Blanks as `std::istream >> std::string` splits on them (the "C" locale's isspace).
bool isBlank(char c) {
  // '\t' '\n' '\v' '\f' '\r' are 9 to 13: one unsigned range test for the five.
  return c == ' ' || static_cast<unsigned char>(c - '\t') <= '\r' - '\t';
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
std::optional<JointType> parseJointType(std::string_view type, std::initializer_list<JointType> allowed) {
  for (const JointType candidate : allowed) {
    const char* spelling = toString(candidate);
    if (!type.empty() && type[0] == spelling[0] && type == spelling)  // the first letter tells most apart
      return candidate;
  }
  return std::nullopt;
}

/// Loop elements take every type of the dialect but the URDF tree's own planar and floating.
std::optional<JointType> parseLoopType(std::string_view type) {
  return parseJointType(
      type, {JointType::Revolute, JointType::Continuous, JointType::Prismatic, JointType::Cylindrical,
             JointType::Spherical, JointType::Universal, JointType::Fixed});
}

/// Drake's <drake:joint> types, as its URDF parser builds them: ball (BallRpyJoint), universal, planar.
std::optional<JointType> parseDrakeType(std::string_view type) {
  if (type == "ball")
    return JointType::Spherical;
  if (type == "universal")
    return JointType::Universal;
  if (type == "planar")
    return JointType::Planar;
  return std::nullopt;
}

/// Tree joints take URDF's types.
std::optional<JointType> parseTreeType(std::string_view type) {
  return parseJointType(type, {JointType::Revolute, JointType::Continuous, JointType::Prismatic,
                               JointType::Fixed, JointType::Floating, JointType::Planar});
}

bool needsAxis(JointType type) {
  return type == JointType::Revolute || type == JointType::Continuous || type == JointType::Prismatic ||
         type == JointType::Cylindrical || type == JointType::Universal;
}

/// A coupling as written, resolved once every tree joint is known.
struct PendingCoupling {
  std::string name;
  std::string kind;  ///< "joint" (a mimic) or "coupling", for diagnostics.
  std::string leader, follower;
  /// generalized_rbda names the two links instead (`<predecessor link=...>`): their parent joints then.
  bool byLink = false;
  double multiplier = 1.0;
  double offset = 0.0;
};

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) { mechanism_.file = file_; }

  /// The warnings given so far (after a refusal: those before it).
  const std::vector<Diagnostic>& warnings() const { return mechanism_.warnings; }

  /// The mechanism of the <robot> element @p robot; with @p rest, of the two halves of one (XmlHalves): the
  /// children of @p robot, then those of @p rest.
  Mechanism read(Element robot, Element rest = Element()) {
    const char* robotName = attributeOf(robot, "name");
    mechanism_.name = robotName == nullptr ? "" : robotName;
    const std::array<Element, 2> parts{robot, rest};
    auto forEachTopLevel = [&](auto&& use) {
      for (Element part : parts) {
        for (Element e = part ? firstChildElement(part) : Element(); e; e = nextSiblingElement(e))
          use(e);
      }
    };
    // One walk over the top-level elements sorts them by kind (document order within each kind) and warns
    // about the unknown ones; each kind is then read in the equation order of DESIGN.md §3.
    std::array<std::vector<Element>, kIgnored> byKind;
    forEachTopLevel([&](Element e) {
      const TopLevel kind = classify(e.name());
      if (kind == kUnknown)
        warnUnknown(e);
      else if (kind != kIgnored)
        byKind[kind].push_back(e);
    });
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
    for (Element e : byKind[kDistance])
      readTwoEnded(e, ConnectionKind::DistanceConstraint);
    for (Element e : byKind[kCable])
      readTwoEnded(e, ConnectionKind::Cable);
    // <loop_joint>, <loop> and <drake:ball_constraint> in document order, mixed.
    std::vector<Element>& loops = byKind[kLoopJoint];
    if (!byKind[kLoop].empty() || !byKind[kDrakeBall].empty()) {
      loops.clear();
      forEachTopLevel([&](Element e) {
        const TopLevel kind = classify(e.name());
        if (kind == kLoopJoint || kind == kLoop || kind == kDrakeBall)
          loops.push_back(e);
      });
    }
    int drakeBalls = 0;
    for (Element e : loops) {
      if (classify(e.name()) == kDrakeBall)
        readDrakeBall(e, drakeBalls++);
      else
        readLoop(e);
    }
    for (Element e : byKind[kCoupling])
      readCoupling(e);
    for (const PendingCoupling& coupling : couplings_)
      addCoupling(coupling);
    return std::move(mechanism_);
  }

 private:
  [[noreturn]] void fail(std::string_view kind, std::string_view name, const std::string& what) const {
    throw ReadFailure{makeDiagnostic(file_, std::string(kind), std::string(name), what)};
  }

  void warn(const std::string& kind, const std::string& name, const std::string& what) {
    mechanism_.warnings.push_back(makeDiagnostic(file_, kind, name, what));
  }

  double number(const char* text, std::string_view kind, const std::string& name, Label attribute) const {
    if (text == nullptr)
      fail(kind, name, "missing attribute " + attribute.str());
    const std::optional<double> value = parseDouble(text);
    if (!value)
      fail(kind, name, attribute.str() + " '" + text + "' is not a number");
    if (const std::optional<std::string> why = checkRange(*value))
      fail(kind, name, attribute.str() + " '" + text + "' " + *why);
    return *value;
  }

  /// "a b c": exactly three finite numbers within range; absent: zero.
  Eigen::Vector3d vector(const char* text, std::string_view kind, const std::string& name,
                         Label attribute) const {
    if (text == nullptr)
      return Eigen::Vector3d::Zero();
    // "d d d" of three single digits (rpy="0 0 0", xyz="0 0 1": most triples of a URDF) is the three digits,
    // what the loop below reads from it, without its scan (each test reads only within the text).
    auto digit = [](char c) { return static_cast<unsigned char>(c - '0') <= 9; };
    if (digit(text[0]) && text[1] == ' ' && digit(text[2]) && text[3] == ' ' && digit(text[4]) &&
        text[5] == '\0')
      return Eigen::Vector3d(text[0] - '0', text[2] - '0', text[4] - '0');
    Eigen::Vector3d v;
    int count = 0;
    const char* at = text;
    while (true) {
      while (isBlank(*at))
        ++at;
      if (*at == '\0')
        break;
      const char* tokenEnd = at;
      // Characters above ' ' are neither blank nor the end: one comparison for each of a number's digits.
      while (static_cast<unsigned char>(*tokenEnd) > ' ' || (*tokenEnd != '\0' && !isBlank(*tokenEnd)))
        ++tokenEnd;
      if (count == 3)
        fail(kind, name, attribute.str() + " has more than 3 numbers: '" + text + "'");
      // A number is the whole token (the token ends at a blank or the end, where strtod stops).
      const std::optional<double> value = parseNumber(at, tokenEnd);
      if (!value) {
        fail(
            kind, name,
            attribute.str() + " '" + text + "' is not a number triple ('" + std::string(at, tokenEnd) + "')");
      }
      // The range test inline (false for NaN too), checkRange only for its reason: most numbers pass it.
      if (!(std::abs(*value) <= tolerances::kMaxCoordinate)) {
        if (const std::optional<std::string> why = checkRange(*value))
          fail(kind, name, attribute.str() + " '" + text + "' " + *why);
      }
      v[count++] = *value;
      at = tokenEnd;
    }
    if (count != 3)
      fail(kind, name,
           attribute.str() + " needs 3 numbers, got " + std::to_string(count) + ": '" + text + "'");
    return v;
  }

  /// The frame of <e xyz rpy/>; identity when @p e is null. @p what: the element's label ("link1 origin").
  Eigen::Isometry3d frame(Element e, std::string_view kind, const std::string& name, Label what) const {
    if (!e)
      return Eigen::Isometry3d::Identity();
    return makeFrame(vector(attributeOf(e, "xyz"), kind, name, what.then(" xyz")),
                     vector(attributeOf(e, "rpy"), kind, name, what.then(" rpy")));
  }

  /// The unit axis of @p element, <tag xyz>; @p fallback when the element is absent (null).
  Eigen::Vector3d axis(Element element, const char* tag, std::string_view kind, const std::string& name,
                       const Eigen::Vector3d& fallback) const {
    if (!element)
      return fallback;
    const char* xyz = attributeOf(element, "xyz");
    if (xyz == nullptr)
      fail(kind, name, std::string("<") + tag + "> has no xyz");
    const Eigen::Vector3d v = vector(xyz, kind, name, Label{tag, " xyz"});
    if (v.norm() < tolerances::kZeroVector)
      fail(kind, name, std::string(tag) + " xyz '" + xyz + "' is the zero vector");
    return v.normalized();
  }

  std::string elementName(Element e, std::string_view kind) const {
    const char* name = attributeOf(e, "name");
    if (name == nullptr || *name == '\0')
      fail(kind, "", "has no name");
    return name;
  }

  int link(const char* name, std::string_view kind, const std::string& element, std::string_view role) const {
    if (name == nullptr)
      fail(kind, element, "<" + std::string(role) + "> has no link attribute");
    const int index = findLink(name);
    if (index < 0)
      fail(kind, element, std::string(role) + " '" + name + "' is not a link");
    return index;
  }

  /// The index of link @p name, or -1. Links are mostly referred to in the order they are written: written
  /// root first, a joint's parent is the last one's child and its child the next link (+1, 0); written leaf
  /// first, its parent is the link after the last one's parent (+2 from the last one's child) and its child
  /// the link before that (-1). Those neighbours are compared first, in cache, before a probe of the index (a
  /// hash and two cache misses on 10^5 links).
  int findLink(const char* name) const {
    const std::vector<Link>& links = mechanism_.links;
    const std::string_view key(name);  // its length once; a guess of another length costs one comparison
    for (const int guess : {lastLink_ + 1, lastLink_, lastLink_ + 2, lastLink_ - 1}) {
      if (guess >= 0 && guess < static_cast<int>(links.size()) &&
          links[static_cast<size_t>(guess)].name == key)
        return lastLink_ = guess;
    }
    const int index = linkIndex_.find(key, links);
    if (index >= 0)
      lastLink_ = index;
    return index;
  }

  /// Warns about every child of a loop element that is not in @p known, and about a repeated known child.
  void checkChildren(Element e, const std::string& kind, const std::string& name,
                     std::initializer_list<const char*> known) {
    unsigned seen = 0;  // bit i: known[i] met
    for (Element c = firstChildElement(e); c; c = nextSiblingElement(c)) {
      const char* tag = c.name();
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

  void warnUnknown(Element e) {
    const std::string tag = e.name();
    const char* name = attributeOf(e, "name");
    std::string what = "unknown element <" + tag + "> is not read";
    for (const std::string known : kKnownSorted) {
      if (squashed(known) == squashed(tag))
        what += " (did you mean <" + known + ">?)";
    }
    if (tag == "loop_constraint")
      what += " (the URDF+ form <loop> with <predecessor>/<successor> is read)";
    warn(tag, name == nullptr ? "" : name, what);
  }

  void readLinks(const std::vector<Element>& elements) {
    for (Element e : elements) {
      const char* name = attributeOf(e, "name");
      if (name == nullptr || *name == '\0')
        fail("link", "", "has no name");
      const std::string_view key(name);  // its length once, for the index and the copy
      if (linkIndex_.findOrInsert(key, static_cast<int>(mechanism_.links.size()), mechanism_.links) >= 0)
        fail("link", name, "is defined twice");
      mechanism_.links.push_back(Link{std::string(key)});
    }
    if (mechanism_.links.empty())
      fail("robot", mechanism_.name, "has no <link>");
  }

  /// Refuses @p name when a connection has it already (the connection itself is added by addConnection).
  void claimName(std::string_view kind, const std::string& name) const {
    if (connectionIndex_.find(name, mechanism_.joints) >= 0)
      fail(kind, name, kind == "joint" ? "is defined twice" : "has the name of another joint or constraint");
  }

  /// Refuses @p name as claimName does, else gives it the index of the connection appended next (by
  /// appendClaimed or in place): one probe of the index for claimName's and addConnection's two.
  void claimNextName(std::string_view kind, const std::string& name) {
    if (connectionIndex_.findOrInsert(name, static_cast<int>(mechanism_.joints.size()), mechanism_.joints) >=
        0)
      fail(kind, name, kind == "joint" ? "is defined twice" : "has the name of another joint or constraint");
  }

  /// Appends @p joint, whose name claimNextName gave its index, to the mechanism's connections.
  void appendClaimed(Joint&& joint) { mechanism_.joints.push_back(std::move(joint)); }

  /// Appends @p joint to the mechanism's connections, and its name to their index.
  void addConnection(Joint&& joint) {
    connectionIndex_.insert(joint.name, static_cast<int>(mechanism_.joints.size()));
    mechanism_.joints.push_back(std::move(joint));
  }

  void readTreeJoints(const std::vector<Element>& elements) {
    parentOf_.assign(mechanism_.links.size(), -1);
    for (Element e : elements) {
      std::string name = elementName(e, "joint");
      claimNextName("joint", name);  // the joint is written in place below, or the whole read fails
      const auto [parent, child, origin, axisElement, mimic] =
          childrenNamed<5>(e, {"parent", "child", "origin", "axis", "mimic"});
      const char* parentName = parent ? attributeOf(parent, "link") : nullptr;
      const char* childName = child ? attributeOf(child, "link") : nullptr;
      if (parentName == nullptr)
        fail("joint", name, "has no <parent link=\"...\">");
      if (childName == nullptr)
        fail("joint", name, "has no <child link=\"...\">");
      const int parentLink = link(parentName, "joint", name, "parent");
      const int childLink = link(childName, "joint", name, "child");
      if (parentLink == childLink)
        fail("joint", name, "joins link '" + mechanism_.links[childLink].name + "' to itself");
      if (parentOf_[childLink] >= 0) {
        fail("joint", name,
             "link '" + mechanism_.links[childLink].name +
                 "' already has a parent joint; close loops with <loop_joint>");
      }
      const char* type = attributeOf(e, "type");
      const bool drake = std::strcmp(e.name(), "drake:joint") == 0;
      const std::optional<JointType> jointType =
          drake ? parseDrakeType(type == nullptr ? "" : type) : parseTreeType(type == nullptr ? "" : type);
      if (drake && !jointType) {
        fail("drake:joint", name,
             "type '" + std::string(type == nullptr ? "" : type) +
                 "' is not read (ball, universal, planar are)");
      }
      if (!jointType) {
        fail("joint", name,
             "type '" + std::string(type == nullptr ? "" : type) +
                 "' is not a URDF tree type (revolute, continuous, prismatic, fixed, floating, planar)");
      }
      // Written in place at the end of the connections (reserved: no reallocation), not built apart and moved
      // in: a Joint is 448 bytes. A refusal below abandons the whole mechanism, this joint with it.
      Joint& joint = mechanism_.joints.emplace_back();
      joint.kind = ConnectionKind::TreeJoint;
      joint.type = *jointType;
      joint.link1 = parentLink;
      joint.link2 = childLink;
      if (origin) {
        joint.frame1 =
            io_detail::makeOriginFrame(vector(attributeOf(origin, "xyz"), "joint", name, "origin xyz"),
                                       vector(attributeOf(origin, "rpy"), "joint", name, "origin rpy"));
      }
      if (joint.type == JointType::Universal) {
        // Drake's UniversalJoint turns about its frame's x on the parent, then y on the child; it reads no
        // axis.
        joint.axis = Eigen::Vector3d::UnitX();
        joint.axis2 = Eigen::Vector3d::UnitY();
      } else if (joint.type != JointType::Fixed && joint.type != JointType::Floating &&
                 joint.type != JointType::Spherical) {
        // URDF's default, but a forgotten axis turns a planar linkage spatial: said, never silent.
        if (!axisElement) {
          warn("joint", name,
               std::string("type ") + toString(joint.type) +
                   " has no <axis>; axis defaulted to 1 0 0 (URDF's default)");
        }
        joint.axis = axis(axisElement, "axis", "joint", name, Eigen::Vector3d::UnitX());
      }
      if (mimic) {
        PendingCoupling coupling;
        coupling.name = "mimic_" + name;
        coupling.kind = "joint";
        coupling.follower = name;
        const char* leader = attributeOf(mimic, "joint");
        if (leader == nullptr)
          fail("joint", name, "<mimic> has no joint attribute");
        coupling.leader = leader;
        if (attributeOf(mimic, "multiplier"))
          coupling.multiplier = number(attributeOf(mimic, "multiplier"), "joint", name, "mimic multiplier");
        if (attributeOf(mimic, "offset"))
          coupling.offset = number(attributeOf(mimic, "offset"), "joint", name, "mimic offset");
        couplings_.push_back(std::move(coupling));
      }
      parentOf_[childLink] = parentLink;
      joint.name = std::move(name);
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
  std::pair<int, Eigen::Isometry3d> end(Element e, const char* tag, const std::string& kind,
                                        const std::string& name) const {
    Element endElement = e.child(tag);
    if (!endElement)
      fail(kind, name, std::string("missing <") + tag + ">");
    const int l = link(attributeOf(endElement, "link"), kind, name, tag);
    Element origin = endElement.child("origin");
    if (origin)
      return {l, frame(origin, kind, name, Label{tag, " origin"})};
    return {l, makeFrame(vector(attributeOf(endElement, "xyz"), kind, name, Label{tag, " xyz"}),
                         vector(attributeOf(endElement, "rpy"), kind, name, Label{tag, " rpy"}))};
  }

  void readEnds(Element e, const char* tag1, const char* tag2, const std::string& kind, Joint& joint) const {
    std::tie(joint.link1, joint.frame1) = end(e, tag1, kind, joint.name);
    std::tie(joint.link2, joint.frame2) = end(e, tag2, kind, joint.name);
    if (joint.link1 == joint.link2)
      fail(kind, joint.name, "joins link '" + mechanism_.links[joint.link1].name + "' to itself");
  }

  void readTwoEnded(Element e, ConnectionKind kind) {
    const std::string kindName = toString(kind);
    Joint joint;
    joint.name = elementName(e, kindName);
    claimNextName(kindName, joint.name);
    joint.kind = kind;
    joint.type = JointType::Spherical;
    checkChildren(e, kindName, joint.name, {"link1", "link2"});
    if (kind == ConnectionKind::Cable) {
      const char* type = attributeOf(e, "type");
      const std::string typeText = type == nullptr ? "passive" : type;
      if (typeText != "passive" && typeText != "active")
        fail("cable", joint.name, "type '" + typeText + "' is neither passive nor active");
      joint.cableType = typeText == "active" ? CableType::Active : CableType::Passive;
      joint.length = number(attributeOf(e, "length"), "cable", joint.name, "length");
      if (joint.length <= 0.0)
        fail("cable", joint.name, "length must be positive, got " + std::string(attributeOf(e, "length")));
    }
    readEnds(e, "link1", "link2", kindName, joint);
    appendClaimed(std::move(joint));
  }

  /**
   * Drake's <drake:ball_constraint> (its URDF form: <drake:ball_constraint_body_A name=.../>, _p_AP
   * value=..., _body_B, _p_BQ; MultibodyPlant::AddBallConstraint): point P of body A stays at point Q of body
   * B, a spherical loop joint. Drake names none; this is "ball_constraint_<n>", the n-th in the file. Every
   * child is required, as Drake requires them.
   */
  void readDrakeBall(Element e, int n) {
    const std::string kind = e.name();
    Joint joint;
    joint.name = "ball_constraint_" + std::to_string(n);
    claimNextName(kind, joint.name);
    joint.kind = ConnectionKind::LoopJoint;
    joint.type = JointType::Spherical;
    checkChildren(e, kind, joint.name,
                  {"drake:ball_constraint_body_A", "drake:ball_constraint_p_AP",
                   "drake:ball_constraint_body_B", "drake:ball_constraint_p_BQ"});
    auto required = [&](const char* tag, const char* attribute) {
      Element c = e.child(tag);
      if (!c || attributeOf(c, attribute) == nullptr)
        fail(kind, joint.name, std::string("missing <") + tag + " " + attribute + "=\"...\"/>");
      return attributeOf(c, attribute);
    };
    joint.link1 = link(required("drake:ball_constraint_body_A", "name"), kind, joint.name, "body_A");
    joint.link2 = link(required("drake:ball_constraint_body_B", "name"), kind, joint.name, "body_B");
    if (joint.link1 == joint.link2)
      fail(kind, joint.name, "joins link '" + mechanism_.links[joint.link1].name + "' to itself");
    joint.frame1.translation() =
        vector(required("drake:ball_constraint_p_AP", "value"), kind, joint.name, Label{"p_AP", ""});
    joint.frame2.translation() =
        vector(required("drake:ball_constraint_p_BQ", "value"), kind, joint.name, Label{"p_BQ", ""});
    appendClaimed(std::move(joint));
  }

  /// <loop_joint> of our dialect (Isaac Sim, Drake) or URDF+ <loop>: the same connection, two spellings.
  void readLoop(Element e) {
    const std::string kind = e.name();
    const bool urdfPlus = kind == "loop";
    Joint joint;
    joint.name = elementName(e, kind);
    claimNextName(kind, joint.name);
    joint.kind = ConnectionKind::LoopJoint;
    const char* type = attributeOf(e, "type");
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
    const auto [axisElement, axis2Element] = childrenNamed<2>(e, {"axis", "axis2"});
    if (needsAxis(joint.type) && !axisElement) {
      warn(kind, joint.name,
           std::string("type ") + toString(joint.type) + " has no <axis>; axis defaulted to 1 0 0");
    }
    if (joint.type == JointType::Universal && !axis2Element) {
      warn(kind, joint.name, "type universal has no <axis2>; axis2 defaulted to 0 1 0");
    }
    joint.axis = axis(axisElement, "axis", kind, joint.name, Eigen::Vector3d::UnitX());
    joint.axis2 = axis(axis2Element, "axis2", kind, joint.name, Eigen::Vector3d::UnitY());
    if (joint.type == JointType::Universal && joint.axis.cross(joint.axis2).norm() < tolerances::kPlanarAxis)
      fail(kind, joint.name, "universal joint axes 'axis' and 'axis2' are parallel");
    appendClaimed(std::move(joint));
  }

  /// URDF+ <coupling>: successor = ratio * predecessor + offset.
  void readCoupling(Element e) {
    PendingCoupling coupling;
    coupling.kind = "coupling";
    coupling.name = elementName(e, "coupling");
    checkChildren(e, "coupling", coupling.name,
                  {"predecessor", "successor", "leader", "follower", "ratio", "offset"});
    // generalized_rbda writes <predecessor link=.../>: its couplings hold ratio times the predecessor's joint
    // values from the two links' nearest common ancestor to the successor's (explicitRollingConstraint).
    auto endOf = [&](const char* first, const char* second) -> std::string {
      Element c = e.child(first);
      if (!c)
        c = e.child(second);
      if (!c)
        fail("coupling", coupling.name,
             std::string("missing <") + first + " joint=\"...\"> (or <" + second + ">)");
      const char* joint = attributeOf(c, "joint");
      const char* link = attributeOf(c, "link");
      if (joint == nullptr && link == nullptr)
        fail("coupling", coupling.name, std::string("<") + c.name() + "> has no joint or link attribute");
      if (joint == nullptr)
        coupling.byLink = true;
      return joint != nullptr ? joint : link;
    };
    coupling.leader = endOf("predecessor", "leader");
    const bool leaderByLink = coupling.byLink;
    coupling.follower = endOf("successor", "follower");
    if (leaderByLink != coupling.byLink)
      fail("coupling", coupling.name, "names a joint at one end and a link at the other");
    Element ratio = e.child("ratio");
    if (!ratio)
      fail("coupling", coupling.name, "missing <ratio value=\"...\">");
    coupling.multiplier = number(attributeOf(ratio, "value"), "coupling", coupling.name, "ratio value");
    if (Element offset = e.child("offset"))
      coupling.offset = number(attributeOf(offset, "value"), "coupling", coupling.name, "offset value");
    couplings_.push_back(std::move(coupling));
  }

  /// The tree joints from link @p linkName up to the root, nearest first (@p role names it in errors).
  std::vector<int> pathToRoot(const std::string& linkName, const PendingCoupling& pending,
                              const char* role) const {
    if (parentJoint_.empty()) {  // built once, at the first coupling between links
      parentJoint_.assign(mechanism_.links.size(), -1);
      for (size_t j = 0; j < mechanism_.joints.size(); ++j) {
        if (mechanism_.joints[j].kind == ConnectionKind::TreeJoint)
          parentJoint_[static_cast<size_t>(mechanism_.joints[j].link2)] = static_cast<int>(j);
      }
    }
    std::vector<int> path;
    for (int joint =
             parentJoint_[static_cast<size_t>(link(linkName.c_str(), "coupling", pending.name, role))];
         joint >= 0; joint = parentJoint_[static_cast<size_t>(mechanism_.joints[joint].link1)])
      path.push_back(joint);
    return path;
  }

  /**
   * A coupling between two links (generalized_rbda): ratio times the sum of the joint values on the
   * predecessor's path from the two links' nearest common ancestor equals that sum on the successor's path
   * (its explicitRollingConstraint); its benchmarks and the MIT humanoid's ankle have two joints on one path.
   * The first joint of each path is the leader or follower, the rest go to moreLeaders / moreFollowers; every
   * joint on a longer path must be revolute or continuous, as the sum then has one unit.
   */
  void coupleLinks(const PendingCoupling& pending, Joint& coupling) const {
    std::vector<int> leaders = pathToRoot(pending.leader, pending, "predecessor link");
    std::vector<int> followers = pathToRoot(pending.follower, pending, "successor link");
    // Drop the common part above the nearest common ancestor (both paths end at the root).
    while (!leaders.empty() && !followers.empty() && leaders.back() == followers.back()) {
      leaders.pop_back();
      followers.pop_back();
    }
    if (leaders.empty() || followers.empty()) {
      fail("coupling", pending.name,
           "link '" + (leaders.empty() ? pending.leader : pending.follower) + "' is an ancestor of '" +
               (leaders.empty() ? pending.follower : pending.leader) + "': no joint to couple on its side");
    }
    if (leaders.size() + followers.size() > 2) {
      for (const std::vector<int>* path : {&leaders, &followers}) {
        for (const int j : *path) {
          const Joint& joint = mechanism_.joints[static_cast<size_t>(j)];
          if (joint.type != JointType::Revolute && joint.type != JointType::Continuous)
            fail("coupling", pending.name,
                 "joint '" + joint.name + "' on a path from the links' common ancestor is not revolute; " +
                     "only revolute joint values are summed");
        }
      }
    }
    coupling.leader = leaders.front();
    coupling.follower = followers.front();
    for (size_t k = 1; k < leaders.size(); ++k)
      coupling.moreLeaders.push_back(WeightedJoint{leaders[k], 1.0});
    for (size_t k = 1; k < followers.size(); ++k)
      coupling.moreFollowers.push_back(WeightedJoint{followers[k], 1.0});
  }

  void addCoupling(const PendingCoupling& pending) {
    const std::string& element = pending.kind == "joint" ? pending.follower : pending.name;
    // A tree joint of one freedom, or the refusal naming it in its @p role.
    auto checkOneFreedom = [&](int found, const char* role) {
      const Joint& tree = mechanism_.joints[static_cast<size_t>(found)];
      if (!hasSingleValue(tree)) {
        fail(pending.kind, element,
             std::string(role) + " '" + tree.name + "' is " + toString(tree.type) +
                 "; only revolute, continuous and prismatic joints can be coupled");
      }
    };
    auto resolve = [&](const std::string& jointName, const char* role) {
      const int found = connectionIndex_.find(jointName, mechanism_.joints);
      if (found < 0 || mechanism_.joints[found].kind != ConnectionKind::TreeJoint)
        fail(pending.kind, element, std::string(role) + " '" + jointName + "' is not a tree joint");
      checkOneFreedom(found, role);
      return found;
    };
    Joint joint;
    joint.name = pending.name;
    claimName("coupling", joint.name);
    joint.kind = ConnectionKind::Coupling;
    if (pending.byLink) {
      coupleLinks(pending, joint);  // tree joints, found on the links' paths
      for (const int j : coupledJoints(joint))
        checkOneFreedom(j, "joint");
    } else {
      joint.leader = resolve(pending.leader, pending.kind == "joint" ? "mimic joint" : "predecessor");
      joint.follower = resolve(pending.follower, "successor");
    }
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
  mutable std::vector<int> parentJoint_;  ///< Tree joint whose child each link is (-1: the root); lazily.
  mutable int lastLink_ = -1;  ///< The link findLink found last (a guess for the next; changes no result).
};

}  // namespace

namespace {

/// pugixml reads text as tinyxml2 did: entities and character references decoded, CDATA kept, line ends
/// normalised to '\n', attribute blanks kept as written (no parse_wconv_attribute: a tab in a name stays a
/// tab). parse_fragment keeps top-level text as nodes so that it can be refused (wellFormedError), and
/// makes an element-less document parse: refused there as well.
constexpr unsigned kParseOptions =
    pugi::parse_cdata | pugi::parse_escapes | pugi::parse_eol | pugi::parse_fragment;

/// From this size of text on, the well-formedness walk runs on a second thread beside the reader: a
/// millisecond of walking, against tens of microseconds to start a thread.
constexpr size_t kSideThreadBytes = size_t{1} << 20;

/// The 1-based line of byte @p offset of @p text (the text as written, before the parser changed it); an
/// offset at or past the end (pugixml's for an unclosed element) is on the last line.
size_t lineAt(const std::string& text, ptrdiff_t offset) {
  const size_t last = text.empty() ? 0 : text.size() - 1;
  const size_t end = offset < 0 ? 0 : std::min(last, static_cast<size_t>(offset));
  return 1 + static_cast<size_t>(std::count(text.begin(), text.begin() + end, '\n'));
}

/// Where a parsed document breaks XML's well-formedness in what pugixml accepts and tinyxml2 refused.
struct XmlFault {
  std::string what;
  ptrdiff_t offset = -1;  ///< Into the text as written; -1: unknown.
};

/// The name of the first attribute of @p e named like an earlier one of @p e, or nullptr. Most elements have
/// one or two attributes: their names are gathered once and compared there (pugixml's accessors are calls
/// into the shared library).
const char* repeatedAttribute(Element e) {
  // A null attribute's name is "" and a parsed one's never is (pugixml refuses an attribute without a
  // name): the names end the walk, one call an attribute fewer than a test of each handle.
  const pugi::xml_attribute first = e.first_attribute();
  pugi::xml_attribute a = first.next_attribute();  // null too when there is no first (and for non-elements)
  const char* name = a.name();
  if (*name == '\0')
    return nullptr;  // fewer than two attributes
  constexpr int kGathered = 8;
  const char* names[kGathered];
  names[0] = first.name();
  int count = 1;
  for (; *name != '\0'; a = a.next_attribute(), name = a.name()) {
    const int earlier = std::min(count, kGathered);
    for (int i = 0; i < earlier; ++i) {
      if (names[i][0] == name[0] && std::strcmp(names[i], name) == 0)
        return name;
    }
    if (count >= kGathered) {  // beyond the gathered names: through pugixml
      for (pugi::xml_attribute b = first; b != a; b = b.next_attribute()) {
        if (std::strcmp(b.name(), name) == 0)
          return name;
      }
    } else {
      names[count] = name;
    }
    ++count;
  }
  return nullptr;
}

/**
 * @brief What pugixml lets through that is not well-formed XML (XML 1.0 §2.1, §3.1): text outside the root
 *        element, no element at all, an attribute given twice in one element; nothing when none of these.
 *
 * One walk over every node in document order, without recursion (nesting depth is the input's to choose).
 */
std::optional<XmlFault> wellFormedError(const pugi::xml_document& document) {
  bool anyElement = false;
  for (Element top = document.first_child(); top; top = top.next_sibling()) {
    if (top.type() == pugi::node_pcdata || top.type() == pugi::node_cdata)
      return XmlFault{"text outside the root element", top.offset_debug()};
    anyElement = anyElement || top.type() == pugi::node_element;
  }
  if (!anyElement)
    return XmlFault{"No document element found", -1};
  // pugixml's own walk (iterative, inside the library: a third faster than stepping with its accessors).
  struct RepeatedAttributes : pugi::xml_tree_walker {
    std::optional<XmlFault> fault;
    bool for_each(pugi::xml_node& node) override {
      const char* repeated = repeatedAttribute(node);  // nullptr but for elements
      if (repeated != nullptr) {
        fault = XmlFault{"attribute '" + std::string(repeated) + "' given twice in <" + node.name() + ">",
                         node.offset_debug()};
      }
      return repeated == nullptr;
    }
  } walker;
  Element root = document.root();  // a handle: traverse is not const, but does not change the tree
  root.traverse(walker);
  return walker.fault;
}

/// The mechanism of the <robot> element @p robot (with @p rest: of its two halves, Reader::read).
Result<Mechanism> readRobot(Element robot, Element rest, const std::string& file) {
  if (!robot)
    return makeDiagnostic(file, "xml", "", "the root element is not <robot>");
  Reader reader(file);
  try {
    return reader.read(robot, rest);
  } catch (const ReadFailure& failure) {
    return io_detail::refusalAfter(failure.diagnostic, reader.warnings());
  }
}

/// The mechanism of a parsed document (@p parsed: pugixml's answer; @p textAsWritten() gives the text for the
/// line of an error).
template <class TextAsWritten>
Result<Mechanism> readDocument(const pugi::xml_document& document, const pugi::xml_parse_result& parsed,
                               const std::string& file, const TextAsWritten& textAsWritten, bool sideThread) {
  auto refuse = [&](const XmlFault& fault) {
    std::string what = "not well-formed XML: " + fault.what;
    if (fault.offset >= 0)
      what += " at line " + std::to_string(lineAt(textAsWritten(), fault.offset));
    return makeDiagnostic(file, "xml", "", what);
  };
  if (!parsed)
    return refuse(XmlFault{parsed.description(), parsed.offset});
  auto readTree = [&] { return readRobot(document.child("robot"), Element(), file); };
  auto walk = [&] { return wellFormedError(document); };
  if (!sideThread) {
    if (const std::optional<XmlFault> found = walk())
      return refuse(*found);
    return readTree();
  }
  // The walk for what pugixml lets through reads the tree as the reader does, and its fault comes first
  // whatever the reader finds: on a large file it runs beside the reader (a tenth of the load of a long
  // chain).
  core_detail::SideTask<std::optional<XmlFault>> fault(true, walk);
  Result<Mechanism> mechanism = readTree();
  if (const std::optional<XmlFault> found = fault.get())
    return refuse(*found);
  return mechanism;
}

/// From this size of file on, a second thread may parse half of it (io_detail::parseInHalves): about 10 ms of
/// parsing each, against tens of microseconds to start a thread.
constexpr size_t kHalvesBytes = size_t{4} << 20;

/**
 * The mechanism of a file parsed in two halves, or nothing when the walk for what pugixml lets through finds
 * a fault in either: the whole document is read then, and its walk names the fault at its line.
 */
std::optional<Result<Mechanism>> readHalves(const io_detail::XmlHalves& halves, const std::string& file) {
  core_detail::SideTask<bool> faulty(
      true, [&] { return wellFormedError(halves.first) || wellFormedError(halves.second); });
  Result<Mechanism> mechanism = readRobot(halves.first.child("robot"), halves.second.child("robot"), file);
  if (faulty.get())
    return std::nullopt;
  return mechanism;
}

/// The file read whole, in one buffer.
Result<Mechanism> readWholeUrdfFile(const std::string& path, bool sideThread) {
  // The text once in memory: the parser works in this buffer (names and values point into it).
  std::string text;
  if (!io_detail::readWholeFile(path, text))
    return makeDiagnostic(path, "", "", "cannot open the file");  // also a directory, an unreadable file
  pugi::xml_document document;
  const pugi::xml_parse_result parsed = document.load_buffer_inplace(&text[0], text.size(), kParseOptions);
  std::string original;  // read again only for the line of an error: the parse changed `text`
  const bool besideReader = sideThread && text.size() >= kSideThreadBytes;
  return readDocument(
      document, parsed, io_detail::baseName(path),
      [&]() -> const std::string& {
        io_detail::readWholeFile(path, original);
        return original;
      },
      besideReader);
}

/// The file read from its two halves where it can be cut (from byte @p cutFrom on, by default its middle),
/// else whole; @p cut, when given, is set to where it was cut (0: read whole).
Result<Mechanism> readUrdfFileFrom(const std::string& path, bool sideThread, size_t halvesFrom,
                                   std::optional<size_t> cutFrom, size_t* cut) {
  if (cut != nullptr)
    *cut = 0;
  if (sideThread) {
    if (const std::unique_ptr<io_detail::XmlHalves> halves =
            io_detail::parseInHalves(path, kParseOptions, "robot", halvesFrom, cutFrom)) {
      if (std::optional<Result<Mechanism>> mechanism = readHalves(*halves, io_detail::baseName(path))) {
        if (cut != nullptr)
          *cut = halves->cut;
        return std::move(*mechanism);
      }
    }
  }
  return readWholeUrdfFile(path, sideThread);
}

}  // namespace

Result<Mechanism> readUrdf(const std::string& urdfText, const std::string& fileName, bool sideThread) {
  pugi::xml_document document;
  const pugi::xml_parse_result parsed = document.load_buffer(urdfText.data(), urdfText.size(), kParseOptions);
  const bool besideReader = sideThread && urdfText.size() >= kSideThreadBytes;
  return readDocument(
      document, parsed, io_detail::baseName(fileName), [&]() -> const std::string& { return urdfText; },
      besideReader);
}

Result<Mechanism> readUrdfFile(const std::string& path, bool sideThread) {
  return readUrdfFileFrom(path, sideThread, kHalvesBytes, std::nullopt, nullptr);
}

Result<Mechanism> core_detail::readUrdfFileCutFrom(const std::string& path, size_t cutFrom, size_t* cut) {
  return readUrdfFileFrom(path, true, 0, cutFrom, cut);
}

}  // namespace mobility_analysis
