#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "mobility_analysis/NaturalCoordinates.hpp"

namespace mobility_analysis {

/// Row-major sparse Jacobian: each equation's row is contiguous, as the ordered rank test reads it.
using SparseJacobian = Eigen::SparseMatrix<double, Eigen::RowMajor>;

/**
 * @brief Evaluates the constraint residual \f$ \Phi(q) \f$ (dim num_constraints).
 * @param[in] model the coordinate model.
 * @param[in] q coordinates (dim num_coordinates).
 * @param[out] phi residual, resized.
 */
void computeConstraintResidual(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                               Eigen::VectorXd& phi);

/**
 * @brief Evaluates the analytic constraint Jacobian \f$ \Phi_q(q) \f$, num_constraints x num_coordinates.
 *
 * Every equation is at most quadratic in natural coordinates, so each entry is linear in q (lecture,
 * "Comparison of coordinates"); each equation writes only its own few columns.
 */
SparseJacobian computeConstraintJacobian(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q);

}  // namespace mobility_analysis
