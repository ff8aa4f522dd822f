#pragma once

#include <string>
#include <vector>

#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/MobilityAnalysis.hpp"

namespace mobility_analysis {

/// Models with more coordinates than this get no driveable-joint search (a dense null space) [-].
constexpr int kMaxDriveableSearchCoordinates = 3000;

/**
 * @brief The tree joints that together drive the free directions at the analysed state: in document order,
 *        each revolute, continuous or prismatic tree joint whose rate is independent of the ones chosen
 * before it over the null space of the constraint Jacobian (so at most `dof` of them; a passive motion such
 * as a rod spinning between two ball joints moves no joint and adds none).
 *
 * The null space comes from a dense rank-revealing QR of the Jacobian's transpose (threshold 1e-9); each
 * joint's rate along a null vector from recovering the link poses at q ± eps n. A planar analysis takes its
 * rates from the spatial model at the same pose (planar coordinates do not give the links' turns back); at
 * most `report.dof` joints are chosen. Used by `~move` (free_direction) and `~animate`.
 * @return The joint names; empty when the model has more than kMaxDriveableSearchCoordinates coordinates.
 */
std::vector<std::string> findDriveableJoints(const Mechanism& mechanism, const MobilityAnalysis& analysis);

}  // namespace mobility_analysis
