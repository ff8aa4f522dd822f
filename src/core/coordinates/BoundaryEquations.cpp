#include <array>
#include <cmath>

#include "mobility_analysis/coordinates/ModelBuilder.hpp"

namespace mobility_analysis {

void addBoundaryEquations(ModelBuilder& builder) {
  CoordinateModel& model = builder.model;
  // The ground's lambda rigid freedoms, fixed by lambda of its coordinates.
  const int root = builder.mechanism.rootLink;
  const BodyBasis& basis = builder.bases[root];
  auto fix = [&](int element, int k) {
    ConstraintEquation eq;
    eq.source = EquationSource::Boundary;
    eq.element = root;
    eq.kind = EquationKind::FixedCoordinate;
    eq.form = EquationForm::Component;
    eq.a = Direction{element, -1};
    eq.component = k;
    eq.value = builder.coordinates(element)[k];
    model.equations.push_back(eq);
  };
  for (int k = 0; k < model.dim; ++k) {
    fix(basis.p0, k);
  }
  // Rotation omega moves a direction d by omega x d: coordinate k of d's head changes by omega.(d x e_k).
  // Pick the coordinates whose rows are best conditioned (largest |det|).
  if (builder.planar()) {
    const Eigen::Vector3d d1 = builder.directionValue(basis.d1);
    fix(basis.d1.head, std::abs(d1.y()) >= std::abs(d1.x()) ? 0 : 1);
    return;
  }
  std::vector<std::pair<int, int>> rows;
  std::vector<Eigen::Vector3d> gradients;
  for (const Direction& d : {basis.d1, basis.d2}) {
    const Eigen::Vector3d v = builder.directionValue(d);
    for (int k = 0; k < 3; ++k) {
      rows.emplace_back(d.head, k);
      gradients.push_back(v.cross(Eigen::Vector3d::Unit(k)));
    }
  }
  double best = -1.0;
  std::array<int, 3> chosen{0, 1, 2};
  for (int r0 = 0; r0 < 6; ++r0) {
    for (int r1 = r0 + 1; r1 < 6; ++r1) {
      for (int r2 = r1 + 1; r2 < 6; ++r2) {
        const double det = std::abs(gradients[r0].dot(gradients[r1].cross(gradients[r2])));
        if (det > best * (1.0 + 1e-12)) {
          best = det;
          chosen = {r0, r1, r2};
        }
      }
    }
  }
  for (int r : chosen) {
    fix(rows[r].first, rows[r].second);
  }
}

}  // namespace mobility_analysis
