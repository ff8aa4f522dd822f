#include "mobility_analysis/coordinates/ModelBuilder.hpp"

namespace mobility_analysis {

void orderCoordinates(ModelBuilder& builder) {
  CoordinateModel& model = builder.model;
  const int dim = model.dim;
  // Elements grouped by body (document order of links), dim numbers each; every index is remapped.
  int offset = 0;
  std::vector<Element> ordered;
  std::vector<int> newIndex(model.elements.size());
  std::vector<Eigen::Vector3d> orderedWorld;
  ordered.reserve(model.elements.size());
  orderedWorld.reserve(model.elements.size());
  for (size_t b = 0; b < builder.mechanism.links.size(); ++b) {
    for (int e : model.bodyElements[b]) {
      newIndex[e] = static_cast<int>(ordered.size());
      ordered.push_back(model.elements[e]);
      ordered.back().offset = offset;
      orderedWorld.push_back(builder.world[e]);
      offset += dim;
    }
  }
  auto remap = [&](Direction& d) {
    if (d.head >= 0)
      d.head = newIndex[d.head];
    if (d.tail >= 0)
      d.tail = newIndex[d.tail];
  };
  for (BodyBasis& basis : builder.bases) {
    basis.p0 = newIndex[basis.p0];
    remap(basis.d1);
    remap(basis.d2);
  }
  for (ConnectionElements& c : builder.connections) {
    for (int* e : {&c.point1, &c.point2, &c.axis1, &c.axis2}) {
      if (*e >= 0)
        *e = newIndex[*e];
    }
  }
  for (std::vector<int>& list : model.bodyElements) {
    for (int& e : list)
      e = newIndex[e];
  }
  model.elements = std::move(ordered);
  builder.world = std::move(orderedWorld);
  model.q0.resize(offset);
  for (size_t e = 0; e < model.elements.size(); ++e) {
    model.q0.segment(model.elements[e].offset, dim) = builder.coordinates(static_cast<int>(e)).head(dim);
  }
}

}  // namespace mobility_analysis
