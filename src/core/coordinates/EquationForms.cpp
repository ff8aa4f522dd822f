#include "mobility_analysis/coordinates/EquationForms.hpp"

namespace mobility_analysis {

namespace {

/// [v]x, the matrix of v x (.).
Eigen::Matrix3d crossMatrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

/// The planar operand J d1 (a quarter turn) of a Combination, or d2 in space.
Eigen::Vector3d secondBasis(const ElementView& v, const ConstraintEquation& eq) {
  if (v.dim() == 3)
    return v.direction(eq.d2());
  const Eigen::Vector3d d1 = v.direction(eq.d1());
  return Eigen::Vector3d(-d1.y(), d1.x(), 0.0);
}

/// The component a cross form reads: k in space, z in the plane.
int crossComponent(const ElementView& v, const ConstraintEquation& eq) {
  return v.dim() == 3 ? eq.component : 2;
}

}  // namespace

void FormWriter::addElement(int e, const Eigen::Vector3d& g, int row, GradientSink& sink) const {
  const int offset = view_.offset(e);
  for (int i = 0; i < view_.dim(); ++i) {
    if (g[i] != 0.0)
      sink.emplace_back(row, offset + i, g[i]);
  }
}

void FormWriter::addDirection(const Direction& d, const Eigen::Vector3d& g, int row,
                              GradientSink& sink) const {
  addElement(d.head, g, row, sink);
  if (d.tail >= 0)
    addElement(d.tail, -g, row, sink);
}

void FormWriter::addBlock(int ea, int eb, const Eigen::Matrix3d& M, HessianSink& sink) const {
  const int oa = view_.offset(ea), ob = view_.offset(eb);
  for (int i = 0; i < view_.dim(); ++i) {
    for (int j = 0; j < view_.dim(); ++j) {
      if (M(i, j) != 0.0) {
        sink.emplace_back(oa + i, ob + j, M(i, j));
        sink.emplace_back(ob + j, oa + i, M(i, j));
      }
    }
  }
}

void FormWriter::addBilinear(const Direction& a, const Direction& b, const Eigen::Matrix3d& M, double weight,
                             HessianSink& sink) const {
  if (weight == 0.0)
    return;
  // a = x_ha - x_ta, b = x_hb - x_tb: the block of each (element of a, element of b) pair carries the signs.
  const Eigen::Matrix3d W = weight * M;
  addBlock(a.head, b.head, W, sink);
  if (a.tail >= 0)
    addBlock(a.tail, b.head, -W, sink);
  if (b.tail >= 0)
    addBlock(a.head, b.tail, -W, sink);
  if (a.tail >= 0 && b.tail >= 0)
    addBlock(a.tail, b.tail, W, sink);
}

// --- Dot: a·b - value
// -------------------------------------------------------------------------------------------
double DotForm::value(const ElementView& v, const ConstraintEquation& eq) {
  return v.direction(eq.a).dot(v.direction(eq.b)) - eq.value;
}

void DotForm::gradient(const ElementView& v, const ConstraintEquation& eq, int row, GradientSink& sink) {
  // d(a.b) = b.da + a.db
  const FormWriter writer(v);
  writer.addDirection(eq.a, v.direction(eq.b), row, sink);
  writer.addDirection(eq.b, v.direction(eq.a), row, sink);
}

void DotForm::hessian(const ElementView& v, const ConstraintEquation& eq, double weight, HessianSink& sink) {
  FormWriter(v).addBilinear(eq.a, eq.b, Eigen::Matrix3d::Identity(), weight, sink);
}

// --- Cross: (a x b)_k - value = a^T (-[e_k]x) b - value
// ---------------------------------------------------------
double CrossForm::value(const ElementView& v, const ConstraintEquation& eq) {
  return v.direction(eq.a).cross(v.direction(eq.b))[crossComponent(v, eq)] - eq.value;
}

void CrossForm::gradient(const ElementView& v, const ConstraintEquation& eq, int row, GradientSink& sink) {
  // (a x b)_k = a.(b x e_k) = b.(e_k x a); planar (k = z): a_x b_y - a_y b_x.
  const Eigen::Vector3d ek = Eigen::Vector3d::Unit(crossComponent(v, eq));
  const Eigen::Vector3d a = v.direction(eq.a);
  const Eigen::Vector3d b = v.direction(eq.b);
  const FormWriter writer(v);
  writer.addDirection(eq.a, b.cross(ek), row, sink);
  writer.addDirection(eq.b, ek.cross(a), row, sink);
}

void CrossForm::hessian(const ElementView& v, const ConstraintEquation& eq, double weight,
                        HessianSink& sink) {
  const Eigen::Vector3d ek = Eigen::Vector3d::Unit(crossComponent(v, eq));
  FormWriter(v).addBilinear(eq.a, eq.b, -crossMatrix(ek), weight, sink);
}

// --- Component: a_k - value
// -------------------------------------------------------------------------------------
double ComponentForm::value(const ElementView& v, const ConstraintEquation& eq) {
  return v.direction(eq.a)[eq.component] - eq.value;
}

void ComponentForm::gradient(const ElementView& v, const ConstraintEquation& eq, int row,
                             GradientSink& sink) {
  FormWriter(v).addDirection(eq.a, Eigen::Vector3d::Unit(eq.component), row, sink);
}

void ComponentForm::hessian(const ElementView&, const ConstraintEquation&, double, HessianSink&) {}

// --- Combination: (x_target - x_origin - c0 d1 - c1 d2 - c2 d1 x d2)_k
// ----------------------------------------
double CombinationForm::value(const ElementView& v, const ConstraintEquation& eq) {
  const Eigen::Vector3d d1 = v.direction(eq.d1());
  const Eigen::Vector3d d2 = secondBasis(v, eq);
  Eigen::Vector3d r = v.element(eq.target()) - eq.coefficients.x() * d1 - eq.coefficients.y() * d2;
  if (eq.origin() >= 0)
    r -= v.element(eq.origin());
  if (v.dim() == 3)
    r -= eq.coefficients.z() * d1.cross(d2);
  return r[eq.component];
}

void CombinationForm::gradient(const ElementView& v, const ConstraintEquation& eq, int row,
                               GradientSink& sink) {
  const int k = eq.component;
  const Eigen::Vector3d ek = Eigen::Vector3d::Unit(k);
  const Eigen::Vector3d& c = eq.coefficients;
  const FormWriter writer(v);
  writer.addElement(eq.target(), ek, row, sink);
  if (eq.origin() >= 0)
    writer.addElement(eq.origin(), -ek, row, sink);
  if (v.dim() == 3) {
    // -(c0 d1 + c1 d2 + c2 d1 x d2)_k: d/dd1 = -c0 e_k - c2 (d2 x e_k), d/dd2 = -c1 e_k - c2 (e_k x d1).
    const Eigen::Vector3d d1 = v.direction(eq.d1());
    const Eigen::Vector3d d2 = v.direction(eq.d2());
    writer.addDirection(eq.d1(), -c.x() * ek - c.z() * d2.cross(ek), row, sink);
    writer.addDirection(eq.d2(), -c.y() * ek - c.z() * ek.cross(d1), row, sink);
  } else {
    // -(c0 d1 + c1 J d1)_k with J d1 = (-d1_y, d1_x): row k of c0 I + c1 J.
    const Eigen::Vector3d jRow = k == 0 ? Eigen::Vector3d(0.0, -1.0, 0.0) : Eigen::Vector3d(1.0, 0.0, 0.0);
    writer.addDirection(eq.d1(), -c.x() * ek - c.y() * jRow, row, sink);
  }
}

void CombinationForm::hessian(const ElementView& v, const ConstraintEquation& eq, double weight,
                              HessianSink& sink) {
  // Only the space term -c2 (d1 x d2)_k = c2 d1^T [e_k]x d2 is quadratic; the plane form is linear.
  if (v.dim() != 3 || eq.coefficients.z() == 0.0)
    return;
  FormWriter(v).addBilinear(
      eq.d1(), eq.d2(), eq.coefficients.z() * crossMatrix(Eigen::Vector3d::Unit(eq.component)), weight, sink);
}

// --- Triple: (a x b).c - value
// ----------------------------------------------------------------------------------
double TripleForm::value(const ElementView& v, const ConstraintEquation& eq) {
  return v.direction(eq.a).cross(v.direction(eq.b)).dot(v.direction(eq.c)) - eq.value;
}

void TripleForm::gradient(const ElementView& v, const ConstraintEquation& eq, int row, GradientSink& sink) {
  // d((a x b).c) = (b x c).da + (c x a).db + (a x b).dc
  const Eigen::Vector3d a = v.direction(eq.a);
  const Eigen::Vector3d b = v.direction(eq.b);
  const Eigen::Vector3d c = v.direction(eq.c);
  const FormWriter writer(v);
  writer.addDirection(eq.a, b.cross(c), row, sink);
  writer.addDirection(eq.b, c.cross(a), row, sink);
  writer.addDirection(eq.c, a.cross(b), row, sink);
}

void TripleForm::hessian(const ElementView& v, const ConstraintEquation& eq, double weight,
                         HessianSink& sink) {
  // (a x b).c = -a^T [c]x b = -b^T [a]x c = -c^T [b]x a: one block per pair, each linear in the third
  // operand.
  const FormWriter writer(v);
  writer.addBilinear(eq.a, eq.b, -crossMatrix(v.direction(eq.c)), weight, sink);
  writer.addBilinear(eq.b, eq.c, -crossMatrix(v.direction(eq.a)), weight, sink);
  writer.addBilinear(eq.c, eq.a, -crossMatrix(v.direction(eq.b)), weight, sink);
}

bool hasConstantHessian(EquationForm form) {
  return visitForm(form, [](auto type) { return decltype(type)::kConstantHessian; });
}

}  // namespace mobility_analysis
