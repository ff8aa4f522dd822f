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
/// computeConstraintJacobian, its second half of rows written on a second thread when @p sideThread and the
/// model is large (from 2 10^4 equations); the matrix is the same.
SparseJacobian computeConstraintJacobian(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                                         bool sideThread);

/**
 * @brief The Hessian of equation @p row, \f$ \partial^2 \Phi_{row} / \partial q^2 \f$ at q (dense,
 * num_coordinates square; for tests and small models).
 *
 * Constant for the quadratic forms (EquationForms.hpp); the triple product's depends on q.
 */
Eigen::MatrixXd computeEquationHessian(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                                       int row);

/**
 * @brief The stressed Hessian \f$ \sum_i w_i \, \partial^2 \Phi_i / \partial q^2 \f$ at q, the matrix of the
 * second-order test (Calladine & Pellegrino 1991): a first-order motion \f$ \delta \f$ extends to second order
 * only if \f$ \delta^T (\sum_i \omega_i H_i) \delta = 0 \f$ for every self-stress \f$ \omega \f$.
 * @param[in] weights one weight per equation (dim num_constraints); zero weights cost nothing.
 * @return Symmetric, num_coordinates square.
 */
Eigen::SparseMatrix<double> computeStressedHessian(const CoordinateModel& model,
                                                   const Eigen::Ref<const Eigen::VectorXd>& q,
                                                   const Eigen::Ref<const Eigen::VectorXd>& weights);

}  // namespace mobility_analysis
