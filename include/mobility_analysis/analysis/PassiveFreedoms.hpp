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
 * An idle group is one link, or a chain of up to three links, joined to the rest of the mechanism by exactly
 * two end connections (each link of a chain has two connections) that reach two other links (a door turning
 * on hinges to the ground alone, or a robot's last link, is output, not idle), that moves as one rigid body;
 * its motion is passive when it is a finite motion (a turn about a line, a slide along a line, or a screw
 * about one) that keeps every constraint while all other links are fixed: an S–S rod or S–P–S leg turning
 * about the line through its ball joints, a link between two coaxial revolutes turning about their axis, the
 * RPPR's middle link sliding along the line of its two parallel prismatic joints. passive_dof is the
 * dimension of the span of all such motions (each a first-order motion of the whole mechanism that is also
 * finite), so output_dof = finite_dof − passive_dof counts the freedoms that move something outside an idle
 * group.
 */
struct PassiveFreedoms {
  int dof = 0;
  std::vector<PassiveMotion> motions;  ///< One per independent motion, with its group and a phrase.
};

/**
 * @brief Finds the passive freedoms at the pose @p q.
 * @param[in] mechanism the mechanism.
 * @param[in] model its coordinate model.
 * @param[in] q closed coordinates (dim num_coordinates).
 * @param[in] J the constraint Jacobian at q.
 */
PassiveFreedoms findPassiveFreedoms(const Mechanism& mechanism, const CoordinateModel& model,
                                    const Eigen::Ref<const Eigen::VectorXd>& q, const SparseJacobian& J);

}  // namespace mobility_analysis
