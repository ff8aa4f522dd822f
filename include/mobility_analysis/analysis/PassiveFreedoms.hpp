#pragma once

#include <vector>

#include <Eigen/Core>

#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/MobilityReport.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"

namespace mobility_analysis {

/**
 * @brief Passive (idle) freedoms, after Tsai (1999, "Robot Analysis", §1.4): a motion of an idle group while
 * every link outside the group stays put.
 *
 * An idle group is one link, or a chain of up to three rigid bodies (links welded by fixed connections count
 * as one), joined to the rest of the mechanism by exactly two end connections (each link of a chain has two
 * connections) that reach two other links (a door turning on hinges to the ground alone, or a robot's last
 * link, is output, not idle), that moves as one rigid body; its motion is passive when it is a finite motion
 * (a turn about a line, a slide along a line, or a screw about one) that keeps every constraint while all
 * other links are fixed: an S–S rod or S–P–S leg turning about the line through its ball joints, a link
 * between two coaxial revolutes turning about their axis, the RPPR's middle link sliding along the line of
 * its two parallel prismatic joints. passive_dof is the dimension of the span of all such motions (each a
 * first-order motion of the whole mechanism that is also finite), so output_dof = finite_dof − passive_dof
 * counts the freedoms that move something outside an idle group.
 *
 * The span is taken whole, not group by group: along a chain the groups are searched from one end, each after
 * the groups it contains, and a motion is kept when it adds a dimension to every motion kept before, whichever
 * links those move (a pair of rods turning about the line of both is the sum of their spins). Motions are
 * compared in the units of their own links (a point's velocity divided by its link's length), so small links
 * in a large mechanism are judged as in a small one. The motions kept are listed by group, in the groups'
 * sorted order.
 */
struct PassiveFreedoms {
  int dof = 0;
  std::vector<PassiveMotion> motions;  ///< One per independent motion, with its group and a phrase.
  int groupsRigidByEnds = 0;  ///< Candidate groups settled by the end-connection bound (no twist computed).
  int groupsSearched = 0;     ///< Groups with two end connections reaching two other links, fully searched.
};

/**
 * @brief How findPassiveFreedoms searches; the answer is the same either way.
 *
 * The end-connection bound. A group's twists xi are tested on A = J(rows touching the group, group columns) T
 * (rows scaled to unit norm): a twist is a candidate when |A xi| <= 1e-8 max(sigma_max(A), 1) |xi|. Let A' be
 * the rows of the group's two end connections only, where each such row touches the group's end link and the
 * link outside (checked; else the bound is not used): these are rows of A, so sigma_min(A) >= sigma_min(A').
 * With F_l the sum over all rows touching link l of |row on l's columns times T|^2 (computed once per link),
 * |A|_F^2 <= |group| sum_l F_l (a row of A is a sum of at most |group| per-link parts). When
 * sigma_min(A')^2 >= 1 / |(A'^T A')^-1|_F clears 1e-6 max(sqrt(|group| sum F_l), 1), a hundredfold above the
 * test's threshold as in the search's own bound, no twist can be a candidate and the group is settled without
 * building A. On a serial chain of revolutes every group is settled so: two revolutes at different points
 * (in space: on different axes) leave a rigid body no twist.
 */
struct PassiveFreedomsOptions {
  bool endConnectionBound = true;  ///< false: every group goes through the full search (for tests).
};

/**
 * @brief Finds the passive freedoms at the pose @p q.
 * @param[in] mechanism the mechanism.
 * @param[in] model its coordinate model.
 * @param[in] q closed coordinates (dim num_coordinates).
 * @param[in] J the constraint Jacobian at q.
 * @param[in] options the search (the end-connection bound on or off).
 */
PassiveFreedoms findPassiveFreedoms(const Mechanism& mechanism, const CoordinateModel& model,
                                    const Eigen::Ref<const Eigen::VectorXd>& q, const SparseJacobian& J,
                                    const PassiveFreedomsOptions& options = {});

}  // namespace mobility_analysis
