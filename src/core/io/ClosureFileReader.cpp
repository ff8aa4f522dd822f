#include "mobility_analysis/io/ClosureFileReader.hpp"

#include <algorithm>
#include <set>

#include <yaml-cpp/yaml.h>

#include "XmlValues.hpp"

namespace mobility_analysis {

namespace {

/// Keys of Gepetto's robot.yaml that describe motors, not loops: known, skipped.
const std::set<std::string> kSkippedKeys = {"name_mot", "Lidmot", "Lidvmot", "rotule_name"};

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

Result<Mechanism> addClosures(Mechanism mechanism, const YAML::Node& root, const std::string& file) {
  auto error = [&](const std::string& kind, const std::string& name, const std::string& what) {
    return makeDiagnostic(file, kind, name, what);
  };
  if (!root.IsMap())
    return error("yaml", "", "the file is not a map with a closed_loop key");
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    if (key != "closed_loop" && key != "type" && key != "joint_name" && key != "joint_type" &&
        kSkippedKeys.count(key) == 0) {
      mechanism.warnings.push_back(makeDiagnostic(file, "yaml", key, "unknown key is not read"));
    }
  }
  const YAML::Node loops = root["closed_loop"];
  if (!loops || !loops.IsSequence())
    return error("yaml", "closed_loop", "is missing or not a list of [frameA, frameB] pairs");
  const std::vector<std::string> types = stringList(root["type"]);
  const std::vector<std::string> names = stringList(root["joint_name"]);
  const std::vector<std::string> jointTypes = stringList(root["joint_type"]);
  if (types.size() != loops.size()) {
    return error(
        "yaml", "type",
        std::to_string(types.size()) + " types for " + std::to_string(loops.size()) + " closed_loop pairs");
  }
  for (size_t i = 0; i < loops.size(); ++i) {
    const std::string name =
        i < names.size() && !names[i].empty() ? names[i] : "closed_loop_" + std::to_string(i);
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
    if (i < jointTypes.size() && !jointTypes[i].empty()) {
      if (jointTypes[i] == "SPHERICAL") {
        joint.type = JointType::Spherical;
      } else {
        mechanism.warnings.push_back(
            makeDiagnostic(file, "closed_loop", name,
                           "joint_type '" + jointTypes[i] + "' is not read; type '" + type + "' is used"));
      }
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
