#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"
#include "mobility_analysis/RedundancyAnalysis.hpp"
#include "mobility_analysis/SelfStressBasis.hpp"

namespace mobility_analysis {

/**
 * @brief How the mechanism really moves near the pose, next to the first-order answer (the nullity).
 *
 * In natural coordinates Φ(q0 + δ) = J δ + ½ H(δ, δ) + (cubic terms of the triple-product twists only). A
 * first-order motion δ = N x (J N = 0) extends to second order only if ω·H(δ, δ) = 0 for every self-stress ω
 * (Calladine & Pellegrino 1991, "First-order infinitesimal mechanisms"): the quadratic forms
 * Q_ω = N^T (Σ_i ω_i H_i) N decide. A pose where every Q_ω vanishes is regular to second order (and a
 * mechanism without self-stresses is regular outright: J has full row rank, so the configuration set is a
 * manifold of dimension nullity). Where some Q_ω does not vanish the pose is singular: finite_dof, the
 * dimension of the configuration set near the pose, is then measured by stepping along first-order motions
 * and projecting back onto Φ = 0 (Newton, least change): a step that comes back to the pose finds no motion
 * that way, one that lands on a nearby configuration finds the dimension of the branch there (the nullity at
 * that regular point). A self-stress whose Q_ω vanishes persists along the motion (structural); the others
 * exist only at this pose (configuration): the structural ones span the kernel of ω -> Q_ω.
 */
struct FiniteMobility {
  int finiteDof = 0;
  bool singular = false;
  /// Per equation (dim num_constraints): redundant at the pose only because of it ("configuration").
  std::vector<bool> configurationCause;
  /// The self-stresses that persist (all of them at a regular pose); link and loop redundancy reads these.
  std::vector<SelfStress> structuralStresses;
  int configurationStresses = 0;     ///< Dimension of the stresses that exist only at this pose.
  bool steppedAndProjected = false;  ///< Whether the step-and-project check ran (skipped above kStepLimit).
  std::string note;                  ///< Why a check was skipped, if it was.
};

/// The step-and-project check runs on models up to this many coordinates: each step is a sparse Newton
/// projection, whose factorisation grows fast on densely coupled models (a 31 x 33 bar grid: 5 s).
constexpr int kFiniteMobilityStepLimit = 2000;

/**
 * @brief The second-order test and the step-and-project check at the assembled pose.
 * @param[in] model the coordinate model.
 * @param[in] q the pose (dim num_coordinates), closed.
 * @param[in] J the constraint Jacobian at q.
 * @param[in] basis the self-stresses and first-order motions of J.
 * @param[in] ranks the ordered rank at q (its redundant equations get a cause).
 * @param[in] tolerance the relative rank threshold.
 */
FiniteMobility analyzeFiniteMobility(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                                     const SparseJacobian& J, const SelfStressBasis& basis,
                                     const OrderedRank& ranks, double tolerance);

/**
 * @brief Projects @p start onto Φ = 0 by Levenberg–Marquardt steps of least change (as the assembly does).
 * @return The projected coordinates and whether max |Φ| fell below @p closure.
 */
std::pair<Eigen::VectorXd, bool> projectOntoConstraints(const CoordinateModel& model,
                                                        const Eigen::Ref<const Eigen::VectorXd>& start,
                                                        double closure, int maxIterations);

}  // namespace mobility_analysis
