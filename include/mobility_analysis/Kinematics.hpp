#pragma once

#include <vector>

#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis {

/// Link poses in the root (ground) frame, indexed like Mechanism::links.
using LinkPoses = std::vector<Eigen::Isometry3d>;

/**
 * @brief Forward kinematics of the joint tree: T_child = T_parent * origin * motion(q).
 * @param[in] mechanism the mechanism.
 * @param[in] positions tree-joint values [rad] or [m]; joints not listed are at 0.
 * @return Pose of every link in the root frame.
 */
LinkPoses computeTreePoses(const Mechanism& mechanism, const JointPositions& positions);

/**
 * @brief The inverse of computeTreePoses: every revolute, continuous and prismatic tree joint's value at
 *        @p poses, read from the relative pose of its two links.
 *
 * Angles are in (-pi, pi], or the representative nearest @p reference's value where it names the joint (so a
 * continuous joint followed through several turns keeps counting). Fixed, floating and other multi-freedom
 * tree joints have no single value and are left out.
 * @return Joint values [rad] or [m] by name.
 */
JointPositions computeJointPositions(const Mechanism& mechanism, const LinkPoses& poses,
                                     const JointPositions& reference = {});

/**
 * @brief The values computeJointPositions reads off the written pose (computeTreePoses with no values), as
 *        they were written: every revolute, continuous and prismatic tree joint at exactly 0.
 *
 * Read back off the poses instead they come out as rounding (a PUMA 560's joint2 at -5.6e-17 rad).
 */
JointPositions writtenJointPositions(const Mechanism& mechanism);

/**
 * @brief How far @p joint is from holding at @p poses: the distance between its two joint-frame origins
 *        that the joint type forbids [m] plus the angle between axes it forbids [rad] times @p lengthScale.
 */
double computeJointResidual(const Mechanism& mechanism, const LinkPoses& poses, int joint,
                            double lengthScale);

/**
 * @brief A characteristic length of the mechanism [m]: the RMS distance of all joint-frame origins (at
 *        @p poses) from their centroid; 1 when they all coincide. Every length is divided by it before an
 *        equation is built, so that tolerances do not depend on the unit.
 */
double computeCharacteristicLength(const Mechanism& mechanism, const LinkPoses& poses);

}  // namespace mobility_analysis
