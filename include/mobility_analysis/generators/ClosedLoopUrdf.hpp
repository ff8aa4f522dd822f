#pragma once

#include "mobility_analysis/generators/MechanismDescription.hpp"

#include <Eigen/Geometry>

#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace mobility_analysis {

/// A URDF pose: translation and fixed-axis roll-pitch-yaw, R = Rz(yaw) Ry(pitch) Rx(roll).
struct UrdfPose {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  ///< [m]
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();  ///< roll, pitch, yaw [rad]
};

/// A `<joint>` of the spanning tree (or a `floating` joint for a link held only by loop joints).
struct TreeJointLayout {
  std::string name;
  std::string type;    ///< "revolute", "continuous", "prismatic", "fixed" or "floating".
  std::string parent;  ///< Parent link.
  std::string child;   ///< Child link; its frame is this joint's frame.
  UrdfPose origin;     ///< Joint frame in the parent link's frame.
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  ///< In the joint frame (unused for fixed/floating).
};

/// A `<loop_joint>` or `<distance_constraint>`: the shared world frame seen from each side.
struct LoopJointLayout {
  std::string name;
  ConnectionType type = ConnectionType::Revolute;
  std::string link1;
  std::string link2;
  UrdfPose frame1;  ///< Joint frame in link1's frame (distance: only xyz, the end on link1).
  UrdfPose frame2;  ///< Joint frame in link2's frame (distance: only xyz, the end on link2).
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();   ///< In the joint frame.
  Eigen::Vector3d axis2 = Eigen::Vector3d::UnitY();  ///< Universal only, in the joint frame.
};

/// A cylinder drawn for a link, in the link's frame.
struct CylinderVisual {
  UrdfPose origin;    ///< Cylinder centre; its z axis along the cylinder.
  double length = 0;  ///< [m]
  double radius = 0;  ///< [m]
};

/**
 * @brief Everything the URDF file says, before it is printed.
 *
 * Exposed so tests can recompose link frames from the written numbers without parsing XML.
 */
struct ClosedLoopLayout {
  std::string robotName;
  std::vector<std::string> links;                    ///< Document order; links.front() is the root.
  std::vector<Eigen::Isometry3d> linkFrames;         ///< World frame of each link at the written pose.
  std::vector<std::vector<CylinderVisual>> visuals;  ///< Per link (parallel to links).
  std::vector<TreeJointLayout> treeJoints;           ///< Parents before children.
  std::vector<LoopJointLayout> loopJoints;           ///< Connection order.
};

/// Options of the URDF writer.
struct UrdfWriterOptions {
  bool visuals = true;           ///< Emit `<visual>` cylinders so rviz's RobotModel shows the links.
  std::string generatorCommand;  ///< Written into the header comment ("mobility_generate bennett").
};

/**
 * @brief Picks the spanning tree and expresses every connection in link frames.
 *
 * Tree: connections whose type a URDF `<joint>` can express are examined in document order; one becomes a
 * tree joint when exactly one of its links is attached (a connection whose links are both unattached is
 * re-examined as soon as one of them is). A tree child's frame := the joint's world frame, so
 * origin = inverse(parent frame) · joint frame. Links never reached hang from the root by `floating`.
 * Every other connection becomes a loop joint whose two frames reference the same world frame, so the
 * loops close exactly at the written pose.
 * @param[in] mechanism The description.
 * @param[in] options Writer options (visuals).
 * @return The layout, or an error naming a duplicate/unknown link or connection or a degenerate axis.
 */
GeneratorResult<ClosedLoopLayout> computeClosedLoopLayout(const MechanismDescription& mechanism,
                                                          const UrdfWriterOptions& options = {});

/**
 * @brief Writes the closed-loop URDF (DESIGN.md §2) of @p mechanism to @p out, streaming.
 * @param[in] mechanism The description.
 * @param[out] out Receives the whole document, or nothing on error.
 * @param[in] options Writer options.
 * @return Nothing on success, else the error (nothing was written).
 */
std::optional<GeneratorError> writeClosedLoopUrdf(const MechanismDescription& mechanism, std::ostream& out,
                                                  const UrdfWriterOptions& options = {});

/// @return The closed-loop URDF of @p mechanism as a string, or the error.
GeneratorResult<std::string> toClosedLoopUrdf(const MechanismDescription& mechanism,
                                              const UrdfWriterOptions& options = {});

/**
 * @brief URDF roll-pitch-yaw of a rotation, accurate to rounding even near pitch = ±90°.
 * @param[in] rotation Rotation matrix.
 * @return (roll, pitch, yaw) with rotation = Rz(yaw) Ry(pitch) Rx(roll) [rad].
 */
Eigen::Vector3d rpyFromRotation(const Eigen::Matrix3d& rotation);

/// @return Rz(yaw) Ry(pitch) Rx(roll) for @p rpy = (roll, pitch, yaw) [rad].
Eigen::Matrix3d rotationFromRpy(const Eigen::Vector3d& rpy);

/// @return The transform a UrdfPose denotes.
Eigen::Isometry3d toIsometry(const UrdfPose& pose);

}  // namespace mobility_analysis
