#pragma once

#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"
#include "mobility_analysis/RedundancyAnalysis.hpp"

namespace mobility_analysis {

/**
 * @brief The ordered rank test with the joint tree factored out: exact, and linear in size for local loops.
 *
 * Rigid-link and tree-joint equations (the first rows of the contract order) are independent by construction:
 * each link keeps lambda freedoms and each tree joint constrains a child that is free until then. Their null
 * space is spanned by the tree's motion modes (one per tree-joint freedom, plus the ground's rigid motions), so
 * a later equation depends on the rows before it exactly when its projection \f$ J_r N_T \f$ onto those modes
 * depends on the earlier projections. A loop row only moves with the joints on the tree path between its two
 * links (the rest moves both ends rigidly), so the projected matrix stays as local as the loops are.
 * @param[in] mechanism the mechanism.
 * @param[in] model its natural-coordinate model.
 * @param[in] q coordinates at the assembled pose.
 * @param[in] J the constraint Jacobian at q.
 * @param[in] tolerance relative rank threshold.
 * @return The same answer as computeOrderedRank(J, …) (dependencies list the loop-phase equations and one
 *         equation of every tree joint and link on their tree paths), or nothing when the rows before the first
 *         loop element are not independent by count (then use computeOrderedRank).
 */
std::optional<OrderedRank> computeOrderedRankOverTree(const Mechanism& mechanism, const CoordinateModel& model,
                                                      const Eigen::Ref<const Eigen::VectorXd>& q,
                                                      const SparseJacobian& J, double tolerance);

}  // namespace mobility_analysis
