#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis {

std::optional<int> Mechanism::findLink(const std::string& linkName) const {
  for (size_t i = 0; i < links.size(); ++i) {
    if (links[i].name == linkName) {
      return static_cast<int>(i);
    }
  }
  return std::nullopt;
}

std::optional<int> Mechanism::findJoint(const std::string& jointName) const {
  for (size_t i = 0; i < joints.size(); ++i) {
    if (joints[i].name == jointName) {
      return static_cast<int>(i);
    }
  }
  return std::nullopt;
}

std::optional<int> Mechanism::findParentJoint(int link) const {
  for (size_t i = 0; i < joints.size(); ++i) {
    if (joints[i].kind == ConnectionKind::TreeJoint && joints[i].link2 == link) {
      return static_cast<int>(i);
    }
  }
  return std::nullopt;
}

std::vector<int> coupledJoints(const Joint& coupling) {
  std::vector<int> joints = {coupling.follower, coupling.leader};
  for (const std::vector<WeightedJoint>* more : {&coupling.moreFollowers, &coupling.moreLeaders}) {
    for (const WeightedJoint& j : *more)
      joints.push_back(j.joint);
  }
  return joints;
}

bool hasSingleValue(const Joint& joint) {
  return joint.kind == ConnectionKind::TreeJoint &&
         (joint.type == JointType::Revolute || joint.type == JointType::Continuous ||
          joint.type == JointType::Prismatic);
}

const char* toString(JointType type) {
  switch (type) {
    case JointType::Revolute:
      return "revolute";
    case JointType::Continuous:
      return "continuous";
    case JointType::Prismatic:
      return "prismatic";
    case JointType::Cylindrical:
      return "cylindrical";
    case JointType::Spherical:
      return "spherical";
    case JointType::Universal:
      return "universal";
    case JointType::Planar:
      return "planar";
    case JointType::Fixed:
      return "fixed";
    case JointType::Floating:
      return "floating";
  }
  return "unknown";
}

const char* toString(ConnectionKind kind) {
  switch (kind) {
    case ConnectionKind::TreeJoint:
      return "joint";
    case ConnectionKind::DistanceConstraint:
      return "distance_constraint";
    case ConnectionKind::Cable:
      return "cable";
    case ConnectionKind::LoopJoint:
      return "loop_joint";
    case ConnectionKind::Coupling:
      return "coupling";
  }
  return "unknown";
}

}  // namespace mobility_analysis
