#pragma once

#include "mobility_analysis/generators/MechanismDescription.hpp"

#include <vector>

namespace mobility_analysis {

/// Shape of a generated chain.
enum class ChainShape {
  Straight,  ///< Every joint on the x axis, 0.1 m apart.
  Zigzag     ///< Joints alternate between y = 0 and y = 0.05 m, 0.1 m apart in x.
};

/// Document order of a generated chain.
enum class ChainOrder {
  RootFirst,  ///< Links and tree joints from the ground outwards.
  LeafFirst   ///< Links and tree joints from the free end towards the ground.
};

/**
 * @brief Closed-form expectations of an open planar revolute chain of @p links moving links.
 *
 * Links N + 1 (with the ground), joints N revolute, no loop: planar (λ 3) DOF N, Grübler 3(N + 1 − N − 1) + N
 * = N, redundant 0; spatial (λ 6) DOF N, Grübler N, redundant 0.
 */
std::vector<FamilyExpectation> expectChain(int links);

/**
 * @brief Open serial chain: `ground`, `link_1` … `link_N`, revolute `joint_i` (about z) between link_(i−1)
 *        and link_i, every joint 0.1 m further along x (zig-zag: alternately 0.05 m off the axis).
 * @param[in] links N ≥ 1.
 * @param[in] shape Straight or zig-zag.
 * @param[in] order Root-first or leaf-first document order (links and tree joints).
 * @note Expectations: see expectChain().
 */
MechanismDescription makeChain(int links, ChainShape shape = ChainShape::Straight,
                               ChainOrder order = ChainOrder::RootFirst);

/**
 * @brief Closed-form expectations of a star of @p arms arms on one hub (makeStar()).
 *
 * Links N + 2 (with the ground), joints N + 1 revolute, no loop: planar (λ 3) DOF N + 1, Grübler
 * 3(N + 2 − (N + 1) − 1) + N + 1 = N + 1, redundant 0; spatial (λ 6) the same.
 */
std::vector<FamilyExpectation> expectStar(int arms);

/**
 * @brief A star: `hub` on revolute `hub_joint` (about z) at the origin of `ground`, and `arm_1` … `arm_N`
 *        each on its own revolute `joint_i` (about z) on the hub, at angle 2π i / N on a circle whose
 *        circumference gives 0.1 m a joint, each arm 0.1 m long pointing outwards. One link carries every
 *        joint: the tree whose hub's equations must not couple its joints (issue 13: a chain or a star
 *        costs O(N)).
 * @param[in] arms N ≥ 1.
 * @note Expectations: see expectStar().
 */
MechanismDescription makeStar(int arms);

/**
 * @brief Closed-form expectations of a single ring of @p links links (N ≥ 3), one of them the ground.
 *
 * Links N, joints N revolute, one loop: planar (λ 3) DOF N − 3, Grübler 3(N − N − 1) + N = N − 3,
 * redundant 0; spatial (λ 6) DOF N − 3 (the planar motions; every axis is parallel), Grübler
 * 6(N − N − 1) + N = N − 6, redundant 3 (the loop's three out-of-plane equations).
 */
std::vector<FamilyExpectation> expectRing(int links);

/**
 * @brief One loop of N links on a circle: link_i is the chord from vertex i to vertex i+1 of a regular N-gon
 *        with 0.1 m sides (x–y plane), revolute joint_i about z at vertex i+1 joins link_i and link_(i+1);
 *        link_0 is the ground.
 * @param[in] links N ≥ 3.
 * @note Expectations: see expectRing().
 */
MechanismDescription makeRing(int links);

/**
 * @brief Closed-form expectations of the pin-jointed square bar lattice of R × C cells (makeBarLattice()).
 *
 * As a bar framework (Bolker & Crapo 1977): nodes n = (R + 1)(C + 1), bars b = R(C + 1) + C(R + 1) =
 * 2RC + R + C, no state of self-stress (a corner node has two perpendicular bars, so both carry nothing, and
 * the zero forces propagate along every row and column), so the internal mechanisms number
 * 2n − b − 3 = R + C − 1 (one shear per row and per column, less the rigid rotation).
 * As links: b bar links (one of them the ground) and Σ(k_v − 1) = 2b − n revolute pins (k_v bars at node v):
 * planar Grübler 3(b − 1) − 2(2b − n) = 2n − b − 3 = R + C − 1 = DOF, redundant 0.
 */
std::vector<FamilyExpectation> expectBarLattice(int rows, int columns);

/**
 * @brief Pin-jointed square bar lattice of R × C square cells (0.5 m sides, x–y plane): every cell edge is a
 *        bar link (`h_i_j` from node (i, j) to (i, j+1), `v_i_j` from (i, j) to (i+1, j)); at a node where k
 *        bars meet, the first bar (h before v, lower index first) is pinned to each of the k − 1 others by a
 *        revolute about z (`pin_i_j_t`), which joins the k bars at one point without redundancy. Bar `h_0_0`
 *        is the ground.
 * @param[in] rows R ≥ 1.
 * @param[in] columns C ≥ 1.
 * @param[in] braced Also a passive cable in both diagonals of every cell, written taut (makeBracedLattice()).
 * @note Expectations: see expectBarLattice() / expectBracedLattice().
 */
MechanismDescription makeBarLattice(int rows, int columns, bool braced = false);

/**
 * @brief Closed-form expectations of the bar lattice braced by taut cables in both diagonals of every cell.
 *
 * Bolker & Crapo: a braced grid is rigid iff its bracing graph (rows and columns as vertices, one edge per
 * braced cell) is connected, which takes R + C − 1 braces; here every cell is braced, so DOF 0. The 2RC
 * cables count as distance constraints (λ 3: −1 each): Grübler R + C − 1 − 2RC, so the states of self-stress
 * (= redundant equations) number 2RC − (R + C − 1): one per cell for its second diagonal (RC), and RC − (R +
 * C − 1) first diagonals beyond the R + C − 1 that already make the grid rigid. (Maxwell: b' − 2n + 3 = s − m
 * with b' = 4RC + R + C bars, m = 0.)
 */
std::vector<FamilyExpectation> expectBracedLattice(int rows, int columns);

/**
 * @brief Closed-form expectations of the braced triangular truss mast of @p bays bays (makeTrussMast()).
 *
 * As a framework: j = 3(N + 1) nodes, b = 3(N + 1) battens + 3N longerons + 6N diagonals = 12N + 3 bars;
 * each bay with one diagonal per face is an octahedron (rigid), so m = 0, and Maxwell b − 3j + 6 = s − m
 * gives s = 3N. As links (one rigid triangle per level, the base one the ground, struts as distance
 * constraints): spatial (λ 6) Grübler 6N − 9N = −3N, DOF 0, redundant 3N.
 */
std::vector<FamilyExpectation> expectTrussMast(int bays);

/**
 * @brief Spatial truss mast of N triangular-prism bays (equilateral triangles of circumradius 0.5 m, bays
 *        0.6 m high, along z): at each level l the three nodes and their three battens are one rigid link
 *        `level_l` (level_0 is the ground; a triangle of bars is rigid and carries no self-stress, so this is
 *        the bar framework exactly, without the idle spin a bar link between two ball joints would add);
 *        per bay three longerons `long_l_c` and both diagonals of each side face `diag_l_c_a/b`, written as
 *        `distance_constraint`s (bars with ball ends). Levels above the ground hang by floating joints.
 * @param[in] bays N ≥ 1.
 * @note Expectations: see expectTrussMast(). Analyse with `--mode spatial` (there is no joint axis for the
 *       automatic choice to go by).
 */
MechanismDescription makeTrussMast(int bays);

/**
 * @brief The ring pantograph with a cable net (after You & Pellegrino 1997): makeHobermanRing() at
 *        @p openingDeg, N ≥ 3, with 2N passive cables, written at their lengths at @p deployedOpeningDeg, and
 *        the active cable of makeRingPantograph(): hoop cables `hoop_j` from kink_j to kink_(j+1) and
 * diagonal cables `diagonal_j` from kink_j to pin_ab_(j+1) (the outer pin of the next unit). Both lengthen
 *        monotonically as the ring deploys (opening 150 → 60 deg), so they are slack folded and taut
 * deployed. The hoop cables alone stop the one motion at first order (their length is not stationary there;
 * for N = 3 the diagonals' is), so the counts hold for every N ≥ 3.
 * @note Expectations (planar): folded DOF 1, Grübler −3, redundant 4 (the bare ring's); deployed DOF 0,
 *       Grübler −3 − 2N, redundant = states of self-stress 2N + 3 (the ring's 4, plus 2N − 1 cables beyond
 * the first, which stops the one motion). The active cable is ignored (DESIGN.md §2).
 */
MechanismDescription makeRingPantographNet(int units, double openingDeg, double deployedOpeningDeg = 60.0);

}  // namespace mobility_analysis
