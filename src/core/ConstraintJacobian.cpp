#include "mobility_analysis/ConstraintJacobian.hpp"

#include <vector>

namespace mobility_analysis {

namespace {

/// Reads element coordinates as 3-vectors (planar: z = 0) and accumulates one equation's gradient.
class EquationEvaluator {
 public:
  EquationEvaluator(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q)
      : model_(model), q_(q), dim_(model.dim) {}

  Eigen::Vector3d element(int e) const {
    const int offset = model_.elements[e].offset;
    return dim_ == 3 ? Eigen::Vector3d(q_.segment<3>(offset))
                     : Eigen::Vector3d(q_(offset), q_(offset + 1), 0.0);
  }

  Eigen::Vector3d direction(const Direction& d) const {
    return d.tail < 0 ? element(d.head) : (element(d.head) - element(d.tail)).eval();
  }

  /// d1 x d2 in space; J d1 (the quarter turn) in the plane.
  Eigen::Vector3d second(const ConstraintEquation& eq) const {
    if (dim_ == 3)
      return direction(eq.d2);
    const Eigen::Vector3d d1 = direction(eq.d1);
    return Eigen::Vector3d(-d1.y(), d1.x(), 0.0);
  }

  double value(const ConstraintEquation& eq) const {
    const int k = eq.component;
    switch (eq.form) {
      case EquationForm::Dot:
        return direction(eq.a).dot(direction(eq.b)) - eq.value;
      case EquationForm::Cross:
        return direction(eq.a).cross(direction(eq.b))[dim_ == 3 ? k : 2] - eq.value;
      case EquationForm::Component:
        return direction(eq.a)[k] - eq.value;
      case EquationForm::Triple:
        return direction(eq.a).cross(direction(eq.b)).dot(direction(eq.c)) - eq.value;
      case EquationForm::Coupling:
        return evaluateCoupling(model_.couplings[eq.coupling], model_, q_);
      case EquationForm::Combination: {
        const Eigen::Vector3d d1 = direction(eq.d1);
        const Eigen::Vector3d d2 = second(eq);
        Eigen::Vector3d r = element(eq.target) - eq.coefficients.x() * d1 - eq.coefficients.y() * d2;
        if (eq.origin >= 0)
          r -= element(eq.origin);
        if (dim_ == 3)
          r -= eq.coefficients.z() * d1.cross(d2);
        return r[k];
      }
    }
    return 0.0;
  }

  /// Appends (row, column, value) of the equation's gradient; repeated columns are summed by setFromTriplets.
  void gradient(const ConstraintEquation& eq, int row, std::vector<Eigen::Triplet<double>>& triplets) const {
    const int k = eq.component;
    const Eigen::Vector3d ek = Eigen::Vector3d::Unit(k);
    switch (eq.form) {
      case EquationForm::Dot: {
        // d(a.b) = b.da + a.db
        addDirection(eq.a, direction(eq.b), row, triplets);
        addDirection(eq.b, direction(eq.a), row, triplets);
        break;
      }
      case EquationForm::Cross: {
        // (a x b)_k = a.(b x e_k) = b.(e_k x a); planar: a_x b_y - a_y b_x.
        const Eigen::Vector3d a = direction(eq.a);
        const Eigen::Vector3d b = direction(eq.b);
        if (dim_ == 3) {
          addDirection(eq.a, b.cross(ek), row, triplets);
          addDirection(eq.b, ek.cross(a), row, triplets);
        } else {
          addDirection(eq.a, Eigen::Vector3d(b.y(), -b.x(), 0.0), row, triplets);
          addDirection(eq.b, Eigen::Vector3d(-a.y(), a.x(), 0.0), row, triplets);
        }
        break;
      }
      case EquationForm::Component:
        addDirection(eq.a, ek, row, triplets);
        break;
      case EquationForm::Triple: {
        // d((a x b).c) = (b x c).da + (c x a).db + (a x b).dc
        const Eigen::Vector3d a = direction(eq.a);
        const Eigen::Vector3d b = direction(eq.b);
        const Eigen::Vector3d c = direction(eq.c);
        addDirection(eq.a, b.cross(c), row, triplets);
        addDirection(eq.b, c.cross(a), row, triplets);
        addDirection(eq.c, a.cross(b), row, triplets);
        break;
      }
      case EquationForm::Coupling:
        appendCouplingGradient(model_.couplings[eq.coupling], model_, q_, row, triplets);
        break;
      case EquationForm::Combination: {
        const Eigen::Vector3d& c = eq.coefficients;
        addElement(eq.target, ek, row, triplets);
        if (eq.origin >= 0)
          addElement(eq.origin, -ek, row, triplets);
        if (dim_ == 3) {
          // -(c0 d1 + c1 d2 + c2 d1 x d2)_k: d/dd1 = -c0 e_k - c2 (d2 x e_k), d/dd2 = -c1 e_k - c2 (e_k x
          // d1).
          const Eigen::Vector3d d1 = direction(eq.d1);
          const Eigen::Vector3d d2 = direction(eq.d2);
          addDirection(eq.d1, -c.x() * ek - c.z() * d2.cross(ek), row, triplets);
          addDirection(eq.d2, -c.y() * ek - c.z() * ek.cross(d1), row, triplets);
        } else {
          // -(c0 d1 + c1 J d1)_k with J d1 = (-d1_y, d1_x): row k of c0 I + c1 J.
          const Eigen::Vector3d jRow =
              k == 0 ? Eigen::Vector3d(0.0, -1.0, 0.0) : Eigen::Vector3d(1.0, 0.0, 0.0);
          addDirection(eq.d1, -c.x() * ek - c.y() * jRow, row, triplets);
        }
        break;
      }
    }
  }

 private:
  void addElement(int e, const Eigen::Vector3d& g, int row,
                  std::vector<Eigen::Triplet<double>>& triplets) const {
    const int offset = model_.elements[e].offset;
    for (int i = 0; i < dim_; ++i) {
      if (g[i] != 0.0)
        triplets.emplace_back(row, offset + i, g[i]);
    }
  }

  void addDirection(const Direction& d, const Eigen::Vector3d& g, int row,
                    std::vector<Eigen::Triplet<double>>& triplets) const {
    addElement(d.head, g, row, triplets);
    if (d.tail >= 0)
      addElement(d.tail, -g, row, triplets);
  }

  const CoordinateModel& model_;
  const Eigen::Ref<const Eigen::VectorXd>& q_;
  int dim_;
};

}  // namespace

void computeConstraintResidual(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                               Eigen::VectorXd& phi) {
  const EquationEvaluator evaluator(model, q);
  phi.resize(model.numConstraints());
  for (int i = 0; i < model.numConstraints(); ++i) {
    phi(i) = evaluator.value(model.equations[i]);
  }
}

SparseJacobian computeConstraintJacobian(const CoordinateModel& model,
                                         const Eigen::Ref<const Eigen::VectorXd>& q) {
  const EquationEvaluator evaluator(model, q);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(model.numConstraints()) * 12);
  for (int i = 0; i < model.numConstraints(); ++i) {
    evaluator.gradient(model.equations[i], i, triplets);
  }
  SparseJacobian jacobian(model.numConstraints(), model.numCoordinates());
  jacobian.setFromTriplets(triplets.begin(), triplets.end());
  jacobian.prune(0.0);
  return jacobian;
}

}  // namespace mobility_analysis
