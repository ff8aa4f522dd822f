/// Small pieces every family generator builds its mechanisms from (internal to src/generators).
#pragma once

#include "mobility_analysis/generators/MechanismDescription.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <cmath>
#include <string>
#include <vector>

namespace mobility_analysis {
namespace generator_parts {

constexpr double kDeg = M_PI / 180.0;

/// The closed form of one analysis mode; lambda and the redundancy follow from the mode and the counts.
inline FamilyExpectation expectation(const std::string& mode, int dof, int grubler) {
  const int lambda = mode == "planar" ? 3 : 6;
  return FamilyExpectation{mode, lambda, dof, grubler, dof - grubler};
}

inline LinkDescription link(std::string name, std::vector<Eigen::Vector3d> path = {}) {
  LinkDescription description;
  description.name = std::move(name);
  description.visualPath = std::move(path);
  return description;
}

/// Where the pins of unit j of makeHobermanRing() are, for the cables of the ring pantographs: the same
/// formulas as the ring (unit 0 around its kink at 0, u2 = −Rot(κ) u1, v2 = −Rot(κ) v1; the centre O of the
/// rotation by κ taking A1 → B2 solves (I − Rκ) O = B2 − Rκ A1).
struct HobermanRingGeometry {
  Eigen::Vector2d a1, b1, a2, b2, centre;
  double kappa = 0.0;
  HobermanRingGeometry(int units, double openingDeg) {
    const double arm = 0.5, phase = 100 * kDeg, opening = openingDeg * kDeg;
    kappa = 2.0 * M_PI / units;
    const Eigen::Rotation2Dd rk(kappa);
    const Eigen::Vector2d u1(std::cos(phase), std::sin(phase));
    const Eigen::Vector2d v1(std::cos(phase + opening), std::sin(phase + opening));
    a1 = arm * u1;
    b1 = arm * v1;
    a2 = -arm * (rk * u1);
    b2 = -arm * (rk * v1);
    centre = (Eigen::Matrix2d::Identity() - rk.toRotationMatrix()).fullPivLu().solve(b2 - rk * a1);
  }
  /// Point p of unit 0 carried to unit j (rotation by jκ about the centre), in the plane z = 0.
  Eigen::Vector3d place(int j, const Eigen::Vector2d& p) const {
    const Eigen::Vector2d q = centre + Eigen::Rotation2Dd(j * kappa) * (p - centre);
    return Eigen::Vector3d(q.x(), q.y(), 0.0);
  }
  Eigen::Vector3d kink(int j) const { return place(j, Eigen::Vector2d::Zero()); }
};

}  // namespace generator_parts
}  // namespace mobility_analysis
