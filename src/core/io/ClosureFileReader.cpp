#include "mobility_analysis/io/ClosureFileReader.hpp"

#include <algorithm>
#include <optional>
#include <set>

#include <Eigen/Core>

#include <yaml-cpp/yaml.h>

#include "XmlValues.hpp"

namespace mobility_analysis {

namespace {

/// Keys of Gepetto's robot.yaml that describe motors, not the mechanism: known, skipped.
const std::set<std::string> kSkippedKeys = {"name_mot", "Lidmot", "Lidvmot"};

/// A frame of the closure file: a link, or a tree joint (its child link's frame).
std::optional<int> frameLink(const Mechanism& mechanism, const std::string& frame) {
  if (const std::optional<int> link = mechanism.findLink(frame))
    return link;
  const std::optional<int> joint = mechanism.findJoint(frame);
  if (joint && mechanism.joints[*joint].kind == ConnectionKind::TreeJoint)
    return mechanism.joints[*joint].link2;
  return std::nullopt;
}

std::vector<std::string> stringList(const YAML::Node& node) {
  std::vector<std::string> items;
  if (node && node.IsSequence()) {
    for (const YAML::Node& item : node)
      items.push_back(item.IsScalar() ? item.as<std::string>() : std::string());
  }
  return items;
}

/// Unit vector of Gepetto's axis letter X, Y or Z; nothing for another character.
std::optional<Eigen::Vector3d> letterAxis(char letter) {
  switch (letter) {
    case 'X':
      return Eigen::Vector3d::UnitX();
    case 'Y':
      return Eigen::Vector3d::UnitY();
    case 'Z':
      return Eigen::Vector3d::UnitZ();
    default:
      return std::nullopt;
  }
}

/**
 * Builds tree joint @p name of the URDF as Gepetto's loader does for `joint_name` / `joint_type`
 * (example_parallel_robots' completeRobotLoader): `SPHERICAL` a ball at the joint's origin, `UJOINT_AB` a
 * universal joint turning about the joint frame's A axis on the parent and its B axis on the child
 * (Pinocchio's R_A then R_B at the same place), `FIXED` the joint frozen at its zero (buildReducedModel at
 * the neutral configuration). A name that is no tree joint and a type it does not know are warnings:
 * Gepetto's loader passes over the first and the second is not read.
 */
std::optional<Diagnostic> retypeJoint(Mechanism& mechanism, const std::string& name, const std::string& type,
                                      const std::string& file) {
  const std::optional<int> found = mechanism.findJoint(name);
  if (!found || mechanism.joints[*found].kind != ConnectionKind::TreeJoint) {
    mechanism.warnings.push_back(
        makeDiagnostic(file, "joint_name", name, "is not a tree joint of the URDF; not read"));
    return std::nullopt;
  }
  for (const Joint& coupling : mechanism.joints) {
    if (coupling.kind != ConnectionKind::Coupling)
      continue;
    const std::vector<int> coupled = coupledJoints(coupling);
    if (std::find(coupled.begin(), coupled.end(), *found) != coupled.end())
      return makeDiagnostic(
          file, "joint_name", name,
          "is coupled to another joint by '" + coupling.name + "'; it cannot become " + type);
  }
  Joint& joint = mechanism.joints[*found];
  if (type == "SPHERICAL") {
    joint.type = JointType::Spherical;
  } else if (type == "FIXED") {
    joint.type = JointType::Fixed;
  } else if (type.size() == 9 && type.compare(0, 7, "UJOINT_") == 0 && letterAxis(type[7]) &&
             letterAxis(type[8]) && type[7] != type[8]) {
    joint.type = JointType::Universal;
    joint.axis = *letterAxis(type[7]);
    joint.axis2 = *letterAxis(type[8]);
  } else {
    mechanism.warnings.push_back(makeDiagnostic(
        file, "joint_type", name,
        "'" + type + "' is none of SPHERICAL, UJOINT_<axis><axis>, FIXED; not read, the URDF joint is kept"));
  }
  return std::nullopt;
}

/// `joint_name` and `joint_type` (one type per name), then `rotule_name` (the older files: every tree joint
/// whose name contains it becomes a ball, as Gepetto's jointTypeUpdate made it).
std::optional<Diagnostic> retypeJoints(Mechanism& mechanism, const YAML::Node& root,
                                       const std::string& file) {
  const std::vector<std::string> names = stringList(root["joint_name"]);
  const std::vector<std::string> types = stringList(root["joint_type"]);
  if (names.size() != types.size()) {
    return makeDiagnostic(
        file, "yaml", "joint_type",
        std::to_string(types.size()) + " joint types for " + std::to_string(names.size()) + " joint names");
  }
  for (size_t i = 0; i < names.size(); ++i) {
    if (std::optional<Diagnostic> error = retypeJoint(mechanism, names[i], types[i], file))
      return error;
  }
  const YAML::Node rotule = root["rotule_name"];
  if (rotule) {
    const std::string part = rotule.IsScalar() ? rotule.as<std::string>() : std::string();
    if (part.empty())
      return makeDiagnostic(file, "yaml", "rotule_name", "is not a non-empty text");
    std::vector<std::string> matched;
    for (const Joint& joint : mechanism.joints) {
      if (joint.kind == ConnectionKind::TreeJoint && joint.name.find(part) != std::string::npos)
        matched.push_back(joint.name);
    }
    for (const std::string& name : matched) {
      if (std::optional<Diagnostic> error = retypeJoint(mechanism, name, "SPHERICAL", file))
        return error;
    }
  }
  return std::nullopt;
}

Result<Mechanism> addClosures(Mechanism mechanism, const YAML::Node& root, const std::string& file) {
  auto error = [&](const std::string& kind, const std::string& name, const std::string& what) {
    return makeDiagnostic(file, kind, name, what);
  };
  if (!root.IsMap())
    return error("yaml", "", "the file is not a map with a closed_loop key");
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    if (key != "closed_loop" && key != "type" && key != "joint_name" && key != "joint_type" &&
        key != "rotule_name" && kSkippedKeys.count(key) == 0) {
      mechanism.warnings.push_back(makeDiagnostic(file, "yaml", key, "unknown key is not read"));
    }
  }
  const YAML::Node loops = root["closed_loop"];
  if (!loops || !loops.IsSequence())
    return error("yaml", "closed_loop", "is missing or not a list of [frameA, frameB] pairs");
  const std::vector<std::string> types = stringList(root["type"]);
  if (types.size() != loops.size()) {
    return error(
        "yaml", "type",
        std::to_string(types.size()) + " types for " + std::to_string(loops.size()) + " closed_loop pairs");
  }
  if (std::optional<Diagnostic> retyped = retypeJoints(mechanism, root, file))
    return *retyped;
  for (size_t i = 0; i < loops.size(); ++i) {
    const std::string name = "closed_loop_" + std::to_string(i);
    const YAML::Node pair = loops[i];
    if (!pair.IsSequence() || pair.size() != 2 || !pair[0].IsScalar() || !pair[1].IsScalar())
      return error("closed_loop", name, "is not a pair [frameA, frameB]");
    Joint joint;
    joint.name = name;
    joint.kind = ConnectionKind::LoopJoint;
    if (mechanism.findJoint(name))
      return error("closed_loop", name, "has the name of another joint or constraint");
    const std::string type = types[i];
    if (type == "6d" || type == "6D") {
      joint.type = JointType::Fixed;
    } else if (type == "3d" || type == "3D") {
      joint.type = JointType::Spherical;
    } else {
      return error("closed_loop", name, "type '" + type + "' is neither 6d nor 3d");
    }
    const std::string frames[2] = {pair[0].as<std::string>(), pair[1].as<std::string>()};
    int links[2];
    for (int side = 0; side < 2; ++side) {
      const std::optional<int> link = frameLink(mechanism, frames[side]);
      if (!link)
        return error("closed_loop", name, "frame '" + frames[side] + "' is neither a link nor a tree joint");
      links[side] = *link;
    }
    if (links[0] == links[1])
      return error("closed_loop", name, "joins link '" + mechanism.links[links[0]].name + "' to itself");
    joint.link1 = links[0];
    joint.link2 = links[1];
    // Both frames are the links' own: Pinocchio's constraint holds the two frames (6d) or their origins (3d)
    // together, so the joint frame is the identity on each side.
    mechanism.joints.push_back(joint);
  }
  // Couplings stay last in the equation order (DESIGN.md §3): move them behind the new loop joints.
  std::stable_partition(mechanism.joints.begin(), mechanism.joints.end(),
                        [](const Joint& j) { return j.kind != ConnectionKind::Coupling; });
  return mechanism;
}

}  // namespace

Result<Mechanism> addClosureFile(Mechanism mechanism, const std::string& path) {
  const std::string file = io_detail::baseName(path);
  try {
    const YAML::Node root = YAML::LoadFile(path);
    return addClosures(std::move(mechanism), root, file);
  } catch (const YAML::BadFile&) {
    return makeDiagnostic(path, "", "", "cannot open the file");
  } catch (const YAML::Exception& e) {
    // yaml-cpp's parse errors and conversions: one line with its message (escaped by Diagnostic::toString).
    return makeDiagnostic(file, "yaml", "", std::string("not a closure file: ") + e.what());
  }
}

}  // namespace mobility_analysis
