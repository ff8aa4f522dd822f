#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/SparseCore>

#include "mobility_analysis/Kinematics.hpp"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

/**
 * @brief A configuration of the joint tree: the relative motion of every tree joint.
 *
 * The child's joint frame expressed in the parent's joint frame, so that
 * T_child = T_parent * frame1 * motion * frame2^-1. Indexed like Mechanism::joints; entries of
 * connections that are not tree joints are unused (identity).
 */
struct TreeConfiguration {
  std::vector<Eigen::Isometry3d> motions;
};

/**
 * @brief How the loop-closure problem of a mechanism is laid out in tree coordinates.
 *
 * The unknowns are increments of the tree joints: one for a revolute, continuous or prismatic joint (an angle
 * [rad] or a slide [Lc]), six for a floating joint (three slides [Lc] and three turns [rad] in the parent's
 * joint frame), none for a fixed joint. A tree joint of any other type (planar, spherical, …) is given six
 * unknowns and its own equations as residuals. The residuals are the loop-closing connections written as
 * differences of frames, not as the analysis model's products: a revolute closes when its two points coincide
 * and its two axis vectors are *equal* (a2 - a1 = 0), so an axis turned by 180° is not a solution, and a
 * weld closes when two columns of its two rotations are equal. Lengths are divided by the characteristic
 * length Lc, so every residual is dimensionless.
 */
struct ClosureLayout {
  double lengthScale = 1.0;         ///< Lc [m].
  std::vector<int> parentJoint;     ///< Tree joint whose child is each link (-1 for the root).
  std::vector<int> linkOrder;       ///< Links, every parent before its children.
  std::vector<int> unknownOffset;   ///< Per connection: first unknown (-1: none).
  std::vector<int> unknownCount;    ///< Per connection: number of unknowns.
  std::vector<int> constrained;     ///< Connections that contribute residuals, in equation order.
  std::vector<int> residualOffset;  ///< Per entry of `constrained`: first residual row.
  std::vector<int> residualCount;   ///< Per entry of `constrained`: number of residual rows.
  std::vector<double> length;       ///< Per connection: distance or taut cable length [Lc] (else 0).
  int numUnknowns = 0;
  int numResiduals = 0;
  /// The largest residual taken as closed [Lc or rad]: tolerances::kAssemblyTarget, or the rounding of the
  /// poses where the mechanism lies so far from the model's origin that it is larger (makeClosureLayout).
  double target = tolerances::kAssemblyTarget;
};

/**
 * @brief Lays out the loop-closure problem of @p mechanism.
 * @param[in] written poses the distance constraints take their lengths from, and at which a passive cable is
 *            taut (it then constrains at its declared length); active and slack cables constrain nothing.
 * @param[in] lengthScale Lc [m].
 */
ClosureLayout makeClosureLayout(const Mechanism& mechanism, const LinkPoses& written, double lengthScale);

/// @return The tree configuration whose forward kinematics is @p poses (tree joints only; loops may be open).
TreeConfiguration configurationFromPoses(const Mechanism& mechanism, const ClosureLayout& layout,
                                         const LinkPoses& poses);

/// @return Every link's pose in the root frame for @p configuration.
LinkPoses posesOf(const Mechanism& mechanism, const ClosureLayout& layout,
                  const TreeConfiguration& configuration);

/// @return posesOf(configurationFromPoses(@p poses)), in one pass: no configuration is stored (10^5 joints'
///         motions were 13 MB of fresh pages when the tree has nothing to close).
LinkPoses reposeTree(const Mechanism& mechanism, const ClosureLayout& layout, const LinkPoses& poses);

/**
 * @brief The loop residual at @p poses and, if @p jacobian is not null, its derivative with respect to the
 *        unknowns kept by @p columns.
 * @param[in] columns per unknown of the layout: its column in the Jacobian, or -1 to hold it (a driven
 * joint).
 * @param[in] numColumns number of kept unknowns.
 * @param[out] residual dim layout.numResiduals.
 * @param[out] jacobian numResiduals x numColumns, or null.
 */
void evaluateClosure(const Mechanism& mechanism, const ClosureLayout& layout, const LinkPoses& poses,
                     const std::vector<int>& columns, int numColumns, Eigen::VectorXd& residual,
                     Eigen::SparseMatrix<double>* jacobian);

/**
 * @brief Moves @p configuration by the increments @p step of the kept unknowns (see evaluateClosure).
 *
 * A revolute turns about its axis, a prismatic slides along it, a six-unknown joint slides in and turns about
 * its parent joint frame's axes through the child's joint origin; to first order this is the motion the
 * Jacobian describes.
 */
void applyIncrement(const Mechanism& mechanism, const ClosureLayout& layout, const std::vector<int>& columns,
                    const Eigen::Ref<const Eigen::VectorXd>& step, TreeConfiguration& configuration);

/// @return Per unknown: its own column (all unknowns kept), and the count in @p numColumns.
std::vector<int> allColumns(const ClosureLayout& layout, int& numColumns);

/// @return The connection whose residual rows are largest in magnitude, preferring loop-closing connections,
///         with that residual [Lc]; -1 if none.
std::pair<int, double> largestClosureResidual(const Mechanism& mechanism, const ClosureLayout& layout,
                                              const Eigen::VectorXd& residual);

}  // namespace mobility_analysis
