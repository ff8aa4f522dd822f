#include "mobility_analysis/generators/ParametricFamilies.hpp"

#include "GeneratorParts.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <cmath>
#include <cstdio>
#include <string>

namespace mobility_analysis {

namespace {

using generator_parts::expectation;
using generator_parts::HobermanRingGeometry;
using generator_parts::kDeg;
using generator_parts::link;

std::string indexed(const char* prefix, int i) {
  return prefix + std::to_string(i);
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
std::vector<FamilyExpectation> expectSlePlanarMast(int units) {
  return {expectation("planar", 1, 1), expectation("spatial", 1, 1 - 3 * units)};
}

MechanismDescription makeSlePlanarMast(int units, double elevationDeg) {
  const double barLength = 1.0;
  const double elevation = elevationDeg * kDeg;
  const double w = barLength * std::cos(elevation);
  const double h = barLength * std::sin(elevation);
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  auto point = [](double x, double y) { return Eigen::Vector3d(x, y, 0.0); };
  auto bar = [](int k, char side) { return "bar_" + std::to_string(k) + "_" + side; };

  MechanismDescription m;
  m.name = "sle_mast_" + std::to_string(units);
  m.comment =
      "Planar scissor (SLE) mast of " + std::to_string(units) +
      " units in the x-y plane, axes along z. Unit k: bar_k_a from (0, (k-1)h) to (w, kh)\n"
      "and bar_k_b from (w, (k-1)h) to (0, kh), pivoted at their midpoints; bars 1 m at 50 deg, w = cos 50,\n"
      "h = sin 50. Unit k+1's feet are pinned to unit k's tops. Base: bar_1_a pinned to the ground at "
      "(0,0),\n"
      "bar_1_b's foot pinned to a slider that slides along x on the ground. Every unit keeps the same\n"
      "angle, so the width w (with w^2 + h^2 = 1) is the one freedom for any number of units.\n"
      "Closed form: planar DOF 1, Gruebler 1, redundant 0; spatial DOF 1, Gruebler 1 - 3N, redundant 3N.";
  m.links.reserve(2 * units + 2);
  m.connections.reserve(3 * units + 1);
  m.links.push_back(link("ground", {point(-0.2, 0), point(w + 0.2, 0)}));
  m.links.push_back(link("slider", {point(w - 0.08, 0), point(w + 0.08, 0)}));
  for (int k = 1; k <= units; ++k) {
    const double y0 = (k - 1) * h;
    m.links.push_back(link(bar(k, 'a'), {point(0, y0), point(w, y0 + h)}));
    m.links.push_back(link(bar(k, 'b'), {point(w, y0), point(0, y0 + h)}));
  }
  m.connections.push_back(makeRevolute("base_pin", "ground", bar(1, 'a'), point(0, 0), z));
  m.connections.push_back(
      makePrismatic("base_slide", "ground", "slider", point(w, 0), Eigen::Vector3d::UnitX()));
  m.connections.push_back(makeRevolute("slider_pin", "slider", bar(1, 'b'), point(w, 0), z));
  for (int k = 1; k <= units; ++k) {
    const double y0 = (k - 1) * h;
    if (k > 1) {
      m.connections.push_back(
          makeRevolute(indexed("left_pin_", k), bar(k - 1, 'b'), bar(k, 'a'), point(0, y0), z));
      m.connections.push_back(
          makeRevolute(indexed("right_pin_", k), bar(k - 1, 'a'), bar(k, 'b'), point(w, y0), z));
    }
    m.connections.push_back(
        makeRevolute(indexed("centre_", k), bar(k, 'a'), bar(k, 'b'), point(0.5 * w, y0 + 0.5 * h), z));
  }
  m.visualRadius = 0.015;
  m.expectations = expectSlePlanarMast(units);
  return m;
}

// ---------------------------------------------------------------------------------------------------------
std::vector<FamilyExpectation> expectSleSpatialMast(int units) {
  return {expectation("spatial", 1, 1 - 3 * units)};
}

MechanismDescription makeSleSpatialMast(int units) {
  MechanismDescription m = makeSlePlanarMast(units);
  m.name = "sle_spatial_" + std::to_string(units);
  m.comment =
      "Scissor (SLE) mast of " + std::to_string(units) +
      " units on a pin + slider base, for analysis in space (mode spatial):\n"
      "the geometry of sle_planar (all hinge axes along z, so auto mode would pick the plane). In space\n"
      "each unit's scissor loop is over-constrained by the 3 out-of-plane equations of a planar loop.\n"
      "Closed form (N units): links 2N + 2, joints 3N + 1; spatial DOF 1, Gruebler 6(2N+2 - 3N-1 - 1) + 3N+1\n"
      "= 1 - 3N, redundant 3N.\n" +
      m.comment.substr(m.comment.find("Unit k:"));
  m.expectations = expectSleSpatialMast(units);
  return m;
}

// ---------------------------------------------------------------------------------------------------------
std::vector<FamilyExpectation> expectSleTriangularMast(int units) {
  return {expectation("spatial", 1, 3 - 6 * units)};
}

MechanismDescription makeSleTriangularMast(int units) {
  const double barLength = 1.0;
  const double elevation = 50 * kDeg;
  const double w = barLength * std::cos(elevation);
  const double h = barLength * std::sin(elevation);
  const double circumradius = w / std::sqrt(3.0);
  Eigen::Vector3d corner[3];
  Eigen::Vector3d normal[3];
  for (int c = 0; c < 3; ++c) {
    const double angle = 90 * kDeg + 120 * kDeg * c;
    corner[c] = Eigen::Vector3d(circumradius * std::cos(angle), circumradius * std::sin(angle), 0.0);
  }
  for (int f = 0; f < 3; ++f) {
    // Face f spans corner f → corner f+1; its pivots are normal to the face.
    normal[f] = (corner[(f + 1) % 3] - corner[f]).cross(Eigen::Vector3d::UnitZ()).normalized();
  }
  auto at = [&](int c, int level) {
    return Eigen::Vector3d(corner[c % 3] + Eigen::Vector3d(0, 0, level * h));
  };
  // Bar a of unit k on face f rises from corner f to corner f+1; bar b from corner f+1 to corner f.
  auto bar = [](int k, int f, char side) {
    return "bar_" + std::to_string(k) + "_" + std::to_string(f) + "_" + side;
  };

  MechanismDescription m;
  m.name = "sle_triangular_" + std::to_string(units);
  m.comment =
      "Spatial scissor mast of " + std::to_string(units) +
      " units: right prism on an equilateral triangle (side w = cos 50 m, centred on the z axis).\n"
      "Each face f (corner f -> corner f+1) is a scissor chain: unit k has bar_k_f_a from corner f at "
      "height\n"
      "(k-1)h to corner f+1 at kh and bar_k_f_b the other diagonal (bars 1 m at 50 deg, h = sin 50), pivoted "
      "at\n"
      "their midpoints by a revolute about the face normal (centre_k_f), so each unit's four ends form a\n"
      "rectangle with diagonal 1 m. Every other joint is spherical: consecutive units of a face meet at the "
      "face\n"
      "edges (pin_k_f_l / pin_k_f_r) and the two faces meeting at a corner are joined at every level\n"
      "(corner_l_c). bar_1_0_a is the ground; bars held only by spherical joints hang by floating joints.\n"
      "Why DOF 1: a face's rectangles share their horizontal edges, so a face has one width w; shared "
      "vertical\n"
      "edges force equal heights, so all faces have the same w and every level is an equilateral triangle "
      "of\n"
      "side w; opposite sides of a rectangle are parallel and equal, so level l is level l-1 translated by "
      "h\n"
      "along the normal of its plane: a right prism, w^2 + h^2 = 1 being the one freedom.\n"
      "Closed form (N units): links 6N, joints 12N - 3 (3N centre R, 9N - 3 spherical),\n"
      "spatial DOF 1, Gruebler 6(6N - 12N + 3 - 1) + 30N - 9 = 3 - 6N, redundant 6N - 2.";
  m.links.reserve(6 * units);
  m.connections.reserve(12 * units);
  for (int k = 1; k <= units; ++k) {
    for (int f = 0; f < 3; ++f) {
      m.links.push_back(link(bar(k, f, 'a'), {at(f, k - 1), at(f + 1, k)}));
      m.links.push_back(link(bar(k, f, 'b'), {at(f + 1, k - 1), at(f, k)}));
    }
  }
  // Spherical rather than revolute face pins: the rectangles already keep each face planar, and three
  // fewer equations per pin keep the model lean (redundancy 6 per unit instead of 18).
  auto addCorners = [&](int level) {
    for (int c = 0; c < 3; ++c) {
      // Corner c is the left edge of face c and the right edge of face c−1.
      const int left = c;
      const int right = (c + 2) % 3;
      const std::string leftBar = level < units ? bar(level + 1, left, 'a') : bar(units, left, 'b');
      const std::string rightBar = level < units ? bar(level + 1, right, 'b') : bar(units, right, 'a');
      m.connections.push_back(makeSpherical("corner_" + std::to_string(level) + "_" + std::to_string(c),
                                            leftBar, rightBar, at(c, level)));
    }
  };
  for (int k = 1; k <= units; ++k) {
    for (int f = 0; f < 3; ++f) {
      if (k > 1) {
        const std::string tag = std::to_string(k) + "_" + std::to_string(f);
        m.connections.push_back(
            makeSpherical("pin_" + tag + "_l", bar(k - 1, f, 'b'), bar(k, f, 'a'), at(f, k - 1)));
        m.connections.push_back(
            makeSpherical("pin_" + tag + "_r", bar(k - 1, f, 'a'), bar(k, f, 'b'), at(f + 1, k - 1)));
      }
      m.connections.push_back(makeRevolute("centre_" + std::to_string(k) + "_" + std::to_string(f),
                                           bar(k, f, 'a'), bar(k, f, 'b'),
                                           0.5 * (at(f, k - 1) + at(f + 1, k)), normal[f]));
    }
    addCorners(k - 1);
  }
  addCorners(units);
  m.visualRadius = 0.015;
  m.expectations = expectSleTriangularMast(units);
  return m;
}

// ---------------------------------------------------------------------------------------------------------
std::vector<FamilyExpectation> expectHobermanRing(int units) {
  return {expectation("planar", 1, -3), expectation("spatial", 1, -3 * units - 6)};
}

MechanismDescription makeHobermanRing(int units, double openingDeg) {
  // Unit 0 around its kink K = 0; both bars bent the same way: u2 = −Rot(κ) u1, v2 = −Rot(κ) v1; the rotation by
  // κ about the centre O takes unit j to unit j + 1 (HobermanRingGeometry).
  const HobermanRingGeometry ring(units, openingDeg);
  const Eigen::Vector2d &a1 = ring.a1, &b1 = ring.b1, &a2 = ring.a2, &b2 = ring.b2;
  auto place = [&](int j, const Eigen::Vector2d& p) { return ring.place(j, p); };
  auto bar = [](int j, char side) { return "bar_" + std::to_string(j) + "_" + side; };
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();

  MechanismDescription m;
  m.name = "hoberman_ring_" + std::to_string(units);
  m.comment =
      "Hoberman-type ring of " + std::to_string(units) +
      " angulated scissor units in the x-y plane, axes along z. Each bar has two arms of 0.5 m meeting at\n"
      "its kink; both bars of a unit are bent the same way: u2 = -Rot(kappa) u1, v2 = -Rot(kappa) v1,\n"
      "kappa = 360/N deg, so A2 - B2 = Rot(kappa) (B1 - A1) for every opening angle and the rotation by "
      "kappa\n"
      "about a point O maps unit j onto unit j+1: the ring closes for every opening (written at 70 deg "
      "between\n"
      "the first arms). Unit j: kink_j pins bar_j_a and bar_j_b; pin_j_ab pins bar_j_a's end 2 to "
      "bar_(j+1)_b's\n"
      "end 1, pin_j_ba bar_j_b's end 2 to bar_(j+1)_a's end 1. bar_0_a is the ground.\n"
      "Closed form: planar DOF 1, Gruebler 3(2N - 3N - 1) + 3N = -3, redundant 4; spatial DOF 1,\n"
      "Gruebler -3N - 6, redundant 3N + 7.";
  m.links.reserve(2 * units);
  m.connections.reserve(3 * units);
  for (int j = 0; j < units; ++j) {
    m.links.push_back(link(bar(j, 'a'), {place(j, a1), place(j, Eigen::Vector2d::Zero()), place(j, a2)}));
    m.links.push_back(link(bar(j, 'b'), {place(j, b1), place(j, Eigen::Vector2d::Zero()), place(j, b2)}));
  }
  for (int j = 0; j < units; ++j) {
    const int next = (j + 1) % units;
    m.connections.push_back(
        makeRevolute(indexed("kink_", j), bar(j, 'a'), bar(j, 'b'), place(j, Eigen::Vector2d::Zero()), z));
    m.connections.push_back(
        makeRevolute(indexed("pin_ab_", j), bar(j, 'a'), bar(next, 'b'), place(j, a2), z));
    m.connections.push_back(
        makeRevolute(indexed("pin_ba_", j), bar(j, 'b'), bar(next, 'a'), place(j, b2), z));
  }
  m.visualRadius = 0.015;
  m.expectations = expectHobermanRing(units);
  return m;
}

// ---------------------------------------------------------------------------------------------------------
std::vector<FamilyExpectation> expectDoor(int hinges) {
  return {expectation("spatial", 1, 6 - 5 * hinges), expectation("planar", 1, 3 - 2 * hinges)};
}

MechanismDescription makeDoor(int hinges) {
  const double doorHeight = 2.0;
  const double doorWidth = 0.9;
  const double opening = 40 * kDeg;
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d across(std::cos(opening), std::sin(opening), 0.0);
  auto hingePoint = [&](int k) {
    // Hinges spread evenly over the door's height, 0.2 m from either end.
    const double t = hinges == 1 ? 0.5 : static_cast<double>(k) / (hinges - 1);
    return Eigen::Vector3d(0.0, 0.0, 0.2 + t * (doorHeight - 0.4));
  };

  MechanismDescription m;
  m.name = hinges == 3 ? "door" : "door_" + std::to_string(hinges);
  m.comment =
      "Door (0.9 m x 2 m) on " + std::to_string(hinges) +
      " coaxial hinges along the world z axis, opened 40 deg; hinge_1 is the tree revolute, the others\n"
      "are loop revolutes on the same line. Every revolute axis is parallel (auto mode picks planar).\n"
      "Closed form (K hinges): spatial DOF 1, Gruebler 6(2 - K - 1) + K = 6 - 5K, redundant 5K - 5;\n"
      "planar DOF 1, Gruebler 3 - 2K, redundant 2K - 2.";
  m.links.push_back(link("ground", {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, doorHeight),
                                    Eigen::Vector3d(0, -0.1, doorHeight)}));
  m.links.push_back(
      link("door", {Eigen::Vector3d(0, 0, 0.05), Eigen::Vector3d(0, 0, doorHeight - 0.05),
                    doorWidth * across + Eigen::Vector3d(0, 0, doorHeight - 0.05),
                    doorWidth * across + Eigen::Vector3d(0, 0, 0.05), Eigen::Vector3d(0, 0, 0.05)}));
  for (int k = 0; k < hinges; ++k) {
    m.connections.push_back(makeRevolute(indexed("hinge_", k + 1), "ground", "door", hingePoint(k), z));
  }
  m.visualRadius = 0.02;
  m.expectations = expectDoor(hinges);
  return m;
}

// ---------------------------------------------------------------------------------------------------------
std::vector<FamilyExpectation> expectParallelogramGrid(int rows, int columns) {
  const int r = rows;
  const int c = columns;
  return {expectation("planar", 1, r + c + 1 - 2 * r * c), expectation("spatial", 1, r + c + 1 - 5 * r * c)};
}

MechanismDescription makeParallelogramGrid(int rows, int columns) {
  const Eigen::Vector3d e1(0.5, 0.0, 0.0);
  const double shear = 70 * kDeg;
  const Eigen::Vector3d e2 = 0.4 * Eigen::Vector3d(std::cos(shear), std::sin(shear), 0.0);
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  auto node = [&](int i, int j) { return Eigen::Vector3d(j * e1 + i * e2); };

  MechanismDescription m;
  m.name = "parallelogram_grid_" + std::to_string(rows) + "x" + std::to_string(columns);
  m.comment =
      "Planar grid of " + std::to_string(rows) + " x " + std::to_string(columns) +
      " congruent parallelogram cells (sides 0.5 m along x and 0.4 m at 70 deg), x-y plane, axes along z,\n"
      "made of continuous bars: row_i (i = 0..R, row_0 is the ground) and col_j (j = 0..C), pinned where\n"
      "they cross (pin_i_j). Row bars are rigid and every cell a parallelogram, so all row bars stay\n"
      "parallel to the ground and all column bars parallel to each other: the shear angle is the one\n"
      "freedom. Links R + C + 2, joints (R+1)(C+1).\n"
      "Closed form: planar DOF 1, Gruebler R + C + 1 - 2RC, redundant 2RC - R - C;\n"
      "spatial DOF 1, Gruebler R + C + 1 - 5RC, redundant 5RC - R - C.";
  for (int i = 0; i <= rows; ++i) {
    m.links.push_back(link(indexed("row_", i), {node(i, 0), node(i, columns)}));
  }
  for (int j = 0; j <= columns; ++j) {
    m.links.push_back(link(indexed("col_", j), {node(0, j), node(rows, j)}));
  }
  m.links[0].name = "row_0";
  for (int i = 0; i <= rows; ++i) {
    for (int j = 0; j <= columns; ++j) {
      m.connections.push_back(makeRevolute("pin_" + std::to_string(i) + "_" + std::to_string(j),
                                           indexed("row_", i), indexed("col_", j), node(i, j), z));
    }
  }
  m.visualRadius = 0.012;
  m.expectations = expectParallelogramGrid(rows, columns);
  return m;
}


// ---------------------------------------------------------------------------------------------------------
MechanismDescription makeSleDeployableMast(int units, double elevationDeg, double deployedDeg) {
  MechanismDescription m = makeSlePlanarMast(units, elevationDeg);
  const double w = std::cos(elevationDeg * kDeg), h = std::sin(elevationDeg * kDeg);
  const double taut = std::sin(deployedDeg * kDeg);
  char angles[120];
  std::snprintf(angles, sizeof(angles), "%g deg (deployed at %g deg)", elevationDeg, deployedDeg);
  m.name = "sle_deployable_" + std::to_string(units);
  m.comment =
      "Deployable planar scissor (SLE) mast of " + std::to_string(units) +
      " units (the lecture's stacked SLE mast), written at elevation " + angles +
      ".\nBars 1 m at elevation beta above the base line: unit k spans x in [0, cos beta], y in [(k-1) sin beta, k sin "
      "beta];\nbar_k_a rises from the left foot (0, (k-1)h) to the right top, bar_k_b from the right foot to the left top,"
      "\npinned at their midpoints; unit k+1's feet pinned to unit k's tops; base: bar_1_a pinned to the ground at"
      "\n(0,0), bar_1_b's foot pinned to a slider on the x axis. One freedom: beta (0 folded flat, 90 a line).\n"
      "Cables: passive_k (one per unit) from bar_k_a's foot to bar_k_b's top, the unit's left side, of length\n"
      "sin(deployed) m: slack while beta < deployed, taut at the deployed angle, which it stops. active_base:\n"
      "active, from the ground pin (0,0) to the slider's pin (cos beta, 0), written at its current length;\n"
      "shortening it pulls the slider in and raises the mast (DESIGN.md §2: ignored as the driver).\n"
      "Expected (planar): folded or partly deployed DOF 1, Gruebler 1, redundant 0, passive cables slack;\n"
      "deployed: every passive cable taut, DOF 0, Gruebler 1 - N, N - 1 states of self-stress, not prestressable\n"
      "(all passive cables resist the same motion); with the active cable locked (--lock-active-cables) N states,\n"
      "prestressable (the base cable shortens as the passive cables lengthen), first-order rigid.";
  auto bar = [](int k, char side) { return "bar_" + std::to_string(k) + "_" + side; };
  for (int k = 1; k <= units; ++k) {
    const double y0 = (k - 1) * h;
    m.cables.push_back(CableDescription{indexed("passive_", k), bar(k, 'a'), Eigen::Vector3d(0, y0, 0), bar(k, 'b'),
                                        Eigen::Vector3d(0, y0 + h, 0), taut, false});
  }
  m.cables.push_back(
      CableDescription{"active_base", "ground", Eigen::Vector3d::Zero(), "slider", Eigen::Vector3d(w, 0, 0), w, true});
  const bool deployed = std::abs(elevationDeg - deployedDeg) < 1e-12;
  m.expectations = {expectation("planar", deployed ? 0 : 1, deployed ? 1 - units : 1)};
  return m;
}

MechanismDescription makeRingPantograph(int units, double openingDeg, double deployedOpeningDeg) {
  MechanismDescription m = makeHobermanRing(units, openingDeg);
  const HobermanRingGeometry now(units, openingDeg), deployed(units, deployedOpeningDeg);
  const double hoop = (deployed.kink(1) - deployed.kink(0)).norm();
  char angles[120];
  std::snprintf(angles, sizeof(angles), "%g deg (deployed at %g deg)", openingDeg, deployedOpeningDeg);
  m.name = "ring_pantograph_" + std::to_string(units);
  m.comment =
      "Ring pantograph of " + std::to_string(units) +
      " angulated SLE units with a cable net (after You & Pellegrino 1997), written at opening " + angles +
      ".\nThe ring is hoberman_ring's (below): it expands as the opening between the first arms of each unit"
      "\ndecreases (180 deg: collapsed to a point, 90 deg: the first arms' ends coincide across units).\n"
      "Cables: hoop_j (passive) from kink_j to kink_(j+1) (each on bar_j_a), of the chord length at the deployed"
      "\nopening: slack while the ring is smaller, taut when deployed. active_unit0 (active) from bar_0_a's end 1 to"
      "\nbar_0_b's end 1 (2 arm sin(opening/2)): shortening it closes unit 0's first arms and expands the ring.\n"
      "Expected (planar): folded DOF 1, Gruebler -3, redundant 4; deployed DOF 0, Gruebler -3 - N,\n"
      "4 + N - 1 states of self-stress, not prestressable; active cable locked: 4 + N states, prestressable.\n" +
      m.comment;
  auto bar = [](int j, char side) { return "bar_" + std::to_string(j) + "_" + side; };
  for (int j = 0; j < units; ++j) {
    const int next = (j + 1) % units;
    m.cables.push_back(CableDescription{indexed("hoop_", j), bar(j, 'a'), now.kink(j),
                                        bar(next, 'a'), now.kink(next), hoop, false});
  }
  m.cables.push_back(CableDescription{"active_unit0", bar(0, 'a'), now.place(0, now.a1), bar(0, 'b'),
                                      now.place(0, now.b1), (now.a1 - now.b1).norm(), true});
  const bool isDeployed = std::abs(openingDeg - deployedOpeningDeg) < 1e-12;
  m.expectations = {expectation("planar", isDeployed ? 0 : 1, isDeployed ? -3 - units : -3)};
  return m;
}

}  // namespace mobility_analysis
