#include "mobility_analysis/io/SdfReader.hpp"

#include <algorithm>
#include <cctype>
#include <deque>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include <sdf/sdf.hh>

#include "RefusalLine.hpp"
#include "SdfReaderPlugin.hpp"
#include "XmlValues.hpp"
#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

const char* kWorld = "world";
const char* kModelFrame = "__model__";

/// The element of an SDFormat XML path's last step: `/sdf/model[@name="m"]/jiont[@name="typo"]` gives
/// {"jiont", "typo"}; {"sdf", ""} when there is none.
std::pair<std::string, std::string> lastStep(const std::optional<std::string>& xmlPath) {
  if (!xmlPath || xmlPath->empty())
    return {"sdf", ""};
  const std::string step = xmlPath->substr(xmlPath->find_last_of('/') + 1);
  const size_t bracket = step.find('[');
  std::string name;
  const size_t quote = step.find('"');
  if (quote != std::string::npos) {
    const size_t end = step.find('"', quote + 1);
    name = step.substr(quote + 1, end == std::string::npos ? std::string::npos : end - quote - 1);
  }
  return {bracket == std::string::npos ? step : step.substr(0, bracket), name};
}

/// "(did you mean <joint>?)" when @p tag has the letters of a model element in another order or case.
std::string didYouMean(const std::string& tag) {
  std::string letters;
  for (const char c : tag) {
    if (std::isalpha(static_cast<unsigned char>(c)))
      letters += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  std::sort(letters.begin(), letters.end());
  for (std::string known : {"joint", "link", "frame", "model", "pose", "axis", "parent", "child"}) {
    std::string sorted = known;
    std::sort(sorted.begin(), sorted.end());
    if (sorted == letters)
      return " (did you mean <" + known + ">?)";
  }
  return "";
}

Eigen::Isometry3d toEigen(const ignition::math::Pose3d& pose) {
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  const ignition::math::Quaterniond& q = pose.Rot();
  frame.linear() = Eigen::Quaterniond(q.W(), q.X(), q.Y(), q.Z()).normalized().toRotationMatrix();
  frame.translation() = Eigen::Vector3d(pose.Pos().X(), pose.Pos().Y(), pose.Pos().Z());
  return frame;
}

/// "x y z" (blanks around and between): exactly three numbers, read as the URDF reader reads them (no
/// locale).
bool threeNumbers(const std::string& text, Eigen::Vector3d& out) {
  const char* at = text.c_str();
  for (int i = 0; i < 3; ++i) {
    while (io_detail::isSpace(*at))
      ++at;
    const char* end = at;
    while (*end != '\0' && !io_detail::isSpace(*end))
      ++end;
    const std::optional<double> value = end == at ? std::nullopt : io_detail::parseNumber(at, end);
    if (!value)
      return false;
    out[i] = *value;
    at = end;
  }
  while (io_detail::isSpace(*at))
    ++at;
  return *at == '\0';
}

class SdfConverter {
 public:
  SdfConverter(const sdf::Model& model, std::string file) : model_(model), file_(std::move(file)) {
    mechanism_.file = file_;
    mechanism_.name = model.Name();
  }

  Result<Mechanism> convert(std::vector<Diagnostic> warnings) {
    mechanism_.warnings = std::move(warnings);
    for (uint64_t i = 0; i < model_.ModelCount(); ++i) {
      warn("model", model_.ModelByIndex(i)->Name(), "is a nested model and is not read");
    }
    for (auto add : {&SdfConverter::addLinks, &SdfConverter::addJoints, &SdfConverter::addCustomElements}) {
      if (std::optional<Diagnostic> d = (this->*add)())
        return io_detail::refusalAfter(*d, mechanism_.warnings);
    }
    return std::move(mechanism_);
  }

 private:
  void warn(const std::string& kind, const std::string& name, const std::string& what) {
    mechanism_.warnings.push_back(makeDiagnostic(file_, kind, name, what));
  }

  std::optional<Diagnostic> checkPose(const ignition::math::Pose3d& pose, const std::string& kind,
                                      const std::string& name) const {
    for (const double v : {pose.Pos().X(), pose.Pos().Y(), pose.Pos().Z(), pose.Rot().W(), pose.Rot().X(),
                           pose.Rot().Y(), pose.Rot().Z()}) {
      if (const std::optional<std::string> why = io_detail::checkRange(v))
        return makeDiagnostic(file_, kind, name, "pose " + *why);
    }
    return std::nullopt;
  }

  /// The pose of @p semantic in the model frame, or the Diagnostic with libsdformat's reason.
  std::optional<Diagnostic> resolve(const sdf::SemanticPose& semantic, const std::string& kind,
                                    const std::string& name, Eigen::Isometry3d& out) const {
    ignition::math::Pose3d pose;
    const sdf::Errors errors = semantic.Resolve(pose, kModelFrame);
    if (!errors.empty())
      return makeDiagnostic(file_, kind, name, "pose cannot be resolved: " + errors.front().Message());
    if (std::optional<Diagnostic> d = checkPose(pose, kind, name))
      return d;
    out = toEigen(pose);
    return std::nullopt;
  }

  std::optional<Diagnostic> addLinks() {
    bool toWorld = false;
    for (uint64_t j = 0; j < model_.JointCount(); ++j)
      toWorld = toWorld || model_.JointByIndex(j)->ParentLinkName() == kWorld;
    if (toWorld) {
      linkIndex_[kWorld] = 0;
      mechanism_.links.push_back(Link{kWorld});
      writtenPose_.push_back(Eigen::Isometry3d::Identity());
    }
    for (uint64_t i = 0; i < model_.LinkCount(); ++i) {
      const sdf::Link* link = model_.LinkByIndex(i);
      Eigen::Isometry3d pose;
      if (std::optional<Diagnostic> d = resolve(link->SemanticPose(), "link", link->Name(), pose))
        return d;
      linkIndex_[link->Name()] = static_cast<int>(mechanism_.links.size());
      mechanism_.links.push_back(Link{link->Name()});
      writtenPose_.push_back(pose);
    }
    if (mechanism_.links.empty())
      return makeDiagnostic(file_, "model", model_.Name(), "has no <link>");
    // The ground: the world if a joint names it, else the first link that is no joint's child.
    std::set<std::string> children;
    for (uint64_t j = 0; j < model_.JointCount(); ++j)
      children.insert(model_.JointByIndex(j)->ChildLinkName());
    mechanism_.rootLink = 0;
    if (!toWorld) {
      for (size_t l = 0; l < mechanism_.links.size(); ++l) {
        if (children.count(mechanism_.links[l].name) == 0) {
          mechanism_.rootLink = static_cast<int>(l);
          break;
        }
      }
    }
    return std::nullopt;
  }

  std::optional<Diagnostic> linkOf(const std::string& name, const std::string& jointName, const char* role,
                                   int& index) const {
    const auto it = linkIndex_.find(name);
    if (it == linkIndex_.end())
      return makeDiagnostic(file_, "joint", jointName,
                            std::string(role) + " '" + name + "' is not a link of the model");
    index = it->second;
    return std::nullopt;
  }

  std::optional<Diagnostic> addJoints() {
    struct Pending {
      const sdf::Joint* joint;
      int parent, child;
      JointType type;
      Eigen::Isometry3d frame;  ///< Joint frame in the model frame at the written configuration.
    };
    std::vector<Pending> pending;
    for (uint64_t j = 0; j < model_.JointCount(); ++j) {
      const sdf::Joint* joint = model_.JointByIndex(j);
      const std::string& name = joint->Name();
      if (!names_.insert(name).second)
        return makeDiagnostic(file_, "joint", name, "has the name of another joint");
      Pending p{joint, -1, -1, JointType::Fixed, Eigen::Isometry3d::Identity()};
      if (std::optional<Diagnostic> d = linkOf(joint->ParentLinkName(), name, "parent", p.parent))
        return d;
      if (std::optional<Diagnostic> d = linkOf(joint->ChildLinkName(), name, "child", p.child))
        return d;
      if (p.parent == p.child)
        return makeDiagnostic(file_, "joint", name, "joins link '" + joint->ChildLinkName() + "' to itself");
      switch (joint->Type()) {
        case sdf::JointType::REVOLUTE:
          p.type = JointType::Revolute;
          break;
        case sdf::JointType::CONTINUOUS:
          p.type = JointType::Continuous;
          break;
        case sdf::JointType::PRISMATIC:
          p.type = JointType::Prismatic;
          break;
        case sdf::JointType::BALL:
          p.type = JointType::Spherical;
          break;
        case sdf::JointType::UNIVERSAL:
          p.type = JointType::Universal;
          break;
        case sdf::JointType::FIXED:
          p.type = JointType::Fixed;
          break;
        default:
          return makeDiagnostic(
              file_, "joint", name,
              "type '" + joint->Element()->Get<std::string>("type") +
                  "' is not read (revolute, continuous, prismatic, ball, universal, fixed are)");
      }
      if (std::optional<Diagnostic> d = resolve(joint->SemanticPose(), "joint", name, p.frame))
        return d;
      pending.push_back(p);
    }
    // Walk from the ground, parent to child: a joint whose child is not reached yet is a tree joint.
    std::vector<bool> reached(mechanism_.links.size(), false);
    std::vector<bool> isTree(pending.size(), false);
    linkFrame_.assign(mechanism_.links.size(), Eigen::Isometry3d::Identity());
    const int root = mechanism_.rootLink;
    linkFrame_[root] = writtenPose_[root];
    reached[root] = true;
    std::deque<int> queue = {root};
    while (!queue.empty()) {
      const int link = queue.front();
      queue.pop_front();
      for (size_t k = 0; k < pending.size(); ++k) {
        if (pending[k].parent != link || reached[pending[k].child])
          continue;
        isTree[k] = true;
        reached[pending[k].child] = true;
        linkFrame_[pending[k].child] = pending[k].frame;
        queue.push_back(pending[k].child);
      }
    }
    for (size_t l = 0; l < reached.size(); ++l) {
      if (!reached[l]) {
        return makeDiagnostic(file_, "link", mechanism_.links[l].name,
                              "is not reached from the ground '" + mechanism_.links[root].name +
                                  "' through the joints from parent to child");
      }
    }
    for (const bool tree : {true, false}) {
      for (size_t k = 0; k < pending.size(); ++k) {
        if (isTree[k] != tree)
          continue;
        const Pending& p = pending[k];
        Joint joint;
        joint.name = p.joint->Name();
        joint.kind = tree ? ConnectionKind::TreeJoint : ConnectionKind::LoopJoint;
        joint.type = p.type;
        joint.link1 = p.parent;
        joint.link2 = p.child;
        joint.frame1 = linkFrame_[p.parent].inverse() * p.frame;
        joint.frame2 = tree ? Eigen::Isometry3d::Identity() : linkFrame_[p.child].inverse() * p.frame;
        if (std::optional<Diagnostic> d = readAxes(*p.joint, joint))
          return d;
        mechanism_.joints.push_back(joint);
      }
    }
    return std::nullopt;
  }

  /**
   * The model's elements of other namespaces, which libsdformat keeps without a word: Drake's
   * <drake:ball_constraint> (point P of body A stays at point Q of body B, MultibodyPlant::AddBallConstraint)
   * becomes a spherical loop joint "ball_constraint_<n>"; <drake:collision_filter_group> carries nothing for
   * mobility; any other is a warning, so no constraint is dropped silently.
   */
  std::optional<Diagnostic> addCustomElements() {
    int balls = 0;
    for (sdf::ElementPtr e = model_.Element()->GetFirstElement(); e; e = e->GetNextElement()) {
      const std::string tag = e->GetName();
      if (tag.find(':') == std::string::npos || tag == "drake:collision_filter_group")
        continue;
      if (tag != "drake:ball_constraint") {
        warn(tag, e->HasAttribute("name") ? e->GetAttribute("name")->GetAsString() : "",
             "unknown element <" + tag + "> is not read");
        continue;
      }
      Joint joint;
      joint.name = "ball_constraint_" + std::to_string(balls++);
      if (!names_.insert(joint.name).second)
        return makeDiagnostic(file_, tag, joint.name, "has the name of another joint");
      joint.kind = ConnectionKind::LoopJoint;
      joint.type = JointType::Spherical;
      auto text = [&](const char* part, std::string& out) -> std::optional<Diagnostic> {
        const std::string child = std::string("drake:ball_constraint_") + part;
        if (!e->HasElement(child) || !e->GetElement(child)->GetValue())
          return makeDiagnostic(file_, tag, joint.name, "missing <" + child + ">");
        out = e->GetElement(child)->GetValue()->GetAsString();
        return std::nullopt;
      };
      std::string bodies[2], points[2];
      for (int side = 0; side < 2; ++side) {
        if (std::optional<Diagnostic> d = text(side == 0 ? "body_A" : "body_B", bodies[side]))
          return d;
        if (std::optional<Diagnostic> d = text(side == 0 ? "p_AP" : "p_BQ", points[side]))
          return d;
      }
      int links[2];
      for (int side = 0; side < 2; ++side) {
        const auto it = linkIndex_.find(bodies[side]);
        if (it == linkIndex_.end())
          return makeDiagnostic(file_, tag, joint.name,
                                std::string(side == 0 ? "body_A" : "body_B") + " '" + bodies[side] +
                                    "' is not a link of the model");
        links[side] = it->second;
        Eigen::Vector3d point;
        if (!threeNumbers(points[side], point))
          return makeDiagnostic(
              file_, tag, joint.name,
              std::string(side == 0 ? "p_AP" : "p_BQ") + " '" + points[side] + "' is not three numbers");
        for (int i = 0; i < 3; ++i) {
          if (const std::optional<std::string> why = io_detail::checkRange(point[i]))
            return makeDiagnostic(file_, tag, joint.name, std::string(side == 0 ? "p_AP " : "p_BQ ") + *why);
        }
        // The point is in the body's SDFormat frame; a link's frame here is its tree joint's.
        Eigen::Isometry3d& frame = side == 0 ? joint.frame1 : joint.frame2;
        frame = Eigen::Isometry3d::Identity();
        frame.translation() = linkFrame_[static_cast<size_t>(links[side])].inverse() *
                              (writtenPose_[static_cast<size_t>(links[side])] * point);
      }
      if (links[0] == links[1])
        return makeDiagnostic(file_, tag, joint.name, "joins link '" + bodies[0] + "' to itself");
      joint.link1 = links[0];
      joint.link2 = links[1];
      mechanism_.joints.push_back(joint);
    }
    return std::nullopt;
  }

  /// The joint's axes in its own frame (SDFormat resolves `expressed_in`).
  std::optional<Diagnostic> readAxes(const sdf::Joint& sdfJoint, Joint& joint) {
    const bool needsAxis = joint.type == JointType::Revolute || joint.type == JointType::Continuous ||
                           joint.type == JointType::Prismatic || joint.type == JointType::Universal;
    if (!needsAxis)
      return std::nullopt;
    for (unsigned int index = 0; index < (joint.type == JointType::Universal ? 2u : 1u); ++index) {
      const char* tag = index == 0 ? "axis" : "axis2";
      Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
      if (const sdf::JointAxis* sdfAxis = sdfJoint.Axis(index)) {
        ignition::math::Vector3d xyz;
        const sdf::Errors errors = sdfAxis->ResolveXyz(xyz);
        if (!errors.empty())
          return makeDiagnostic(file_, "joint", joint.name,
                                std::string(tag) + " cannot be resolved: " + errors.front().Message());
        axis = Eigen::Vector3d(xyz.X(), xyz.Y(), xyz.Z());
        for (int i = 0; i < 3; ++i) {
          if (const std::optional<std::string> why = io_detail::checkRange(axis[i]))
            return makeDiagnostic(file_, "joint", joint.name, std::string(tag) + " " + *why);
        }
        if (axis.norm() < tolerances::kZeroVector)
          return makeDiagnostic(file_, "joint", joint.name, std::string(tag) + " is the zero vector");
      } else {
        warn("joint", joint.name,
             std::string("type ") + toString(joint.type) + " has no <" + tag + ">; " + tag +
                 " defaulted to 0 0 1 (SDFormat's default)");
      }
      (index == 0 ? joint.axis : joint.axis2) = axis.normalized();
    }
    if (joint.type == JointType::Universal && joint.axis.cross(joint.axis2).norm() < tolerances::kPlanarAxis)
      return makeDiagnostic(file_, "joint", joint.name,
                            "universal joint axes 'axis' and 'axis2' are parallel");
    return std::nullopt;
  }

  const sdf::Model& model_;
  std::string file_;
  Mechanism mechanism_;
  std::map<std::string, int> linkIndex_;
  std::vector<Eigen::Isometry3d> writtenPose_;  ///< Each link's SDFormat frame in the model frame.
  std::vector<Eigen::Isometry3d>
      linkFrame_;  ///< Each link's frame here (its tree joint's) in the model frame.
  std::set<std::string> names_;
};

/// readSdf, with libsdformat: this file is the plugin libmobility_analysis_sdf.so (SdfReaderPlugin.cpp).
Result<Mechanism> readSdfWithLibsdformat(const std::string& sdfText, const std::string& fileName) {
  const std::string file = io_detail::baseName(fileName);
  sdf::ParserConfig config;
  // Elements SDFormat does not define come back as errors (the model still loads): they become warnings.
  config.SetUnrecognizedElementsPolicy(sdf::EnforcementPolicy::ERR);
  config.SetDeprecatedElementsPolicy(sdf::EnforcementPolicy::ERR);
  sdf::Root root;
  // libsdformat would also print its errors to stderr and append them to ~/.sdformat/sdformat.log: every
  // error comes back here as a Diagnostic instead, so both streams are muted while it parses.
  sdf::Console::ConsoleStream& messages = sdf::Console::Instance()->GetMsgStream();
  sdf::Console::ConsoleStream& log = sdf::Console::Instance()->GetLogStream();
  std::ostream* const messageStream = messages.GetStream();
  std::ostream* const logStream = log.GetStream();
  messages.SetStream(nullptr);
  log.SetStream(nullptr);
  const sdf::Errors errors = root.LoadSdfString(sdfText, config);
  messages.SetStream(messageStream);
  log.SetStream(logStream);
  std::vector<Diagnostic> warnings;
  for (const sdf::Error& error : errors) {
    const auto [kind, name] = lastStep(error.XmlPath());
    const std::string message = error.Message();
    if (message.find("not defined in SDF") != std::string::npos) {
      warnings.push_back(
          makeDiagnostic(file, kind, name, "unknown element <" + kind + "> is not read" + didYouMean(kind)));
    } else if (error.Code() == sdf::ErrorCode::ELEMENT_DEPRECATED ||
               error.Code() == sdf::ErrorCode::ATTRIBUTE_DEPRECATED ||
               error.Code() == sdf::ErrorCode::VERSION_DEPRECATED) {
      warnings.push_back(makeDiagnostic(file, kind, name, message));
    } else {
      return io_detail::refusalAfter(
          makeDiagnostic(file, kind, name, "libsdformat rejected the model: " + message), warnings);
    }
  }
  const sdf::Model* model = root.Model();
  if (model == nullptr && root.WorldCount() > 0) {
    const sdf::World* world = root.WorldByIndex(0);
    for (uint64_t i = 1; i < world->ModelCount(); ++i) {
      warnings.push_back(makeDiagnostic(file, "model", world->ModelByIndex(i)->Name(),
                                        "is not read (only the first model is)"));
    }
    if (world->ModelCount() > 0)
      model = world->ModelByIndex(0);
  }
  if (model == nullptr)
    return makeDiagnostic(file, "sdf", "", "has no <model>");
  return SdfConverter(*model, file).convert(std::move(warnings));
}

}  // namespace

}  // namespace mobility_analysis

/// The plugin's entry point, found by name (SdfReaderPlugin.hpp).
extern "C" __attribute__((visibility("default"))) mobility_analysis::io_detail::SdfReadFunction
mobility_analysis_sdf_reader() {
  return &mobility_analysis::readSdfWithLibsdformat;
}
