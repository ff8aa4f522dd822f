#include <algorithm>
#include <array>

#include <Eigen/Dense>

#include "mobility_analysis/coordinates/ModelBuilder.hpp"

namespace mobility_analysis {

void addRigidLinkEquations(ModelBuilder& builder) {
  CoordinateModel& model = builder.model;
  const bool planar = builder.planar();
  const int dim = model.dim;
  // Links in document order: the basis dot products (d_i.d_j fixed), then every other element as a linear
  // combination of the basis (García de Jalón & Bayo, ch. 3), so each body keeps exactly lambda freedoms.
  // Room for every equation of the model at once (these, then the joints' and the ground's, about lambda - F
  // each): 10^6 equations are not copied over and over while the vector grows.
  size_t count = 0;
  for (size_t b = 0; b < builder.mechanism.links.size(); ++b)
    count += (planar ? 1 : 3) + static_cast<size_t>(dim) * model.bodyElements[b].size();
  for (size_t j = 0; j < builder.mechanism.joints.size(); ++j) {
    if (model.jointActive[j] && model.jointFreedom[j] >= 0)
      count += static_cast<size_t>(std::max(model.lambda - model.jointFreedom[j], 0));
  }
  model.equations.reserve(model.equations.size() + count + static_cast<size_t>(2 * model.lambda));
  for (size_t b = 0; b < builder.mechanism.links.size(); ++b) {
    const BodyBasis& basis = builder.bases[b];
    const std::array<Direction, 2> dirs = {basis.d1, basis.d2};
    const size_t numDirs = planar ? 1 : 2;
    for (size_t i = 0; i < numDirs; ++i) {
      for (size_t j = i; j < numDirs; ++j) {
        ConstraintEquation& eq = model.equations.emplace_back();  // written in place, not copied in
        eq.source = EquationSource::Link;
        eq.element = static_cast<int>(b);
        eq.form = EquationForm::Dot;
        eq.a = dirs[i];
        eq.b = dirs[j];
        eq.value = builder.directionValue(dirs[i]).dot(builder.directionValue(dirs[j]));
        if (i == j && dirs[i].tail < 0) {
          eq.kind = EquationKind::UnitNorm;
          eq.value = 1.0;
        } else if (i == j) {
          eq.kind = EquationKind::LinkDistance;
        } else {
          eq.kind = EquationKind::LinkDotProduct;
        }
      }
    }
    const Eigen::Vector3d d1 = builder.directionValue(basis.d1);
    Eigen::Matrix3d frame;
    if (planar) {
      frame.col(0) = d1;
      frame.col(1) = Eigen::Vector3d(-d1.y(), d1.x(), 0.0);
      frame.col(2) = Eigen::Vector3d::UnitZ();
    } else {
      const Eigen::Vector3d d2 = builder.directionValue(basis.d2);
      frame.col(0) = d1;
      frame.col(1) = d2;
      frame.col(2) = d1.cross(d2);
    }
    const Eigen::PartialPivLU<Eigen::Matrix3d> lu(frame);
    for (int e : model.bodyElements[b]) {
      if (e == basis.p0 || e == basis.d1.head || (!planar && e == basis.d2.head))
        continue;
      const bool isPoint = model.elements[e].isPoint;
      const Eigen::Vector3d rhs =
          isPoint ? (builder.coordinates(e) - builder.coordinates(basis.p0)).eval() : builder.coordinates(e);
      const Eigen::Vector3d coefficients = lu.solve(rhs);
      for (int k = 0; k < dim; ++k) {
        ConstraintEquation& eq = model.equations.emplace_back();
        eq.source = EquationSource::Link;
        eq.element = static_cast<int>(b);
        eq.kind = EquationKind::LinearCombination;
        eq.form = EquationForm::Combination;
        eq.component = k;
        eq.target() = e;
        eq.origin() = isPoint ? basis.p0 : -1;
        eq.d1() = basis.d1;
        eq.d2() = basis.d2;
        eq.coefficients = coefficients;
        if (planar)
          eq.coefficients.z() = 0.0;
      }
    }
  }
}

}  // namespace mobility_analysis
