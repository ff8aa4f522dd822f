#include "mobility_analysis/io/MjcfReader.hpp"

#include <cmath>
#include <memory>
#include <unordered_set>

#include <mujoco/mujoco.h>

#include "XmlValues.hpp"
#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

struct ModelDeleter {
  void operator()(mjModel* model) const { mj_deleteModel(model); }
};
using ModelPointer = std::unique_ptr<mjModel, ModelDeleter>;

/// MuJoCo's warnings during one load: its default handler would print them and write MUJOCO_LOG.TXT.
thread_local std::vector<std::string>* collectedWarnings = nullptr;

void collectWarning(const char* message) {
  if (collectedWarnings != nullptr)
    collectedWarnings->push_back(message == nullptr ? "" : message);
}

Eigen::Isometry3d bodyInParent(const mjModel& m, int body) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const mjtNum* p = m.body_pos + 3 * body;
  const mjtNum* q = m.body_quat + 4 * body;  // w x y z
  pose.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  pose.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
  return pose;
}

class MjcfConverter {
 public:
  MjcfConverter(const mjModel& m, std::string file) : m_(m), file_(std::move(file)) {
    mechanism_.file = file_;
  }

  Result<Mechanism> convert() {
    mechanism_.name = m_.nnames > 0 && m_.names != nullptr ? std::string(m_.names) : "mjcf";
    // Every number MuJoCo computed must be representable before it becomes geometry.
    for (int i = 0; i < 3 * m_.nbody; ++i) {
      if (const std::optional<std::string> why = io_detail::checkRange(m_.body_pos[i]))
        return makeDiagnostic(file_, "body", bodyName(i / 3), "pos " + *why);
    }
    for (int i = 0; i < 3 * m_.njnt; ++i) {
      if (const std::optional<std::string> why = io_detail::checkRange(m_.jnt_pos[i]))
        return makeDiagnostic(file_, "joint", jointName(i / 3), "pos " + *why);
    }
    linkOfBody_.assign(m_.nbody, -1);
    linkFromBody_.assign(m_.nbody, Eigen::Isometry3d::Identity());
    treeJointOf_.assign(m_.njnt, -1);
    addLink("world");
    linkOfBody_[0] = 0;
    mechanism_.rootLink = 0;
    // MuJoCo orders bodies so that a parent comes before its children: one pass, no recursion.
    for (int b = 1; b < m_.nbody; ++b) {
      if (std::optional<Diagnostic> d = addBody(b))
        return *d;
    }
    for (int e = 0; e < m_.neq; ++e) {
      if (std::optional<Diagnostic> d = addEquality(e))
        return *d;
    }
    return std::move(mechanism_);
  }

 private:
  std::string bodyName(int b) const {
    const char* name = mj_id2name(&m_, mjOBJ_BODY, b);
    return name != nullptr && *name != '\0' ? name : "body" + std::to_string(b);
  }
  std::string jointName(int j) const {
    const char* name = mj_id2name(&m_, mjOBJ_JOINT, j);
    return name != nullptr && *name != '\0' ? name : "joint" + std::to_string(j);
  }
  std::string equalityName(int e) const {
    const char* name = mj_id2name(&m_, mjOBJ_EQUALITY, e);
    return name != nullptr && *name != '\0' ? name : "equality" + std::to_string(e);
  }

  int addLink(const std::string& name) {
    mechanism_.links.push_back(Link{name});
    return static_cast<int>(mechanism_.links.size()) - 1;
  }

  std::optional<Diagnostic> claim(const std::string& kind, const std::string& name) {
    if (!names_.insert(name).second)
      return makeDiagnostic(file_, kind, name, "has the name of another joint or constraint");
    return std::nullopt;
  }

  /// A body and its joints. Our tree joints put the child's frame at the joint (Joint::frame2 = identity), so
  /// each link's frame is its body's frame moved to the body's last joint; linkFromBody_ remembers the move.
  std::optional<Diagnostic> addBody(int b) {
    const int parentBody = m_.body_parentid[b];
    int parentLink = linkOfBody_[parentBody];
    // Where the body frame is in the parent link's frame.
    Eigen::Isometry3d previous = linkFromBody_[parentBody] * bodyInParent(m_, b);
    const std::string name = bodyName(b);
    const int count = m_.body_jntnum[b];
    if (count == 0) {
      const int link = addLink(name);
      Joint joint;
      joint.name = "fixed_" + name;
      if (std::optional<Diagnostic> d = claim("joint", joint.name))
        return d;
      joint.kind = ConnectionKind::TreeJoint;
      joint.type = JointType::Fixed;
      joint.link1 = parentLink;
      joint.link2 = link;
      joint.frame1 = previous;
      mechanism_.joints.push_back(joint);
      linkOfBody_[b] = link;
      return std::nullopt;
    }
    Eigen::Vector3d previousPos = Eigen::Vector3d::Zero();  // the joint position the previous link sits at
    for (int k = 0; k < count; ++k) {
      const int j = m_.body_jntadr[b] + k;
      const Eigen::Vector3d pos(m_.jnt_pos[3 * j], m_.jnt_pos[3 * j + 1], m_.jnt_pos[3 * j + 2]);
      const Eigen::Vector3d axis(m_.jnt_axis[3 * j], m_.jnt_axis[3 * j + 1], m_.jnt_axis[3 * j + 2]);
      const bool last = k + 1 == count;
      const int link = addLink(last ? name : name + "/" + jointName(j));
      Joint joint;
      joint.name = jointName(j);
      if (std::optional<Diagnostic> d = claim("joint", joint.name))
        return d;
      joint.kind = ConnectionKind::TreeJoint;
      switch (m_.jnt_type[j]) {
        case mjJNT_HINGE:
          joint.type = JointType::Revolute;
          break;
        case mjJNT_SLIDE:
          joint.type = JointType::Prismatic;
          break;
        case mjJNT_BALL:
          joint.type = JointType::Spherical;
          break;
        default:
          joint.type = JointType::Floating;
          break;
      }
      if (axis.norm() < tolerances::kZeroVector)
        return makeDiagnostic(file_, "joint", joint.name, "axis is the zero vector");
      joint.axis = axis.normalized();  // in the body frame, which is the joint frame's orientation
      joint.link1 = parentLink;
      joint.link2 = link;
      Eigen::Isometry3d jointInBody = Eigen::Isometry3d::Identity();
      jointInBody.translation() = pos;
      if (k == 0) {
        joint.frame1 = previous * jointInBody;
      } else {
        joint.frame1 = Eigen::Isometry3d::Identity();
        joint.frame1.translation() = pos - previousPos;
      }
      treeJointOf_[j] = static_cast<int>(mechanism_.joints.size());
      mechanism_.joints.push_back(joint);
      parentLink = link;
      previousPos = pos;
    }
    linkOfBody_[b] = parentLink;
    Eigen::Isometry3d bodyToLink = Eigen::Isometry3d::Identity();
    bodyToLink.translation() = -previousPos;
    linkFromBody_[b] = bodyToLink;
    return std::nullopt;
  }

  /// World pose of a body at the reference configuration.
  Eigen::Isometry3d worldPose(int b) const {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    for (int body = b; body > 0; body = m_.body_parentid[body])
      pose = bodyInParent(m_, body) * pose;
    return pose;
  }

  std::optional<Diagnostic> addEquality(int e) {
    const std::string name = equalityName(e);
    const int type = m_.eq_type[e];
    const char* kind = type == mjEQ_CONNECT  ? "connect"
                       : type == mjEQ_WELD   ? "weld"
                       : type == mjEQ_JOINT  ? "joint"
                       : type == mjEQ_TENDON ? "tendon"
                                             : "equality";
    if (!m_.eq_active[e]) {
      mechanism_.warnings.push_back(
          makeDiagnostic(file_, kind, name, "is inactive in the model and is not read"));
      return std::nullopt;
    }
    const mjtNum* data = m_.eq_data + mjNEQDATA * e;
    if (type == mjEQ_CONNECT || type == mjEQ_WELD) {
      const int body1 = m_.eq_obj1id[e];
      const int body2 = m_.eq_obj2id[e] < 0 ? 0 : m_.eq_obj2id[e];
      if (body1 == body2)
        return makeDiagnostic(file_, kind, name, "joins body '" + bodyName(body1) + "' to itself");
      Joint joint;
      joint.name = name;
      if (std::optional<Diagnostic> d = claim(kind, name))
        return d;
      joint.kind = ConnectionKind::LoopJoint;
      joint.type = type == mjEQ_CONNECT ? JointType::Spherical : JointType::Fixed;
      joint.link1 = linkOfBody_[body1];
      joint.link2 = linkOfBody_[body2];
      // The joint frame on body1: its anchor (connect) or its origin (weld); on body2 the same world frame at
      // the reference configuration, where MuJoCo takes the constraint to hold.
      Eigen::Isometry3d onBody1 = Eigen::Isometry3d::Identity();
      if (type == mjEQ_CONNECT) {
        for (int i = 0; i < 3; ++i) {
          if (const std::optional<std::string> why = io_detail::checkRange(data[i]))
            return makeDiagnostic(file_, kind, name, "anchor " + *why);
        }
        onBody1.translation() = Eigen::Vector3d(data[0], data[1], data[2]);
      }
      const Eigen::Isometry3d world = worldPose(body1) * onBody1;
      joint.frame1 = linkFromBody_[body1] * onBody1;
      joint.frame2 = linkFromBody_[body2] * worldPose(body2).inverse() * world;
      mechanism_.joints.push_back(joint);
      return std::nullopt;
    }
    if (type == mjEQ_JOINT) {
      const int follower = m_.eq_obj1id[e];
      const int leader = m_.eq_obj2id[e];
      if (leader < 0) {
        mechanism_.warnings.push_back(makeDiagnostic(
            file_, kind, name,
            "has no joint2 (it holds '" + jointName(follower) + "' at a value) and is not read"));
        return std::nullopt;
      }
      auto oneFreedom = [&](int j) { return m_.jnt_type[j] == mjJNT_HINGE || m_.jnt_type[j] == mjJNT_SLIDE; };
      if (!oneFreedom(follower) || !oneFreedom(leader))
        return makeDiagnostic(file_, kind, name, "couples a joint that is not a hinge or slide");
      if (std::optional<Diagnostic> d = readLinearPolycoef(data, kind, name))
        return d;
      Joint joint;
      joint.follower = treeJointOf_[follower];
      joint.leader = treeJointOf_[leader];
      joint.offset = data[0];
      joint.multiplier = data[1];
      return addCoupling(kind, name, std::move(joint));
    }
    if (type == mjEQ_TENDON)
      return addTendonEquality(e, name, data);
    mechanism_.warnings.push_back(
        makeDiagnostic(file_, kind, name, "is an equality of a type that is not read"));
    return std::nullopt;
  }

  /// A joint or tendon equality's polycoef: offset and slope are read (a refusal when out of range), higher
  /// terms are a warning.
  std::optional<Diagnostic> readLinearPolycoef(const mjtNum* data, const char* kind,
                                               const std::string& name) {
    if (data[2] != 0.0 || data[3] != 0.0 || data[4] != 0.0) {
      mechanism_.warnings.push_back(makeDiagnostic(
          file_, kind, name, "has polynomial terms above the linear one; only offset and slope are read"));
    }
    for (int i = 0; i < 2; ++i) {
      if (const std::optional<std::string> why = io_detail::checkRange(data[i]))
        return makeDiagnostic(file_, kind, name, "polycoef " + *why);
    }
    return std::nullopt;
  }

  /// The hinges and coefficients of fixed tendon @p t (length = sum coef qpos), or nothing when it is not one
  /// over hinges alone (a spatial tendon's length is no sum of joint values; a slide would mix units).
  std::optional<std::vector<WeightedJoint>> fixedTendonOverHinges(int t) const {
    std::vector<WeightedJoint> terms;
    for (int k = m_.tendon_adr[t]; k < m_.tendon_adr[t] + m_.tendon_num[t]; ++k) {
      const int j = m_.wrap_objid[k];
      if (m_.wrap_type[k] != mjWRAP_JOINT || m_.jnt_type[j] != mjJNT_HINGE)
        return std::nullopt;
      terms.push_back(WeightedJoint{treeJointOf_[j], m_.wrap_prm[k]});
    }
    return terms;
  }

  /**
   * MuJoCo's tendon equality over fixed tendons: L1 - L1_0 = c0 + c1 (L2 - L2_0) (without tendon2: = c0),
   * with L = sum coef qpos, so in the joint values v = q - q0 one linear coupling. It is written in the first
   * joint of tendon1 (divided by its coefficient): the rest of tendon1 are moreFollowers; tendon2's first
   * joint is the leader and the rest moreLeaders, or without tendon2 tendon1's second joint is the leader.
   */
  std::optional<Diagnostic> addTendonEquality(int e, const std::string& name, const mjtNum* data) {
    const char* kind = "tendon";
    const int tendon1 = m_.eq_obj1id[e], tendon2 = m_.eq_obj2id[e];
    std::optional<std::vector<WeightedJoint>> first = fixedTendonOverHinges(tendon1);
    std::optional<std::vector<WeightedJoint>> second =
        tendon2 >= 0 ? fixedTendonOverHinges(tendon2) : std::vector<WeightedJoint>{};
    if (!first || !second) {
      mechanism_.warnings.push_back(makeDiagnostic(
          file_, kind, name, "couples a tendon that is not a fixed tendon over hinges, and is not read"));
      return std::nullopt;
    }
    if (std::optional<Diagnostic> d = readLinearPolycoef(data, kind, name))
      return d;
    // Leader side: tendon2 scaled by the slope, or tendon1's second joint moved across.
    std::vector<WeightedJoint> leaders;
    for (const WeightedJoint& j : *second)
      leaders.push_back(WeightedJoint{j.joint, data[1] * j.weight});
    std::vector<WeightedJoint>& followers = *first;
    if (tendon2 < 0 && followers.size() >= 2) {
      leaders.push_back(WeightedJoint{followers[1].joint, -followers[1].weight});
      followers.erase(followers.begin() + 1);
    }
    if (followers.empty() || leaders.empty() || followers[0].weight == 0.0 || leaders[0].weight == 0.0) {
      mechanism_.warnings.push_back(makeDiagnostic(
          file_, kind, name, "holds one joint at a value (or has a zero coefficient) and is not read"));
      return std::nullopt;
    }
    Joint joint;
    const double f = followers[0].weight, l = leaders[0].weight;
    joint.follower = followers[0].joint;
    joint.leader = leaders[0].joint;
    joint.multiplier = l / f;
    joint.offset = data[0] / f;
    for (size_t k = 1; k < followers.size(); ++k)
      joint.moreFollowers.push_back(WeightedJoint{followers[k].joint, followers[k].weight / f});
    for (size_t k = 1; k < leaders.size(); ++k)
      joint.moreLeaders.push_back(WeightedJoint{leaders[k].joint, leaders[k].weight / l});
    return addCoupling(kind, name, std::move(joint));
  }

  /// @p coupling (its joints, multiplier and offset set) named @p name, with its kind, type and links; kept
  /// for after the loop joints (couplings_).
  std::optional<Diagnostic> addCoupling(const char* kind, const std::string& name, Joint coupling) {
    if (std::optional<Diagnostic> d = claim(kind, name))
      return d;
    coupling.name = name;
    coupling.kind = ConnectionKind::Coupling;
    coupling.type = mechanism_.joints[coupling.follower].type;
    coupling.link1 = mechanism_.joints[coupling.follower].link2;
    coupling.link2 = mechanism_.joints[coupling.leader].link2;
    couplings_.push_back(std::move(coupling));
    return std::nullopt;
  }

 public:
  /// Couplings go after every loop joint (DESIGN.md §3).
  void appendCouplings(Mechanism& mechanism) const {
    for (const Joint& joint : couplings_)
      mechanism.joints.push_back(joint);
  }

 private:
  const mjModel& m_;
  std::string file_;
  Mechanism mechanism_;
  std::vector<int> linkOfBody_;
  std::vector<Eigen::Isometry3d> linkFromBody_;  ///< Body frame -> its link's frame.
  std::vector<int> treeJointOf_;
  std::unordered_set<std::string> names_;
  std::vector<Joint> couplings_;
};

}  // namespace

Result<Mechanism> readMjcf(const std::string& path) {
  const std::string file = io_detail::baseName(path);
  char error[1024] = {0};
  std::vector<std::string> warnings;
  collectedWarnings = &warnings;
  void (*previousHandler)(const char*) = mju_user_warning;
  mju_user_warning = collectWarning;
  ModelPointer model(mj_loadXML(path.c_str(), nullptr, error, sizeof(error)));
  mju_user_warning = previousHandler;
  collectedWarnings = nullptr;
  if (!model) {
    return makeDiagnostic(file, "mujoco", "", std::string("MuJoCo rejected the model: ") + error);
  }
  MjcfConverter converter(*model, file);
  Result<Mechanism> mechanism = converter.convert();
  if (isOk(mechanism)) {
    converter.appendCouplings(std::get<Mechanism>(mechanism));
    for (const std::string& warning : warnings)
      std::get<Mechanism>(mechanism).warnings.push_back(makeDiagnostic(file, "mujoco", "", warning));
  }
  return mechanism;
}

}  // namespace mobility_analysis
