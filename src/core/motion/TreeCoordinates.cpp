#include "mobility_analysis/motion/TreeCoordinates.hpp"

#include <algorithm>
#include <cmath>

#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

bool isOneFreedomTree(const Joint& joint) {
  return joint.type == JointType::Revolute || joint.type == JointType::Continuous ||
         joint.type == JointType::Prismatic;
}

/// Residual rows of a loop-closing connection of @p type (see ClosureLayout).
int residualRows(JointType type) {
  switch (type) {
    case JointType::Revolute:
    case JointType::Continuous:
      return 6;  // points coincide 3, axes equal 3
    case JointType::Prismatic:
      return 9;  // point on the line 3, two frame columns equal 6
    case JointType::Cylindrical:
      return 6;  // point on the line 3, axes equal 3
    case JointType::Spherical:
      return 3;  // points coincide
    case JointType::Universal:
      return 4;  // points coincide 3, the axes keep their angle 1
    case JointType::Planar:
      return 4;  // point in the plane 1, normals equal 3
    case JointType::Fixed:
      return 9;  // points coincide 3, two frame columns equal 6
    case JointType::Floating:
      return 0;
  }
  return 0;
}

/// Value of 1-DOF tree joint @p j at @p poses in the unknowns' units: [rad], or [Lc] for a slide.
double unknownValue(const Joint& joint, const LinkPoses& poses, double lc) {
  const Eigen::Isometry3d motion =
      (poses[joint.link1] * joint.frame1).inverse() * poses[joint.link2] * joint.frame2;
  if (joint.type == JointType::Prismatic)
    return joint.axis.dot(motion.translation()) / lc;
  const Eigen::Vector3d v = joint.axis.unitOrthogonal();
  const Eigen::Vector3d turned = motion.linear() * v;
  return std::atan2(joint.axis.dot(v.cross(turned)), v.dot(turned));
}

/**
 * @brief A coupling value(f) = m value(l) + c in the tree's own unknowns: linear, one row, written in the
 *        follower's unknown (so its derivative there is 1). A turning follower's residual is taken modulo a
 *        turn, since its angle is read from the poses.
 */
void addCouplingRow(const Mechanism& mechanism, const ClosureLayout& layout, const LinkPoses& poses,
                    const Joint& coupling, const std::vector<int>& columns, int row,
                    Eigen::VectorXd& residual, std::vector<Eigen::Triplet<double>>* triplets) {
  const double lc = layout.lengthScale;
  const Joint& follower = mechanism.joints[coupling.follower];
  const Joint& leader = mechanism.joints[coupling.leader];
  const double followerScale = follower.type == JointType::Prismatic ? lc : 1.0;
  const double leaderScale = leader.type == JointType::Prismatic ? lc : 1.0;
  // The joints summed with either end are revolute (the reader checks it), in the ends' unit.
  const auto [followerValue, leaderValue] =
      couplingSides(coupling, [&](int j) { return unknownValue(mechanism.joints[j], poses, lc); });
  double r =
      followerValue - (coupling.multiplier * leaderValue * leaderScale + coupling.offset) / followerScale;
  if (follower.type != JointType::Prismatic)
    r = std::remainder(r, 2.0 * M_PI);
  residual(row) = r;
  if (triplets == nullptr)
    return;
  const int fc = columns[layout.unknownOffset[coupling.follower]];
  const int lcol = columns[layout.unknownOffset[coupling.leader]];
  if (fc >= 0)
    triplets->emplace_back(row, fc, 1.0);
  if (lcol >= 0)
    triplets->emplace_back(row, lcol, -coupling.multiplier * leaderScale / followerScale);
  for (const WeightedJoint& j : coupling.moreFollowers) {
    if (const int c = columns[layout.unknownOffset[j.joint]]; c >= 0)
      triplets->emplace_back(row, c, j.weight);
  }
  for (const WeightedJoint& j : coupling.moreLeaders) {
    if (const int c = columns[layout.unknownOffset[j.joint]]; c >= 0)
      triplets->emplace_back(row, c, -coupling.multiplier * j.weight * leaderScale / followerScale);
  }
}

/// World twist of one unknown, positions in Lc: a point p moves by omega x p + v per unit of the unknown.
struct Twist {
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
};

/// The quantities of one connection's two ends at a pose: points [Lc] and joint-frame rotations.
struct Ends {
  Eigen::Vector3d p1, p2;
  Eigen::Matrix3d r1, r2;
};

Ends endsOf(const Joint& joint, const LinkPoses& poses, double lc) {
  const Eigen::Isometry3d f1 = poses[joint.link1] * joint.frame1;
  const Eigen::Isometry3d f2 = poses[joint.link2] * joint.frame2;
  return Ends{f1.translation() / lc, f2.translation() / lc, f1.linear(), f2.linear()};
}

/**
 * Residual rows of connection @p joint (value when @p s1 = s2 = 0 and the twist is unused; else the
 * derivative along twist @p t applied to link1 when s1 = 1 and to link2 when s2 = 1).
 */
void closureRows(const Joint& joint, double length, const Ends& e, const Twist* t, double s1, double s2,
                 double* out) {
  const Eigen::Vector3d d = e.p2 - e.p1;
  const Eigen::Vector3d a1 = e.r1 * joint.axis, a2 = e.r2 * joint.axis;
  // Derivatives (zero when t is null).
  Eigen::Vector3d dd = Eigen::Vector3d::Zero(), da1 = Eigen::Vector3d::Zero(), da2 = Eigen::Vector3d::Zero();
  if (t != nullptr) {
    dd = s2 * (t->omega.cross(e.p2) + t->v) - s1 * (t->omega.cross(e.p1) + t->v);
    da1 = s1 * t->omega.cross(a1);
    da2 = s2 * t->omega.cross(a2);
  }
  auto put3 = [&](int at, const Eigen::Vector3d& v) {
    out[at] = v.x();
    out[at + 1] = v.y();
    out[at + 2] = v.z();
  };
  auto columns = [&](int at) {  // two frame columns equal: R2 e_k - R1 e_k, k = x, y
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector3d c1 = e.r1.col(k), c2 = e.r2.col(k);
      put3(at + 3 * k, t == nullptr ? Eigen::Vector3d(c2 - c1)
                                    : Eigen::Vector3d(s2 * t->omega.cross(c2) - s1 * t->omega.cross(c1)));
    }
  };
  if (joint.kind == ConnectionKind::DistanceConstraint || joint.kind == ConnectionKind::Cable) {
    const double n = d.norm();
    if (t == nullptr)
      out[0] = n - length;
    else
      out[0] = n > tolerances::kZeroVector ? d.dot(dd) / n : 0.0;
    return;
  }
  switch (joint.type) {
    case JointType::Revolute:
    case JointType::Continuous:
      put3(0, t == nullptr ? d : dd);
      put3(3, t == nullptr ? Eigen::Vector3d(a2 - a1) : Eigen::Vector3d(da2 - da1));
      break;
    case JointType::Prismatic:
      put3(0, t == nullptr ? Eigen::Vector3d(a1.cross(d)) : Eigen::Vector3d(da1.cross(d) + a1.cross(dd)));
      columns(3);
      break;
    case JointType::Cylindrical:
      put3(0, t == nullptr ? Eigen::Vector3d(a1.cross(d)) : Eigen::Vector3d(da1.cross(d) + a1.cross(dd)));
      put3(3, t == nullptr ? Eigen::Vector3d(a2 - a1) : Eigen::Vector3d(da2 - da1));
      break;
    case JointType::Spherical:
      put3(0, t == nullptr ? d : dd);
      break;
    case JointType::Universal: {
      const Eigen::Vector3d b2 = e.r2 * joint.axis2;
      put3(0, t == nullptr ? d : dd);
      out[3] = t == nullptr ? a1.dot(b2) - joint.axis.dot(joint.axis2)
                            : da1.dot(b2) + a1.dot(s2 * t->omega.cross(b2));
      break;
    }
    case JointType::Planar:
      out[0] = t == nullptr ? a1.dot(d) : da1.dot(d) + a1.dot(dd);
      put3(1, t == nullptr ? Eigen::Vector3d(a2 - a1) : Eigen::Vector3d(da2 - da1));
      break;
    case JointType::Fixed:
      put3(0, t == nullptr ? d : dd);
      columns(3);
      break;
    case JointType::Floating:
      break;
  }
}

/// Twists of the unknowns of tree joint @p j at @p poses (positions in Lc).
int jointTwists(const Mechanism& mechanism, const ClosureLayout& layout, const LinkPoses& poses, int j,
                Twist* twists) {
  const Joint& joint = mechanism.joints[j];
  const double lc = layout.lengthScale;
  const Eigen::Isometry3d parentFrame = poses[joint.link1] * joint.frame1;
  const Eigen::Isometry3d childFrame = poses[joint.link2] * joint.frame2;
  if (layout.unknownCount[j] == 1) {
    const Eigen::Vector3d w = childFrame.linear() * joint.axis;
    if (joint.type == JointType::Prismatic) {
      twists[0] = Twist{Eigen::Vector3d::Zero(), w};
    } else {
      const Eigen::Vector3d o = childFrame.translation() / lc;
      twists[0] = Twist{w, o.cross(w)};
    }
    return 1;
  }
  if (layout.unknownCount[j] == 6) {
    const Eigen::Vector3d c = childFrame.translation() / lc;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d axis = parentFrame.linear().col(k);
      twists[k] = Twist{Eigen::Vector3d::Zero(), axis};
      twists[3 + k] = Twist{axis, c.cross(axis)};
    }
    return 6;
  }
  return 0;
}

/// Tree joint @p joint's motion at @p poses (TreeConfiguration): a one-freedom joint's kept exactly a turn
/// about / slide along its axis (poses carry round-off), a weld's the identity.
Eigen::Isometry3d treeMotion(const Joint& joint, const LinkPoses& poses) {
  Eigen::Isometry3d motion =
      (poses[joint.link1] * joint.frame1).inverse() * poses[joint.link2] * joint.frame2;
  if (joint.type == JointType::Revolute || joint.type == JointType::Continuous) {
    const Eigen::Vector3d v = joint.axis.unitOrthogonal();
    const Eigen::Vector3d turned = motion.linear() * v;
    const double angle = std::atan2(joint.axis.dot(v.cross(turned)), v.dot(turned));
    motion = Eigen::Isometry3d::Identity();
    motion.linear() = Eigen::AngleAxisd(angle, joint.axis).toRotationMatrix();
  } else if (joint.type == JointType::Prismatic) {
    const double slide = joint.axis.dot(motion.translation());
    motion = Eigen::Isometry3d::Identity();
    motion.translation() = slide * joint.axis;
  } else if (joint.type == JointType::Fixed) {
    motion = Eigen::Isometry3d::Identity();
  }
  return motion;
}

}  // namespace

ClosureLayout makeClosureLayout(const Mechanism& mechanism, const LinkPoses& written, double lengthScale) {
  ClosureLayout layout;
  layout.lengthScale = lengthScale;
  const int numLinks = static_cast<int>(mechanism.links.size());
  const int numJoints = static_cast<int>(mechanism.joints.size());
  layout.parentJoint.assign(numLinks, -1);
  layout.unknownOffset.assign(numJoints, -1);
  layout.unknownCount.assign(numJoints, 0);
  layout.length.assign(numJoints, 0.0);
  std::vector<int> parentLink(numLinks, -1);  // the walk below reads no Joint (hundreds of bytes each)
  for (int j = 0; j < numJoints; ++j) {
    const Joint& joint = mechanism.joints[j];
    if (joint.kind == ConnectionKind::TreeJoint) {
      layout.parentJoint[joint.link2] = j;
      parentLink[joint.link2] = joint.link1;
      const int count = isOneFreedomTree(joint) ? 1 : joint.type == JointType::Fixed ? 0 : 6;
      if (count > 0) {
        layout.unknownOffset[j] = layout.numUnknowns;
        layout.unknownCount[j] = count;
        layout.numUnknowns += count;
      }
    }
  }
  // Parents before children: walk up from each link to the first one already placed.
  std::vector<bool> placed(numLinks, false);
  std::vector<int> chain;
  placed[mechanism.rootLink] = true;
  layout.linkOrder.reserve(numLinks);
  layout.linkOrder.push_back(mechanism.rootLink);
  for (int link = 0; link < numLinks; ++link) {
    chain.clear();
    for (int l = link; !placed[l] && layout.parentJoint[l] >= 0; l = parentLink[l])
      chain.push_back(l);
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      placed[*it] = true;
      layout.linkOrder.push_back(*it);
    }
  }
  for (int j = 0; j < numJoints; ++j) {
    const Joint& joint = mechanism.joints[j];
    int rows = 0;
    if (joint.kind == ConnectionKind::TreeJoint) {
      rows = isOneFreedomTree(joint) || joint.type == JointType::Fixed ? 0 : residualRows(joint.type);
    } else if (joint.kind == ConnectionKind::DistanceConstraint || joint.kind == ConnectionKind::Cable) {
      const double distance = ((written[joint.link1] * joint.frame1.translation()) -
                               (written[joint.link2] * joint.frame2.translation()))
                                  .norm();
      if (joint.kind == ConnectionKind::DistanceConstraint) {
        layout.length[j] = distance / lengthScale;
        rows = 1;
      } else if (joint.cableType == CableType::Passive &&
                 std::abs(distance - joint.length) <= tolerances::kCableTaut * joint.length) {
        layout.length[j] = joint.length / lengthScale;
        rows = 1;
      }
    } else if (joint.kind == ConnectionKind::Coupling) {
      // Both ends are 1-DOF tree joints (the readers check it): one linear row in their unknowns.
      const std::vector<int> coupled = coupledJoints(joint);
      rows = std::all_of(coupled.begin(), coupled.end(), [&](int j) { return layout.unknownCount[j] == 1; })
                 ? 1
                 : 0;
    } else {
      rows = residualRows(joint.type);
    }
    if (rows == 0)
      continue;
    layout.constrained.push_back(j);
    layout.residualOffset.push_back(layout.numResiduals);
    layout.residualCount.push_back(rows);
    layout.numResiduals += rows;
  }
  // A residual is a difference of two frames reached through the tree, each rounded to about eps times its
  // distance from the origin: a mechanism 10^4 Lc from it (a robot welded 10 km off its URDF's origin) cannot
  // close below a few 1e-12 Lc, and kAssemblyTarget (1e-12) would refuse every loop of it. The target is
  // kAssemblyTarget up to about 300 Lc from the origin (every bundled model), then the coordinates' rounding.
  double extent = 0.0;
  for (const Eigen::Isometry3d& pose : written)
    extent = std::max(extent, pose.translation().cwiseAbs().maxCoeff());
  layout.target = tolerances::reachableTarget(tolerances::kAssemblyTarget, extent / lengthScale);
  return layout;
}

TreeConfiguration configurationFromPoses(const Mechanism& mechanism, const ClosureLayout& layout,
                                         const LinkPoses& poses) {
  (void)layout;
  TreeConfiguration configuration;
  configuration.motions.assign(mechanism.joints.size(), Eigen::Isometry3d::Identity());
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const Joint& joint = mechanism.joints[j];
    if (joint.kind == ConnectionKind::TreeJoint)
      configuration.motions[j] = treeMotion(joint, poses);
  }
  return configuration;
}

LinkPoses posesOf(const Mechanism& mechanism, const ClosureLayout& layout,
                  const TreeConfiguration& configuration) {
  LinkPoses poses(mechanism.links.size(), Eigen::Isometry3d::Identity());
  for (const int link : layout.linkOrder) {
    const int j = layout.parentJoint[link];
    if (j < 0)
      continue;
    const Joint& joint = mechanism.joints[j];
    poses[link] = poses[joint.link1] * joint.frame1 * configuration.motions[j] * joint.frame2.inverse();
  }
  return poses;
}

LinkPoses reposeTree(const Mechanism& mechanism, const ClosureLayout& layout, const LinkPoses& poses) {
  LinkPoses reposed(mechanism.links.size(), Eigen::Isometry3d::Identity());
  for (const int link : layout.linkOrder) {
    const int j = layout.parentJoint[link];
    if (j < 0)
      continue;
    const Joint& joint = mechanism.joints[j];
    reposed[link] = reposed[joint.link1] * joint.frame1 * treeMotion(joint, poses) * joint.frame2.inverse();
  }
  return reposed;
}

std::vector<int> allColumns(const ClosureLayout& layout, int& numColumns) {
  std::vector<int> columns(layout.numUnknowns);
  for (int k = 0; k < layout.numUnknowns; ++k)
    columns[k] = k;
  numColumns = layout.numUnknowns;
  return columns;
}

void evaluateClosure(const Mechanism& mechanism, const ClosureLayout& layout, const LinkPoses& poses,
                     const std::vector<int>& columns, int numColumns, Eigen::VectorXd& residual,
                     Eigen::SparseMatrix<double>* jacobian) {
  residual.setZero(layout.numResiduals);
  std::vector<Eigen::Triplet<double>> triplets;
  std::vector<char> side(mechanism.joints.size(), 0);  // bit 1: moves link1, bit 2: moves link2
  std::vector<int> touched;
  double rows[9];
  Twist twists[6];
  for (size_t c = 0; c < layout.constrained.size(); ++c) {
    const int j = layout.constrained[c];
    const Joint& joint = mechanism.joints[j];
    if (joint.kind == ConnectionKind::Coupling) {
      addCouplingRow(mechanism, layout, poses, joint, columns, layout.residualOffset[c], residual,
                     jacobian != nullptr ? &triplets : nullptr);
      continue;
    }
    const Ends ends = endsOf(joint, poses, layout.lengthScale);
    const int offset = layout.residualOffset[c];
    const int count = layout.residualCount[c];
    closureRows(joint, layout.length[j], ends, nullptr, 0.0, 0.0, rows);
    for (int r = 0; r < count; ++r)
      residual(offset + r) = rows[r];
    if (jacobian == nullptr)
      continue;
    // The unknowns that move either end: the tree joints on the root paths of link1 and link2, and the
    // connection's own six unknowns when it is itself a multi-freedom tree joint (link2 is its child).
    touched.clear();
    for (int bit = 1; bit <= 2; ++bit) {
      for (int l = bit == 1 ? joint.link1 : joint.link2; layout.parentJoint[l] >= 0;
           l = mechanism.joints[layout.parentJoint[l]].link1) {
        const int pj = layout.parentJoint[l];
        if (side[pj] == 0)
          touched.push_back(pj);
        side[pj] |= static_cast<char>(bit);
      }
    }
    for (const int pj : touched) {
      const double s1 = (side[pj] & 1) ? 1.0 : 0.0, s2 = (side[pj] & 2) ? 1.0 : 0.0;
      side[pj] = 0;
      const int n = jointTwists(mechanism, layout, poses, pj, twists);
      for (int k = 0; k < n; ++k) {
        const int column = columns[layout.unknownOffset[pj] + k];
        if (column < 0)  // held (a driven joint)
          continue;
        closureRows(joint, layout.length[j], ends, &twists[k], s1, s2, rows);
        for (int r = 0; r < count; ++r) {
          if (rows[r] != 0.0)
            triplets.emplace_back(offset + r, column, rows[r]);
        }
      }
    }
  }
  if (jacobian != nullptr) {
    jacobian->resize(layout.numResiduals, numColumns);
    jacobian->setFromTriplets(triplets.begin(), triplets.end());
  }
}

void applyIncrement(const Mechanism& mechanism, const ClosureLayout& layout, const std::vector<int>& columns,
                    const Eigen::Ref<const Eigen::VectorXd>& step, TreeConfiguration& configuration) {
  const double lc = layout.lengthScale;
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const int count = layout.unknownCount[j];
    if (count == 0)
      continue;
    const Joint& joint = mechanism.joints[j];
    Eigen::Isometry3d& motion = configuration.motions[j];
    auto value = [&](int k) {
      const int column = columns[layout.unknownOffset[j] + k];
      return column < 0 ? 0.0 : step(column);
    };
    if (count == 1) {
      const double delta = value(0);
      if (delta == 0.0)
        continue;
      Eigen::Isometry3d increment = Eigen::Isometry3d::Identity();
      if (joint.type == JointType::Prismatic)
        increment.translation() = delta * lc * joint.axis;
      else
        increment.linear() = Eigen::AngleAxisd(delta, joint.axis).toRotationMatrix();
      motion = motion * increment;
      continue;
    }
    const Eigen::Vector3d slide(value(0), value(1), value(2));
    const Eigen::Vector3d turn(value(3), value(4), value(5));
    const double angle = turn.norm();
    const Eigen::Vector3d m = motion.translation();
    Eigen::Isometry3d increment = Eigen::Isometry3d::Identity();
    if (angle > 0.0)
      increment.linear() = Eigen::AngleAxisd(angle, turn / angle).toRotationMatrix();
    increment.translation() = m + lc * slide - increment.linear() * m;
    motion = increment * motion;
  }
}

std::pair<int, double> largestClosureResidual(const Mechanism& mechanism, const ClosureLayout& layout,
                                              const Eigen::VectorXd& residual) {
  int worst = -1;
  double largest = 0.0;
  for (const bool loopsOnly : {true, false}) {
    for (size_t c = 0; c < layout.constrained.size(); ++c) {
      const int j = layout.constrained[c];
      if (loopsOnly && mechanism.joints[j].kind == ConnectionKind::TreeJoint)
        continue;
      const double value =
          residual.segment(layout.residualOffset[c], layout.residualCount[c]).cwiseAbs().maxCoeff();
      if (value > largest) {
        largest = value;
        worst = j;
      }
    }
    if (worst >= 0)
      break;
  }
  return {worst, largest};
}

}  // namespace mobility_analysis
