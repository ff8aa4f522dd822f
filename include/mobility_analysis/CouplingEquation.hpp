#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace mobility_analysis {

struct CoordinateModel;
struct ModelBuilder;

/**
 * @brief One 1-DOF tree joint's value as a function of the natural coordinates.
 *
 * Revolute: \f$ \theta = \operatorname{atan2}(u\cdot(a\times b),\ a\cdot b - (a\cdot u)(b\cdot u)) - \theta_0
 * \f$ with a a direction of the parent, b one of the child and u the axis on the parent (planar: the plane
 * normal), wrapped to (-pi, pi]. Prismatic: \f$ s = (P_{child} - P_{parent})\cdot u - s_0 \f$ [normalised
 * length]. Element indices refer to CoordinateModel::elements.
 */
struct JointValueOperand {
  bool prismatic = false;
  int aHead = -1, aTail = -1;  ///< Revolute: the parent's direction; prismatic: aHead is the parent's point.
  int bHead = -1, bTail = -1;  ///< Revolute: the child's direction; prismatic: bHead is the child's point.
  int axis = -1;               ///< The parent's axis unit vector; -1: the plane normal (planar revolute).
  double rest = 0.0;           ///< The raw value at joint value 0 (theta_0 or s_0).
};

/**
 * @brief A coupling equation (URDF `<mimic>`, URDF+ `<coupling>`, MJCF joint equality):
 *        \f$ v_f(q) - m\, v_l(q) - c = 0 \f$.
 *
 * Not quadratic in natural coordinates (an angle between two bodies' directions), so it has its own value,
 * gradient and Hessian here instead of an EquationForm of ConstraintJacobian. Units: the follower's (rad, or
 * normalised length for a prismatic follower); multiplier and offset are converted when the model is built.
 */
struct CouplingTerms {
  JointValueOperand follower;
  JointValueOperand leader;
  /// Weighted joint values added to the follower's and to the leader's (Joint::moreFollowers,
  /// Joint::moreLeaders: revolute ones only, so in the same unit).
  std::vector<std::pair<JointValueOperand, double>> moreFollowers, moreLeaders;
  double multiplier = 1.0;  ///< m, in follower units per leader unit (normalised lengths for prismatic).
  double offset = 0.0;      ///< c, in follower units.
};

/// @return The joint value of @p operand at @p q [rad] or [normalised length].
double evaluateJointValue(const JointValueOperand& operand, const CoordinateModel& model,
                          const Eigen::Ref<const Eigen::VectorXd>& q);

/// @return The residual \f$ v_f - m v_l - c \f$ at @p q (each v with the values summed with it).
double evaluateCoupling(const CouplingTerms& terms, const CoordinateModel& model,
                        const Eigen::Ref<const Eigen::VectorXd>& q);

/**
 * @brief Appends the analytic gradient of the coupling residual as (row, column, value) triplets; repeated
 *        columns are summed by setFromTriplets.
 */
void appendCouplingGradient(const CouplingTerms& terms, const CoordinateModel& model,
                            const Eigen::Ref<const Eigen::VectorXd>& q, int row,
                            std::vector<Eigen::Triplet<double>>& triplets);

/**
 * @brief The Hessian of the coupling residual on the coordinates it depends on, by central differences of the
 *        analytic gradient (step 1e-6 in normalised units: error O(1e-12) relative).
 * @param[out] columns the coordinates (columns of q) the Hessian is over, ascending.
 * @param[out] hessian dim columns.size() x columns.size(), symmetrised.
 */
void computeCouplingHessian(const CouplingTerms& terms, const CoordinateModel& model,
                            const Eigen::Ref<const Eigen::VectorXd>& q, std::vector<int>& columns,
                            Eigen::MatrixXd& hessian);

/**
 * @brief Phase 5 of buildCoordinateModel for a coupling (coordinates/JointEquations.cpp calls it): builds the
 *        operands of both joints from their elements and the bodies' bases, and appends the one equation
 *        (EquationForm::Coupling, coordinates/EquationForms.hpp CouplingForm).
 *
 * A prismatic joint's value is read from its two points along its axis; a revolute one's from its axis
 * (planar: the plane normal) and, on each body, the basis direction most normal to it, with theta_0 measured
 * with the child turned back to the joint's zero.
 */
void addCouplingEquation(ModelBuilder& builder, int joint);

}  // namespace mobility_analysis
