#pragma once

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/JointTypes.hpp"
#include "mobility_analysis/Kinematics.hpp"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"

namespace mobility_analysis {

/**
 * @brief The phases of buildCoordinateModel (NaturalCoordinates.hpp), one file each under
 * src/core/coordinates/:
 *
 * 1. JointElements.cpp — the elements at the joints and each connection's primitives (the joint-type table).
 * 2. BodyBases.cpp — each body's base point p0 and directions d1, d2 (auxiliary unit vectors where needed).
 * 3. CoordinateOrdering.cpp — elements grouped by body in document order; q0.
 * 4. RigidLinkEquations.cpp — basis dot products and linear combinations, links in document order.
 * 5. JointEquations.cpp — one writer per Primitive (where a joint type's equations live).
 * 6. BoundaryEquations.cpp — the ground's lambda freedoms fixed.
 *
 * Internal to the core: callers use buildCoordinateModel.
 */

/// Per connection: the elements its equations use on each side (-1 when not needed) and its primitives.
struct ConnectionElements {
  /// At most three primitives a connection (JointTypes.cpp), kept in place: a vector each was an allocation
  /// per connection (10^5 on a chain).
  class Primitives {
   public:
    Primitives& operator=(const std::vector<Primitive>& list) {
      count_ = std::min(list.size(), items_.size());
      std::copy(list.begin(), list.begin() + static_cast<std::ptrdiff_t>(count_), items_.begin());
      return *this;
    }
    const Primitive* begin() const { return items_.data(); }
    const Primitive* end() const { return items_.data() + count_; }

   private:
    std::array<Primitive, 3> items_{};
    size_t count_ = 0;
  };
  int point1 = -1, point2 = -1, axis1 = -1, axis2 = -1;
  Primitives primitives;
  Eigen::Vector3d axisWorld = Eigen::Vector3d::UnitZ();
};

/// Body basis of the rigid-link equations: base point p0 and directions d1, d2 (planar: d1 only).
struct BodyBasis {
  int p0 = -1;
  Direction d1, d2;
};

/// The state shared by the phases: the model being written and what the phases hand to each other.
struct ModelBuilder {
  const Mechanism& mechanism;
  const LinkPoses& poses;
  CoordinateModel& model;
  std::vector<Eigen::Vector3d> world;  ///< Element values at the pose (normalised, full 3-D).
  /// Per connection, worldAxes at the pose (zero for a coupling).
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> axes;
  std::vector<ConnectionElements> connections;  ///< Per joint (phase 1).
  std::vector<BodyBasis> bases;                 ///< Per link (phase 2).

  ModelBuilder(const Mechanism& m, const LinkPoses& p, CoordinateModel& out)
      : mechanism(m), poses(p), model(out) {}

  bool planar() const { return model.dim == 2; }
  /// Adds an element of @p body at @p local (point: divided by Lc) and returns its index; @p role and
  /// @p joint (-1 for the body's own elements) make its label (elementLabel).
  int addElement(int body, bool isPoint, const Eigen::Vector3d& local, ElementRole role, int joint = -1);
  /// Element @p e in the model's space: the world value, projected on (e1, e2) in the plane (z = 0).
  Eigen::Vector3d coordinates(int e) const;
  /// A direction's value in the model's space.
  Eigen::Vector3d directionValue(const Direction& d) const;
  /// Projects a world vector into the model's space.
  Eigen::Vector3d project(const Eigen::Vector3d& w) const;
  /// A direction's full 3-D world value.
  Eigen::Vector3d worldOf(const Direction& d) const;
};

/// Joint axis (and universal second axis) of a connection in the world frame at @p poses.
std::pair<Eigen::Vector3d, Eigen::Vector3d> worldAxes(const Joint& joint, const LinkPoses& poses);
/// worldAxes(...).first alone.
Eigen::Vector3d worldAxis(const Joint& joint, const LinkPoses& poses);

/// Phase 1: elements at the joints; fails on a joint that cannot act in the plane or a cable longer than its
/// length.
std::optional<Diagnostic> addJointElements(ModelBuilder& builder);
/// Phase 2: body bases.
void addBodyBases(ModelBuilder& builder);
/// Phase 3: coordinate order (by body, document order) and q0.
void orderCoordinates(ModelBuilder& builder);
/// Phase 4: rigid-link equations.
void addRigidLinkEquations(ModelBuilder& builder);
/// Phase 5: joint equations (tree joints, distance constraints, cables, loop joints; the loader's order).
void addJointEquations(ModelBuilder& builder);
/// Phase 6: boundary equations.
void addBoundaryEquations(ModelBuilder& builder);

}  // namespace mobility_analysis
