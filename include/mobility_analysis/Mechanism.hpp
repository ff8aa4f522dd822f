#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "mobility_analysis/Diagnostic.hpp"

namespace mobility_analysis {

/// Joint types of the closed-loop URDF dialect (DESIGN.md §2). `Planar` and `Floating` are URDF tree types.
enum class JointType {
  Revolute,
  Continuous,
  Prismatic,
  Cylindrical,
  Spherical,
  Universal,
  Planar,
  Fixed,
  Floating
};

/// Where a connection between two links comes from; also the order of its equations (DESIGN.md §3).
/// A Coupling (URDF `<mimic>`, URDF+ `<coupling>`) ties two 1-DOF tree joints: one equation, after the loops.
enum class ConnectionKind { TreeJoint, DistanceConstraint, Cable, LoopJoint, Coupling };

/// Passive cables constrain while taut; active cables are the driver and constrain nothing.
enum class CableType { Passive, Active };

/// One joint's value in a coupling's sum, with its weight (1 for generalized_rbda's paths; a fixed tendon's
/// coefficient, relative to the first joint's, for MJCF).
struct WeightedJoint {
  int joint = -1;  ///< Index into Mechanism::joints: a 1-DOF tree joint.
  double weight = 1.0;
};

/// A rigid link; its frame is the URDF link frame.
struct Link {
  std::string name;
};

/**
 * @brief One connection between two links: a URDF joint, a `loop_joint`, a `distance_constraint` or a
 * `cable`.
 *
 * The joint frame is given on each side: `frame1` in link1's frame and `frame2` in link2's frame. For a tree
 * joint link1 is the parent, `frame1` the URDF origin and `frame2` the identity (the child frame is the joint
 * frame). The joint holds when the two frames coincide up to the joint's own motion about/along `axis`.
 */
struct Joint {
  std::string name;
  ConnectionKind kind = ConnectionKind::TreeJoint;
  JointType type = JointType::Fixed;  ///< Distance constraints and cables use Spherical (ball ends).
  int link1 = -1;                     ///< Index into Mechanism::links (tree: parent).
  int link2 = -1;                     ///< Index into Mechanism::links (tree: child).
  Eigen::Isometry3d frame1 = Eigen::Isometry3d::Identity();  ///< Joint frame in link1's frame [m].
  Eigen::Isometry3d frame2 = Eigen::Isometry3d::Identity();  ///< Joint frame in link2's frame [m].
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();           ///< Unit axis in the joint frame.
  Eigen::Vector3d axis2 = Eigen::Vector3d::UnitY();          ///< Universal only: second unit axis, on link2.
  double length = 0.0;                                       ///< Cable: declared length [m]; else unused.
  CableType cableType = CableType::Passive;                  ///< Cable only.
  /// Coupling only: value(follower) = multiplier * value(leader) + offset [rad or m], both 1-DOF tree joints
  /// (indices into Mechanism::joints). link1 is the follower's child, link2 the leader's child.
  int leader = -1;
  int follower = -1;
  double multiplier = 1.0;
  double offset = 0.0;
  /// Coupling only: further 1-DOF tree joints whose weighted values add to the leader's and to the follower's
  /// (generalized_rbda's coupling of two links sums the joint values on each link's path from their nearest
  /// common ancestor; an MJCF tendon equality weighs them by the fixed tendons' coefficients):
  /// value(follower) + sum w value(moreFollowers) = multiplier (value(leader) + sum w value(moreLeaders)) +
  /// offset. Usually empty; every joint in them is revolute (the readers check it).
  std::vector<WeightedJoint> moreLeaders, moreFollowers;
};

/// Joint values by tree-joint name [rad] or [m].
using JointPositions = std::map<std::string, double>;

/**
 * @brief An immutable closed-loop mechanism as read from the URDF.
 *
 * `joints` holds every connection in the order of its constraint equations: tree joints in document order,
 * then distance constraints, then cables, then loop joints, then couplings (DESIGN.md §3). Whatever format it
 * was read from (io/ReadMechanism.hpp), nothing downstream knows.
 */
struct Mechanism {
  std::string name;           ///< URDF robot name.
  std::string file;           ///< Source file name, for diagnostics.
  std::vector<Link> links;    ///< Links in document order.
  std::vector<Joint> joints;  ///< Connections in equation order.
  int rootLink = 0;           ///< The ground.
  /// What the reader met but did not understand or had to assume (one Diagnostic each); copied into the
  /// report's `warnings` by analyzeMechanism. A strict read turns the first into an error.
  std::vector<Diagnostic> warnings;

  /// @return Index of the link called @p linkName, if any.
  std::optional<int> findLink(const std::string& linkName) const;
  /// @return Index of the connection called @p jointName, if any.
  std::optional<int> findJoint(const std::string& jointName) const;
  /// @return Index of the tree joint whose child is @p link, if any (none for the root).
  std::optional<int> findParentJoint(int link) const;
};

/// Whether @p joint is a revolute, continuous or prismatic tree joint: one value [rad or m] says where it is
/// (the joints whose positions a report lists and a caller may hold).
bool hasSingleValue(const Joint& joint);

/// @return The 1-DOF tree joints coupling @p coupling ties: its follower, its leader, then the joints summed
///         with either (Joint::moreFollowers, Joint::moreLeaders).
std::vector<int> coupledJoints(const Joint& coupling);

/**
 * @brief The two sides of coupling @p coupling's equation at the joint values @p value(joint index):
 *        value(follower) + sum w value(moreFollowers), and value(leader) + sum w value(moreLeaders); the
 *        equation is follower side = multiplier * leader side + offset.
 */
template <class JointValue>
std::pair<double, double> couplingSides(const Joint& coupling, JointValue&& value) {
  double follower = value(coupling.follower), leader = value(coupling.leader);
  for (const WeightedJoint& j : coupling.moreFollowers)
    follower += j.weight * value(j.joint);
  for (const WeightedJoint& j : coupling.moreLeaders)
    leader += j.weight * value(j.joint);
  return {follower, leader};
}

/// @return The dialect's spelling of @p type ("revolute", …).
const char* toString(JointType type);
/// @return "joint", "distance_constraint", "cable", "loop_joint" or "coupling".
const char* toString(ConnectionKind kind);

}  // namespace mobility_analysis
