#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "mobility_analysis/NaturalCoordinates.hpp"

namespace mobility_analysis {

/**
 * @brief Reads the natural coordinates of a model's elements as 3-vectors (planar: z = 0).
 *
 * The one place that knows how an element's coordinates sit in q; every equation form reads q through it.
 */
class ElementView {
 public:
  ElementView(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q)
      : model_(model), q_(q), dim_(model.dim) {}

  int dim() const { return dim_; }

  /// Coordinates of element @p e (dim 3; planar: z = 0).
  Eigen::Vector3d element(int e) const {
    const int offset = model_.elements[e].offset;
    return dim_ == 3 ? Eigen::Vector3d(q_.segment<3>(offset))
                     : Eigen::Vector3d(q_(offset), q_(offset + 1), 0.0);
  }

  /// head - tail (or head alone).
  Eigen::Vector3d direction(const Direction& d) const {
    return d.tail < 0 ? element(d.head) : (element(d.head) - element(d.tail)).eval();
  }

  /// First coordinate of element @p e in q.
  int offset(int e) const { return model_.elements[e].offset; }

 private:
  const CoordinateModel& model_;
  const Eigen::Ref<const Eigen::VectorXd>& q_;
  int dim_;
};

/// Receives one equation's gradient: (column, value); repeated columns are summed by the receiver.
using GradientSink = std::vector<Eigen::Triplet<double>>;

/**
 * @brief Receives (weighted) Hessian entries (row column, column, value) of one or more equations; repeated
 * entries are summed by the receiver. Both triangles are written (the matrix is symmetric).
 */
using HessianSink = std::vector<Eigen::Triplet<double>>;

/**
 * @brief Writes the blocks of a bilinear term a^T M b into a gradient or Hessian: shared by every form.
 */
class FormWriter {
 public:
  explicit FormWriter(const ElementView& view) : view_(view) {}

  /// Gradient: adds g to the columns of element @p e (only its dim coordinates).
  void addElement(int e, const Eigen::Vector3d& g, int row, GradientSink& sink) const;
  /// Gradient: adds g to head and -g to tail of @p d.
  void addDirection(const Direction& d, const Eigen::Vector3d& g, int row, GradientSink& sink) const;
  /**
   * @brief Hessian of weight * a^T M b, with a and b directions (linear in q): the (a, b) block M and the
   * (b, a) block M^T, each spread over the heads (+) and tails (-) of the two directions.
   */
  void addBilinear(const Direction& a, const Direction& b, const Eigen::Matrix3d& M, double weight,
                   HessianSink& sink) const;

 private:
  void addBlock(int ea, int eb, const Eigen::Matrix3d& M, HessianSink& sink) const;
  const ElementView& view_;
};

/**
 * @name Equation forms
 * One small type per EquationForm, owning the value, the gradient and the Hessian of its scalar equation
 * f(q) = 0. Natural coordinates make most forms at most quadratic, so their Hessian is constant
 * (`kConstantHessian`); a form that is not (the triple product, a coupling of joint angles) says so and
 * evaluates its Hessian at q. Adding a form: one type here, one enumerator in EquationForm, one case in
 * visitForm — the residual, the Jacobian, the second-order test and the Hessian checks all read it.
 * @{
 */

/// a·b - value. Hessian: the (a, b) block I.
struct DotForm {
  static constexpr bool kConstantHessian = true;
  static double value(const ElementView& v, const ConstraintEquation& eq);
  static void gradient(const ElementView& v, const ConstraintEquation& eq, int row, GradientSink& sink);
  static void hessian(const ElementView& v, const ConstraintEquation& eq, double weight, HessianSink& sink);
};

/// (a x b)_k - value (planar: a_x b_y - a_y b_x - value) = a^T (-[e_k]x) b - value.
struct CrossForm {
  static constexpr bool kConstantHessian = true;
  static double value(const ElementView& v, const ConstraintEquation& eq);
  static void gradient(const ElementView& v, const ConstraintEquation& eq, int row, GradientSink& sink);
  static void hessian(const ElementView& v, const ConstraintEquation& eq, double weight, HessianSink& sink);
};

/// a_k - value: linear, Hessian zero.
struct ComponentForm {
  static constexpr bool kConstantHessian = true;
  static double value(const ElementView& v, const ConstraintEquation& eq);
  static void gradient(const ElementView& v, const ConstraintEquation& eq, int row, GradientSink& sink);
  static void hessian(const ElementView& v, const ConstraintEquation& eq, double weight, HessianSink& sink);
};

/// (x_target - x_origin - c0 d1 - c1 d2 - c2 d1 x d2)_k; planar d2 := J d1 and no c2 term (linear there).
struct CombinationForm {
  static constexpr bool kConstantHessian = true;
  static double value(const ElementView& v, const ConstraintEquation& eq);
  static void gradient(const ElementView& v, const ConstraintEquation& eq, int row, GradientSink& sink);
  static void hessian(const ElementView& v, const ConstraintEquation& eq, double weight, HessianSink& sink);
};

/// (a x b)·c - value: cubic, so its Hessian depends on q (blocks -[c]x, -[a]x, -[b]x).
struct TripleForm {
  static constexpr bool kConstantHessian = false;
  static double value(const ElementView& v, const ConstraintEquation& eq);
  static void gradient(const ElementView& v, const ConstraintEquation& eq, int row, GradientSink& sink);
  static void hessian(const ElementView& v, const ConstraintEquation& eq, double weight, HessianSink& sink);
};
/** @} */

/**
 * @brief Calls @p visitor with a value of the form type of @p form (DotForm{}, CrossForm{}, …).
 * @return What the visitor returns.
 */
template <class Visitor>
decltype(auto) visitForm(EquationForm form, Visitor&& visitor) {
  switch (form) {
    case EquationForm::Dot:
      return visitor(DotForm{});
    case EquationForm::Cross:
      return visitor(CrossForm{});
    case EquationForm::Component:
      return visitor(ComponentForm{});
    case EquationForm::Combination:
      return visitor(CombinationForm{});
    case EquationForm::Triple:
      return visitor(TripleForm{});
  }
  return visitor(ComponentForm{});  // unreachable: every enumerator has a case
}

/// @return Whether the Hessian of @p form is the same at every q.
bool hasConstantHessian(EquationForm form);

}  // namespace mobility_analysis
