#include <algorithm>

#include "mobility_analysis/Tolerances.hpp"
#include "mobility_analysis/coordinates/ModelBuilder.hpp"

namespace mobility_analysis {

void addBodyBases(ModelBuilder& builder) {
  const Mechanism& mechanism = builder.mechanism;
  CoordinateModel& model = builder.model;
  const bool planar = builder.planar();
  builder.bases.assign(mechanism.links.size(), BodyBasis{});
  std::vector<Direction> candidates;  // per body, reused (no allocation per body)
  // p0 and the best-conditioned directions; auxiliary unit vectors where the joints give too few.
  for (size_t b = 0; b < mechanism.links.size(); ++b) {
    const int body = static_cast<int>(b);
    BodyBasis& basis = builder.bases[b];
    for (int e : model.bodyElements[b]) {
      if (model.elements[e].isPoint) {
        basis.p0 = e;
        break;
      }
    }
    if (basis.p0 < 0) {
      basis.p0 = builder.addElement(body, true, Eigen::Vector3d::Zero(), ElementRole::Origin);
    }
    candidates.clear();
    for (int e : model.bodyElements[b]) {
      if (e == basis.p0)
        continue;
      candidates.push_back(Direction{e, model.elements[e].isPoint ? basis.p0 : -1});
    }
    double best = tolerances::kIndependentDirection;
    for (const Direction& d : candidates) {
      const double norm = builder.directionValue(d).norm();
      if (norm > best * (1.0 + 1e-9)) {
        best = norm;
        basis.d1 = d;
      }
    }
    const Eigen::Matrix3d rotation = builder.poses[b].linear();
    if (basis.d1.head < 0) {
      // No direction from the joints (a body on one pin or ball): a unit vector of its own frame.
      Eigen::Vector3d local = Eigen::Vector3d::UnitX();
      if (planar) {
        const Eigen::Vector3d n = rotation.transpose() * model.planeNormal;
        local = (local - n.dot(local) * n).norm() > 0.5 ? (local - n.dot(local) * n).normalized().eval()
                                                        : n.unitOrthogonal();
      }
      basis.d1 = Direction{builder.addElement(body, false, local, ElementRole::Auxiliary1), -1};
    }
    if (planar)
      continue;
    const Eigen::Vector3d d1 = builder.directionValue(basis.d1);
    double bestSine = tolerances::kIndependentDirection;
    for (const Direction& d : candidates) {
      if (d.head == basis.d1.head)
        continue;
      const Eigen::Vector3d v = builder.directionValue(d);
      const double perpendicular = d1.cross(v).norm() / d1.norm();
      const double sine = perpendicular / std::max(v.norm(), 1e-300);
      if (sine > tolerances::kIndependentDirection && perpendicular > bestSine * (1.0 + 1e-9)) {
        bestSine = perpendicular;
        basis.d2 = d;
      }
    }
    if (basis.d2.head < 0) {
      // A rod, or a body whose joint elements are all on one line: its spin needs a second direction.
      const Eigen::Vector3d worldAux = d1.unitOrthogonal();
      basis.d2 = Direction{
          builder.addElement(body, false, rotation.transpose() * worldAux, ElementRole::Auxiliary2), -1};
    }
  }
}

}  // namespace mobility_analysis
