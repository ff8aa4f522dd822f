#pragma once

#include "mobility_analysis/generators/MechanismDescription.hpp"

#include <cmath>

namespace mobility_analysis {

/**
 * @brief Grashof crank-rocker: ground 1.0, crank 0.35, coupler 1.1, rocker 0.8 [m] (s + l = 1.45 < p + q
 * = 1.8).
 *
 * Expected: planar (λ 3) DOF 1, Grübler 1, redundant 0; spatial (λ 6) DOF 1, Grübler −2, redundant 3.
 * @param[in] crankAngle Crank angle from the ground line [rad]; the rocker closes the open branch.
 */
MechanismDescription makeFourBar(double crankAngle = 60.0 * M_PI / 180.0);

/**
 * @brief PUMA 560 open chain, standard DH (a2 0.4318, a3 0.0203, d3 0.15005, d4 0.4318,
 *        α = −90°, 0, −90°, 90°, −90°, 0), posed at generic joint angles.
 *
 * Expected: spatial (λ 6) DOF 6, Grübler 6, redundant 0.
 */
MechanismDescription makePuma560();

/**
 * @brief Parallelogram (cranks crank_a, crank_b, coupler) plus a third equal, parallel crank, link `pq`.
 *
 * Expected: planar DOF 1, Grübler 0, redundant 1 (link pq redundant); spatial DOF 1, Grübler −6, redundant 7.
 */
MechanismDescription makeParallelogramCrank();

/**
 * @brief Three links pairwise joined by sliders along the sides of an equilateral triangle.
 *
 * The relative slides s1 u1 + s2 u2 + s3 u3 = 0 with u1 + u2 + u3 = 0 force s1 = s2 = s3: one freedom.
 * Expected: planar DOF 1, Grübler 0, redundant 1; spatial DOF 1, Grübler −3, redundant 4.
 */
MechanismDescription makeThreeSliders();

/**
 * @brief RPPR with both slides collinear with the line through the two ground pivots.
 *
 * The cranks cannot turn (both slide lines of the middle link would have to pass through both pivots); the
 * middle link slides freely. Expected: planar DOF 1, Grübler 1, redundant 0; spatial DOF 1, Grübler −2,
 * redundant 3.
 */
MechanismDescription makeRppr();

/**
 * @brief Bennett 4R: DH links (a, α), (b, β), (a, α), (b, β), offsets 0, sin α / a = sin β / b,
 *        a = 0.6 m, α = 40°, β = 70°, closed by loop joint `j4`.
 *
 * Standard DH A_i = Rz(θi) Tx(ai) Rx(αi); the product is the identity for
 * tan(θ1/2) tan(θ2/2) = sin((β+α)/2) / sin((β−α)/2), θ3 = −θ1, θ4 = −θ2 (checked to 1e-15).
 * Expected: spatial DOF 1, Grübler −2, redundant 3.
 * @param[in] scale Length unit factor (1000: millimetres).
 * @param[in] theta1 Input angle [rad].
 */
MechanismDescription makeBennett(double scale = 1.0, double theta1 = 100.0 * M_PI / 180.0);

/**
 * @brief Sarrus 6R: a top plate joined to the ground by two planar 3R limbs whose hinge directions
 *        (x and y) differ; the plate can only translate along z.
 *
 * Expected: spatial DOF 1, Grübler 0, redundant 1.
 * @param[in] height Height of the top hinges above the ground hinges [m], < 1.1.
 */
MechanismDescription makeSarrus(double height = 0.8);

/**
 * @brief Line-symmetric Bricard 6R: joint lines L1, L2, L3 chosen generically, L4..L6 their images under a
 *        half-turn about the z axis (L_{i+3} = H(L_i)), which makes the loop mobile (Bricard).
 *
 * Expected: spatial DOF 1, Grübler 0, redundant 1.
 */
MechanismDescription makeBricard();

/**
 * @brief Goldberg 5R from two Bennett linkages that share the link L = (b, β) and its two joints.
 *
 * Bennett I: L, A1 (a, α), B1 (b, β), C1 (a, α); Bennett II: L, A2 (c, γ), B2 (b, β), C2 (c, γ) with
 * sin α / a = sin β / b = sin γ / c (a 0.6, α 40°, β 70°, γ 55°). C1 and C2 are fused (the ground, at a fixed
 * angle δ about joint 1), L is removed, and A1, A2 keep the revolute about L's second joint: every
 * configuration of the two Bennetts is one of the 5R. Expected: spatial DOF 1, Grübler −1, redundant 2.
 */
MechanismDescription makeGoldberg(double theta1 = 100.0 * M_PI / 180.0);

/**
 * @brief RSSR: two ground revolutes (axes z through the origin and x through (0, 1, 0.35): skew), a rod
 *        between two spherical loop joints, hanging from the ground by `floating`.
 *
 * Expected: spatial DOF 2 (crank motion + rod spin), Grübler 2, redundant 0.
 */
MechanismDescription makeRssr();

/// Change-point four-bar drawn flat (all pins collinear): planar DOF 2, finite 1, Grübler 1, 1 redundant.
MechanismDescription makeFlattenedFourBar();

/// Parallelogram four-bar at its bifurcation pose (flat): planar DOF 2, finite 1, Grübler 1, 1 redundant.
MechanismDescription makeParallelogramBifurcation();

/// Two equal bars collinear between two ground pins: planar DOF 1, finite 0, Grübler 0, 1 redundant.
MechanismDescription makeCollinearBars();

/// Stewart–Gough 6-SPS: spatial DOF 12 (passive 6, output 6), Grübler 12.
MechanismDescription makeStewart6Sps();

/// Delta robot with ball-jointed parallelogram rods: spatial DOF 9 (passive 6, output 3), Grübler 9.
MechanismDescription makeDeltaRobot();
/**
 * @brief Peaucellier–Lipkin straight-line linkage: ground pivots O and A with |OA| = crank |AP| = r, arms
 *        OB = OD = L, rhombus PB = BQ = QD = DP = s (r = 1, L = 3, s = 1.5 [m]).
 *
 * O, P, Q stay collinear with |OP| |OQ| = L^2 - s^2 (inversion about O), and P runs on a circle through O, so
 * Q runs on the line x = (L^2 - s^2) / (2 r) = 3.375. Expected: planar DOF 1, Grübler 1, redundant 0.
 * @param[in] crankAngle Angle of AP from the ground line [rad], |angle| < 82.8 deg (|OP| >= L - s).
 */
MechanismDescription makePeaucellier(double crankAngle = 30.0 * M_PI / 180.0);

}  // namespace mobility_analysis
