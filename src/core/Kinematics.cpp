#include "mobility_analysis/Kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string_view>
#include <utility>
#include <vector>

#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

/// URDF joint motion: a turn about, or a slide along, the joint axis.
Eigen::Isometry3d jointMotion(const Joint& joint, double value) {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  if (joint.type == JointType::Revolute || joint.type == JointType::Continuous) {
    motion.linear() = Eigen::AngleAxisd(value, joint.axis).toRotationMatrix();
  } else if (joint.type == JointType::Prismatic) {
    motion.translation() = value * joint.axis;
  }
  return motion;
}

/// A name's place in a sort by name: its first eight bytes after the prefix all names share, big-endian
/// (zero where it ends), and its index.
struct NameKey {
  uint64_t key;
  uint32_t index;
};

/**
 * @brief @p values' names keyed (NameKey) and sorted by name, equal names in their order in @p values (a
 *        stable sort by name).
 *
 * Names of 10^5 joints share their prefix ("joint_"): a string comparison was a call to memcmp over it and a
 * cache miss on each of the two joints, most of the map's time. Keys order as the names do wherever they
 * differ, so names are compared only when their keys are equal.
 */
std::vector<NameKey> sortedByName(const std::vector<std::pair<std::string_view, double>>& values) {
  size_t prefix = values.empty() ? 0 : values.front().first.size();
  for (const auto& value : values) {
    const std::string_view name = value.first, first = values.front().first;
    size_t common = 0;
    while (common < prefix && common < name.size() && name[common] == first[common])
      ++common;
    prefix = common;
  }
  std::vector<NameKey> keyed(values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    const std::string_view name = values[i].first;
    uint64_t key = 0;
    for (size_t b = 0; b < 8; ++b) {
      const size_t at = prefix + b;
      key = (key << 8) | (at < name.size() ? static_cast<unsigned char>(name[at]) : 0u);
    }
    keyed[i] = NameKey{key, static_cast<uint32_t>(i)};
  }
  std::stable_sort(keyed.begin(), keyed.end(), [&values](const NameKey& a, const NameKey& b) {
    return a.key != b.key ? a.key < b.key : values[a.index].first < values[b.index].first;
  });
  return keyed;
}

/**
 * @brief The map of @p values (name, value), the last value of a name kept, as operator[] in their order
 * gave.
 *
 * Joint names are rarely written in their lexicographic order (joint_9 before joint_10): inserted in joint
 * order, each would search the map (a dozen string comparisons and as many cache misses on 10^5 joints).
 * Sorted first, each is inserted at the end in constant time.
 */
JointPositions toJointPositions(const std::vector<std::pair<std::string_view, double>>& values) {
  const std::vector<NameKey> sorted = sortedByName(values);
  JointPositions positions;
  for (size_t i = 0; i < sorted.size(); ++i) {
    const std::pair<std::string_view, double>& value = values[sorted[i].index];
    if (i + 1 < sorted.size() && sorted[i + 1].key == sorted[i].key &&
        values[sorted[i + 1].index].first == value.first)
      continue;  // a later value of the same name
    positions.emplace_hint(positions.end(), std::string(value.first), value.second);
  }
  return positions;
}

}  // namespace

LinkPoses computeTreePoses(const Mechanism& mechanism, const JointPositions& positions) {
  const size_t numLinks = mechanism.links.size();
  LinkPoses poses(numLinks, Eigen::Isometry3d::Identity());
  std::vector<int> parentJoint(numLinks, -1);
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    if (mechanism.joints[j].kind == ConnectionKind::TreeJoint) {
      parentJoint[mechanism.joints[j].link2] = static_cast<int>(j);
    }
  }
  std::vector<bool> done(numLinks, false);
  done[mechanism.rootLink] = true;
  // The loader guarantees a tree; resolve each link after its parent.
  std::vector<int> chain;
  for (size_t link = 0; link < numLinks; ++link) {
    chain.clear();
    for (int l = static_cast<int>(link); !done[l]; l = mechanism.joints[parentJoint[l]].link1) {
      chain.push_back(l);
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const Joint& joint = mechanism.joints[parentJoint[*it]];
      const auto value = positions.find(joint.name);
      poses[*it] = poses[joint.link1] * joint.frame1 *
                   jointMotion(joint, value == positions.end() ? 0.0 : value->second);
      done[*it] = true;
    }
  }
  return poses;
}

JointPositions computeJointPositions(const Mechanism& mechanism, const LinkPoses& poses,
                                     const JointPositions& reference) {
  std::vector<std::pair<std::string_view, double>> values;
  values.reserve(mechanism.joints.size());
  for (const Joint& joint : mechanism.joints) {
    if (!hasSingleValue(joint))
      continue;
    const bool turns = joint.type == JointType::Revolute || joint.type == JointType::Continuous;
    // The child frame is the joint frame moved by motion(value): T = (T_parent * origin)^-1 * T_child.
    const Eigen::Isometry3d motion = (poses[joint.link1] * joint.frame1).inverse() * poses[joint.link2];
    double value = 0.0;
    if (turns) {
      const Eigen::Vector3d v = joint.axis.unitOrthogonal();
      const Eigen::Vector3d turned = motion.linear() * v;
      value = std::atan2(joint.axis.dot(v.cross(turned)), v.dot(turned));
      const auto previous = reference.find(joint.name);
      if (previous != reference.end())
        value += 2.0 * M_PI * std::round((previous->second - value) / (2.0 * M_PI));
    } else {
      value = joint.axis.dot(motion.translation());
    }
    values.emplace_back(joint.name, value);
  }
  return toJointPositions(values);
}

JointPositions writtenJointPositions(const Mechanism& mechanism) {
  std::vector<std::pair<std::string_view, double>> values;
  values.reserve(mechanism.joints.size());
  for (const Joint& joint : mechanism.joints) {
    if (hasSingleValue(joint))
      values.emplace_back(joint.name, 0.0);
  }
  return toJointPositions(values);
}

double computeJointResidual(const Mechanism& mechanism, const LinkPoses& poses, int jointIndex,
                            double lengthScale) {
  const Joint& joint = mechanism.joints[jointIndex];
  if (joint.kind == ConnectionKind::Coupling) {
    // value(follower) - multiplier value(leader) - offset, in the follower's unit.
    const JointPositions values = computeJointPositions(mechanism, poses);
    auto value = [&](int j) {
      const auto it = values.find(mechanism.joints[j].name);
      return it == values.end() ? 0.0 : it->second;
    };
    const auto [follower, leader] = couplingSides(joint, value);
    const double residual = std::abs(follower - joint.multiplier * leader - joint.offset);
    return mechanism.joints[joint.follower].type == JointType::Prismatic ? residual : lengthScale * residual;
  }
  if (joint.kind == ConnectionKind::DistanceConstraint || joint.kind == ConnectionKind::Cable ||
      joint.type == JointType::Floating) {
    return 0.0;  // a distance constraint takes its length from the pose; cables are checked for tautness
  }
  const Eigen::Isometry3d f1 = poses[joint.link1] * joint.frame1;
  const Eigen::Isometry3d f2 = poses[joint.link2] * joint.frame2;
  const Eigen::Vector3d offset = f2.translation() - f1.translation();
  const Eigen::Vector3d a1 = f1.linear() * joint.axis;
  const Eigen::Vector3d a2 = f2.linear() * joint.axis;
  const double axisError = a1.cross(a2).norm() + std::max(0.0, -a1.dot(a2));
  const double frameError = (f1.linear() - f2.linear()).norm();
  switch (joint.type) {
    case JointType::Revolute:
    case JointType::Continuous:
      return offset.norm() + lengthScale * axisError;
    case JointType::Prismatic:
      return offset.cross(a1).norm() + lengthScale * frameError;
    case JointType::Cylindrical:
      return offset.cross(a1).norm() + lengthScale * axisError;
    case JointType::Spherical:
      return offset.norm();
    case JointType::Universal:
      return offset.norm() +
             lengthScale * std::abs(a1.dot(f2.linear() * joint.axis2) - joint.axis.dot(joint.axis2));
    case JointType::Planar:
      return std::abs(offset.dot(a1)) + lengthScale * axisError;
    case JointType::Fixed:
      return offset.norm() + lengthScale * frameError;
    case JointType::Floating:
      return 0.0;
  }
  return 0.0;
}

double computeCharacteristicLength(const Mechanism& mechanism, const LinkPoses& poses) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(2 * mechanism.joints.size());
  for (const Joint& joint : mechanism.joints) {
    if (joint.type == JointType::Floating || joint.kind == ConnectionKind::Coupling) {
      continue;
    }
    points.push_back(poses[joint.link1] * joint.frame1.translation());
    points.push_back(poses[joint.link2] * joint.frame2.translation());
  }
  if (points.size() < 2) {
    return 1.0;
  }
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    centroid += p;
  }
  centroid /= static_cast<double>(points.size());
  double sum = 0.0;
  for (const Eigen::Vector3d& p : points) {
    sum += (p - centroid).squaredNorm();
  }
  const double rms = std::sqrt(sum / static_cast<double>(points.size()));
  return rms > tolerances::kZeroVector ? rms : 1.0;
}

}  // namespace mobility_analysis
