#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mobility_analysis/Kinematics.hpp"
#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis {

/**
 * @brief A ball joint written as three revolutes: three revolute (or continuous) connections of one kind in
 *        series, their axes meeting at one point and spanning space, joined by two links that have no other
 *        connection (Gepetto's and Pinocchio's spherical joints, MJCF's hinge triples).
 *
 * Near a pose where the axes span space, the three joint rates give every angular velocity of the far link
 * about the centre and nothing else: the chain moves as a ball joint there (the Jacobian of the three
 * rotations about concurrent axes is [a1 a2 a3], invertible), and for a finite turn too, since its image
 * covers a neighbourhood of the identity rotation.
 */
struct CompositeBall {
  std::array<int, 3> joints{};                       ///< The three revolutes, from end1 to end2.
  std::array<int, 2> innerLinks{};                   ///< The links between them, end1's side first.
  int end1 = -1, end2 = -1;                          ///< The links the ball joins.
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< Where the axes meet, in the root frame [m].
};

/**
 * @brief Every composite ball of @p mechanism at @p poses.
 * @param[in] lengthScale the axes meet when each passes within 1e-8 of this of their common point [m].
 */
std::vector<CompositeBall> findCompositeBalls(const Mechanism& mechanism, const LinkPoses& poses,
                                              double lengthScale);

/// A mechanism with its composite balls written as spherical joints, and the poses of its links.
struct MechanismWithBalls {
  Mechanism mechanism;
  LinkPoses poses;
};

/**
 * @brief @p mechanism with each of @p balls one spherical connection (of the revolutes' kind, at the first
 *        revolute's place in the connection order, named "j1+j2+j3") at its centre, and its two inner links
 *        gone; every other link and connection as it was, in the same order.
 */
MechanismWithBalls mergeCompositeBalls(const Mechanism& mechanism, const LinkPoses& poses,
                                       const std::vector<CompositeBall>& balls);

}  // namespace mobility_analysis
