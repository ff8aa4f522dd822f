#pragma once

#include <vector>

#include <Eigen/Core>

#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/MobilityReport.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"
#include "mobility_analysis/SelfStressBasis.hpp"

namespace mobility_analysis {

/// At most this many states are listed element by element in a report (the count is always exact).
constexpr size_t kMaxListedStates = 20000;
/// Prestress stability is decided on a dense null-space basis only up to this many coordinates (m > 0).
constexpr int kMaxStabilityCoordinates = 4000;

/**
 * @brief The report's `self_stress`: the states of self-stress on the local basis, their supports with
 * relative forces, the Calladine–Maxwell counts, and whether the taut cables can be prestressed and whether
 * that prestress stiffens the mechanism modes.
 *
 * Prestress stability: the stress matrix \f$ \Omega = \sum_r \omega_r H_r \f$ (the constant Hessians of the
 * natural-coordinate equations, EquationForms.hpp) restricted to the first-order motions N (null space of
 * J) must be positive definite: \f$ N^T \Omega N \succ 0 \f$ (Connelly & Whiteley's second-order test).
 * With m = 0 the structure is first-order rigid and the test holds trivially.
 * @param[in] mechanism the mechanism (names and kinds of the elements).
 * @param[in] model its natural-coordinate model (equations in contract order).
 * @param[in] q coordinates at the analysed pose (dim num_coordinates).
 * @param[in] J the constraint Jacobian at @p q.
 * @param[in] basis its self-stress basis (computeSelfStressBasis, or sweepSelfStressBasis alone: only its
 * stresses, counts and smallest kept pivot are read, never the echelon members reduceToContractOrder writes,
 * so the report may run while another thread completes the basis).
 * @note A locked active cable is a taut passive cable of @p mechanism (see lockActiveCables).
 */
SelfStressInfo computeSelfStressInfo(const Mechanism& mechanism, const CoordinateModel& model,
                                     const Eigen::Ref<const Eigen::VectorXd>& q, const SparseJacobian& J,
                                     const SelfStressBasis& basis);

/**
 * @brief A copy of @p mechanism whose active cables are locked: passive cables of the length their ends are
 * apart at @p poses, so they are taut there.
 * @param[out] locked per connection, whether it was an active cable that was locked (dim joints).
 */
Mechanism lockActiveCables(const Mechanism& mechanism, const LinkPoses& poses, std::vector<bool>& locked);

/// @return Rows of the distance equations of the taut cables in @p model (passive taut and locked active).
std::vector<int> findTautCableRows(const Mechanism& mechanism, const CoordinateModel& model);

/**
 * @brief The basis' states as multipliers of the equations as written: SelfStressBasis eliminates rows scaled
 * to unit norm, so its coefficient of row r is y_r |J_r|; this divides it out (y^T J = 0 then holds for J
 * itself) and rescales each state to unit largest coefficient.
 */
std::vector<SelfStress> toEquilibriumStresses(const std::vector<SelfStress>& stresses,
                                              const SparseJacobian& J);

/// @return The state @p stress as a dense multiplier vector (dim @p numConstraints).
Eigen::VectorXd toMultipliers(const SelfStress& stress, int numConstraints);

}  // namespace mobility_analysis
