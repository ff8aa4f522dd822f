#pragma once

#include "mobility_analysis/generators/MechanismDescription.hpp"

#include <vector>

namespace mobility_analysis {

/**
 * @brief Closed-form expectations of the planar scissor (SLE) mast with @p units units.
 *
 * Links 2N + 2 (ground, slider, 2N bars), joints 3N + 1 (ground pin, slide, slider pin, N centre pivots,
 * 2(N − 1) end pins). planar (λ 3): DOF 1, Grübler 3(2N+2 − 3N−1 − 1) + 3N+1 = 1, redundant 0;
 * spatial (λ 6): DOF 1, Grübler 1 − 3N, redundant 3N.
 */
std::vector<FamilyExpectation> expectSlePlanarMast(int units);

/**
 * @brief Planar scissor (SLE) mast in the x–y plane: N units of two crossing bars (length 1 m, 50° to the
 *        horizontal, pivoted at their midpoints), bar 1a pinned to the ground, bar 1b's foot pinned to a
 * slider block that slides along x on the ground.
 * @param[in] units N ≥ 1.
 * @note Expectations: see expectSlePlanarMast().
 */
MechanismDescription makeSlePlanarMast(int units, double elevationDeg = 50.0);

/**
 * @brief Closed-form expectations of the scissor mast analysed in space (makeSleSpatialMast()).
 *
 * Links 2N + 2, joints 3N + 1 revolute/prismatic: spatial (λ 6) DOF 1, Grübler 1 − 3N, redundant 3N.
 */
std::vector<FamilyExpectation> expectSleSpatialMast(int units);

/**
 * @brief The scissor (SLE) mast on a pin + slider base of makeSlePlanarMast(), named and described for analysis
 *        in space (`--mode spatial`; auto mode picks the plane, every hinge axis being parallel).
 *
 * What a real mast is: hinges in three-dimensional space, each unit's scissor loop over-constrained by the three
 * out-of-plane equations of a planar loop, yet the mast deploys with one freedom.
 * @param[in] units N ≥ 1.
 * @note Expectations: see expectSleSpatialMast().
 */
MechanismDescription makeSleSpatialMast(int units);

/**
 * @brief Closed-form expectations of the triangular scissor mast (makeSleTriangularMast()).
 *
 * Links 6N (6 bars per unit, one of them the ground), joints 12N − 3: 3N centre revolutes and 9N − 3
 * spherical joints (6(N − 1) face pins, 3(N + 1) corner joints); Σ F = 30N − 9.
 * spatial (λ 6): DOF 1, Grübler 6(6N − (12N − 3) − 1) + 30N − 9 = 3 − 6N, redundant 6N − 2.
 */
std::vector<FamilyExpectation> expectSleTriangularMast(int units);

/**
 * @brief Spatial scissor mast: a right prism on an equilateral triangle whose three faces are scissor chains
 *        (bars 1 m at 50° to the horizontal, centre revolutes about the face normal); all other joints are
 *        spherical: face pins between consecutive units and, at every level, corner joints between the two
 *        faces meeting there. Bar `bar_1_0_a` is the ground; bars held only by spherical joints hang by
 *        `floating` joints.
 *
 * Why DOF 1: each unit's four ends form a rectangle with diagonal 1 m; a face's rectangles share horizontal
 * edges (one width per face), shared vertical edges force equal heights, so every level is an equilateral
 * triangle of side w, and since opposite rectangle sides are parallel and equal each level is the previous
 * one translated by h along its normal: a right prism with w² + h² = 1 as the only parameter. Per unit 6
 * links and 12 joints (3 R + 9 S, 42 joint equations); verified numerically (Jacobian nullity 1, finite
 * motion).
 * @param[in] units N ≥ 1.
 * @note Expectations: see expectSleTriangularMast().
 */
MechanismDescription makeSleTriangularMast(int units);

/**
 * @brief Closed-form expectations of the Hoberman-type ring with @p units angulated units (N ≥ 3).
 *
 * Links 2N, joints 3N revolute (N kinks + 2N end pins).
 * planar (λ 3): DOF 1, Grübler 3(2N − 3N − 1) + 3N = −3, redundant 4;
 * spatial (λ 6): DOF 1, Grübler −3N − 6, redundant 3N + 7.
 */
std::vector<FamilyExpectation> expectHobermanRing(int units);

/**
 * @brief Hoberman-type ring: N units of two identical angulated bars (arms 0.5 m, both bent by κ = 2π/N the
 *        same way) pinned at their kinks; unit j's bar a end 2 is pinned to unit j+1's bar b end 1 and vice
 *        versa; bar `bar_0_a` is the ground.
 *
 * Why it moves: with arms u1, v1 at the kink and u2 = −Rot(κ) u1, v2 = −Rot(κ) v1, A2 − B2 = Rot(κ)(B1 − A1)
 * for every opening angle, so the rotation by κ about a point O maps unit j onto unit j+1 and the ring closes
 * for every opening: one freedom.
 * @param[in] units N ≥ 3.
 * @note Expectations: see expectHobermanRing().
 */
MechanismDescription makeHobermanRing(int units, double openingDeg = 70.0);

/**
 * @brief Closed-form expectations of a door on @p hinges coaxial hinges.
 *
 * Links 2, joints K revolute. spatial (λ 6): DOF 1, Grübler 6(2 − K − 1) + K = 6 − 5K, redundant 5K − 5;
 * planar (λ 3): DOF 1, Grübler 3 − 2K, redundant 2K − 2.
 */
std::vector<FamilyExpectation> expectDoor(int hinges);

/**
 * @brief A door (link `door`) on K coaxial hinges along the world z axis, opened 40°: hinge_1 is the tree
 *        revolute, the others are loop revolutes.
 * @param[in] hinges K ≥ 1.
 * @note Expectations: see expectDoor().
 */
MechanismDescription makeDoor(int hinges);

/**
 * @brief Closed-form expectations of an R × C parallelogram grid of continuous bars.
 *
 * Links R + C + 2 (R + 1 row bars incl. the ground row, C + 1 column bars), joints (R + 1)(C + 1) pins.
 * planar (λ 3): DOF 1, Grübler R + C + 1 − 2RC, redundant 2RC − R − C;
 * spatial (λ 6): DOF 1, Grübler R + C + 1 − 5RC, redundant 5RC − R − C.
 */
std::vector<FamilyExpectation> expectParallelogramGrid(int rows, int columns);

/**
 * @brief Planar grid of R × C congruent parallelogram cells made of continuous bars: R + 1 row bars (row 0 is
 *        the ground) and C + 1 column bars, pinned where they cross.
 *
 * Why DOF 1: every row bar is rigid and every cell a parallelogram, so all row bars stay parallel to the
 * ground and all column bars parallel to each other; the common column angle (the shear) is the only freedom.
 * (With a separate bar per cell edge the count would be R + C − 1 instead.)
 * @param[in] rows R ≥ 1.
 * @param[in] columns C ≥ 1.
 * @note Expectations: see expectParallelogramGrid().
 */
MechanismDescription makeParallelogramGrid(int rows, int columns);

/**
 * @brief The lecture's deployable SLE mast: makeSlePlanarMast() at elevation @p elevationDeg with one passive
 * cable per unit (its left side, taut at @p deployedDeg) and an active cable across the base (pin to slider).
 * @note Expectations (planar): DOF 1, Gruebler 1 below the deployed angle; DOF 0, Gruebler 1 - N at it.
 */
MechanismDescription makeSleDeployableMast(int units, double elevationDeg, double deployedDeg = 45.0);

/**
 * @brief A ring pantograph with a cable net: makeHobermanRing() at @p openingDeg with passive hoop cables
 * between consecutive kinks (taut at @p deployedOpeningDeg) and an active cable across unit 0's first arms.
 * @note Expectations (planar): DOF 1, Gruebler -3 before deployment; DOF 0, Gruebler -3 - N deployed.
 */
MechanismDescription makeRingPantograph(int units, double openingDeg, double deployedOpeningDeg = 60.0);

}  // namespace mobility_analysis
