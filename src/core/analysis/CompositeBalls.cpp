#include "mobility_analysis/analysis/CompositeBalls.hpp"

#include <cmath>
#include <optional>

#include <Eigen/Dense>
#include <Eigen/Geometry>

namespace mobility_analysis {

namespace {

/// The three axes meet when each passes within this fraction of the length scale of their common point [-].
constexpr double kConcurrent = 1e-8;
/// ... and span space when |det(a1, a2, a3)| of their unit directions is above this (a ball in gimbal lock
/// is not one) [-].
constexpr double kSpanning = 1e-3;

bool isRevolute(const Joint& joint) {
  return joint.type == JointType::Revolute || joint.type == JointType::Continuous;
}

/// Per link, how many connections it has and the first two of them.
struct LinkConnections {
  int count = 0;
  std::array<int, 2> first{-1, -1};
  int other(int joint) const { return first[0] == joint ? first[1] : first[0]; }
};

std::vector<LinkConnections> connectionsOfLinks(const Mechanism& mechanism) {
  std::vector<LinkConnections> links(mechanism.links.size());
  auto add = [&](int link, int joint) {
    LinkConnections& at = links[static_cast<size_t>(link)];
    if (at.count < 2)
      at.first[static_cast<size_t>(at.count)] = joint;
    ++at.count;
  };
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const Joint& joint = mechanism.joints[j];
    if (joint.kind == ConnectionKind::Coupling) {
      // A coupled revolute is driven by another joint: not a free ball.
      for (const int t : coupledJoints(joint)) {
        if (t >= 0) {
          const Joint& c = mechanism.joints[static_cast<size_t>(t)];
          add(c.link1, -1);
          add(c.link2, -1);
        }
      }
      continue;
    }
    add(joint.link1, static_cast<int>(j));
    if (joint.link2 != joint.link1)
      add(joint.link2, static_cast<int>(j));
  }
  return links;
}

int otherLink(const Joint& joint, int link) {
  return joint.link1 == link ? joint.link2 : joint.link1;
}

/// Where @p joints' axes meet, if they meet and span space at @p poses.
std::optional<Eigen::Vector3d> commonCenter(const Mechanism& mechanism, const LinkPoses& poses,
                                            const std::array<int, 3>& joints, double lengthScale) {
  std::array<Eigen::Vector3d, 3> point, direction;
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < 3; ++i) {
    const Joint& joint = mechanism.joints[static_cast<size_t>(joints[i])];
    const Eigen::Isometry3d frame = poses[static_cast<size_t>(joint.link1)] * joint.frame1;
    point[i] = frame.translation();
    direction[i] = (frame.linear() * joint.axis).normalized();
    // The point nearest every line: sum_i (I - d_i d_i^T) (c - p_i) = 0.
    const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - direction[i] * direction[i].transpose();
    normal += across;
    rhs += across * point[i];
  }
  Eigen::Matrix3d axes;
  axes << direction[0], direction[1], direction[2];
  if (!(std::abs(axes.determinant()) > kSpanning))
    return std::nullopt;
  const Eigen::Vector3d center = normal.ldlt().solve(rhs);
  for (size_t i = 0; i < 3; ++i) {
    const Eigen::Vector3d offset = center - point[i];
    if (!((offset - direction[i].dot(offset) * direction[i]).norm() <= kConcurrent * lengthScale))
      return std::nullopt;
  }
  return center;
}

}  // namespace

std::vector<CompositeBall> findCompositeBalls(const Mechanism& mechanism, const LinkPoses& poses,
                                              double lengthScale) {
  const std::vector<LinkConnections> links = connectionsOfLinks(mechanism);
  std::vector<char> used(mechanism.links.size(), 0);
  auto inner = [&](int link) {
    return link != mechanism.rootLink && links[static_cast<size_t>(link)].count == 2 &&
           used[static_cast<size_t>(link)] == 0;
  };
  std::vector<CompositeBall> balls;
  // Each ball is found at its middle revolute, whose two links are the inner ones.
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const Joint& middle = mechanism.joints[j];
    if (!isRevolute(middle) || middle.kind == ConnectionKind::Coupling || middle.link1 == middle.link2 ||
        !inner(middle.link1) || !inner(middle.link2))
      continue;
    CompositeBall ball;
    ball.innerLinks = {middle.link1, middle.link2};
    ball.joints[1] = static_cast<int>(j);
    ball.joints[0] = links[static_cast<size_t>(middle.link1)].other(ball.joints[1]);
    ball.joints[2] = links[static_cast<size_t>(middle.link2)].other(ball.joints[1]);
    if (ball.joints[0] < 0 || ball.joints[2] < 0 || ball.joints[0] == ball.joints[2])
      continue;
    const Joint& first = mechanism.joints[static_cast<size_t>(ball.joints[0])];
    const Joint& last = mechanism.joints[static_cast<size_t>(ball.joints[2])];
    if (!isRevolute(first) || !isRevolute(last) || first.kind != middle.kind || last.kind != middle.kind)
      continue;
    ball.end1 = otherLink(first, ball.innerLinks[0]);
    ball.end2 = otherLink(last, ball.innerLinks[1]);
    if (ball.end1 == ball.end2 || ball.end1 == ball.innerLinks[1] || ball.end2 == ball.innerLinks[0])
      continue;
    const std::optional<Eigen::Vector3d> center = commonCenter(mechanism, poses, ball.joints, lengthScale);
    if (!center)
      continue;
    ball.center = *center;
    used[static_cast<size_t>(ball.innerLinks[0])] = 1;
    used[static_cast<size_t>(ball.innerLinks[1])] = 1;
    balls.push_back(ball);
  }
  return balls;
}

MechanismWithBalls mergeCompositeBalls(const Mechanism& mechanism, const LinkPoses& poses,
                                       const std::vector<CompositeBall>& balls) {
  const size_t numLinks = mechanism.links.size();
  std::vector<char> linkGone(numLinks, 0), jointGone(mechanism.joints.size(), 0);
  std::vector<int> ballAt(mechanism.joints.size(), -1);
  for (size_t b = 0; b < balls.size(); ++b) {
    linkGone[static_cast<size_t>(balls[b].innerLinks[0])] = 1;
    linkGone[static_cast<size_t>(balls[b].innerLinks[1])] = 1;
    ballAt[static_cast<size_t>(balls[b].joints[0])] = static_cast<int>(b);
    jointGone[static_cast<size_t>(balls[b].joints[1])] = 1;
    jointGone[static_cast<size_t>(balls[b].joints[2])] = 1;
  }
  MechanismWithBalls merged;
  Mechanism& m = merged.mechanism;
  m.name = mechanism.name;
  m.file = mechanism.file;
  m.warnings = mechanism.warnings;
  std::vector<int> newLink(numLinks, -1), newJoint(mechanism.joints.size(), -1);
  for (size_t l = 0; l < numLinks; ++l) {
    if (linkGone[l])
      continue;
    newLink[l] = static_cast<int>(m.links.size());
    m.links.push_back(mechanism.links[l]);
    merged.poses.push_back(poses[l]);
  }
  m.rootLink = newLink[static_cast<size_t>(mechanism.rootLink)];
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    if (jointGone[j])
      continue;
    newJoint[j] = static_cast<int>(m.joints.size());
    Joint joint = mechanism.joints[j];
    if (ballAt[j] >= 0) {
      const CompositeBall& ball = balls[static_cast<size_t>(ballAt[j])];
      // The side that was link1 of the first revolute stays link1 (a tree joint's parent).
      const bool forward = joint.link1 == ball.end1;
      joint.link1 = forward ? ball.end1 : ball.end2;
      joint.link2 = forward ? ball.end2 : ball.end1;
      joint.type = JointType::Spherical;
      for (int k : {1, 2})
        joint.name += "+" + mechanism.joints[static_cast<size_t>(ball.joints[static_cast<size_t>(k)])].name;
      const Eigen::Translation3d at(ball.center);
      joint.frame1 = poses[static_cast<size_t>(joint.link1)].inverse() * at;
      joint.frame2 = poses[static_cast<size_t>(joint.link2)].inverse() * at;
    }
    joint.link1 = newLink[static_cast<size_t>(joint.link1)];
    joint.link2 = newLink[static_cast<size_t>(joint.link2)];
    m.joints.push_back(std::move(joint));
  }
  // Couplings never name a ball's revolutes (findCompositeBalls), so every index they hold survives.
  for (Joint& joint : m.joints) {
    if (joint.kind != ConnectionKind::Coupling)
      continue;
    joint.leader = joint.leader >= 0 ? newJoint[static_cast<size_t>(joint.leader)] : -1;
    joint.follower = joint.follower >= 0 ? newJoint[static_cast<size_t>(joint.follower)] : -1;
    for (std::vector<WeightedJoint>* more : {&joint.moreLeaders, &joint.moreFollowers}) {
      for (WeightedJoint& t : *more)
        t.joint = newJoint[static_cast<size_t>(t.joint)];
    }
  }
  return merged;
}

}  // namespace mobility_analysis
