#include "mobility_analysis/generators/ScalingFamilies.hpp"

#include "mobility_analysis/generators/ParametricFamilies.hpp"

#include "GeneratorParts.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace mobility_analysis {

namespace {

using generator_parts::expectation;
using generator_parts::HobermanRingGeometry;
using generator_parts::kDeg;
using generator_parts::link;

std::string ij(const char* prefix, int i, int j) {
  return prefix + std::to_string(i) + "_" + std::to_string(j);
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
std::vector<FamilyExpectation> expectChain(int links) {
  return {expectation("planar", links, links), expectation("spatial", links, links)};
}

MechanismDescription makeChain(int links, ChainShape shape, ChainOrder order) {
  const bool zigzag = shape == ChainShape::Zigzag;
  const bool leafFirst = order == ChainOrder::LeafFirst;
  auto point = [&](int i) { return Eigen::Vector3d(0.1 * i, zigzag && (i % 2 == 1) ? 0.05 : 0.0, 0.0); };
  auto name = [](int i) { return i == 0 ? std::string("ground") : "link_" + std::to_string(i); };

  MechanismDescription m;
  m.name = std::string(zigzag ? "zigzag" : "straight") + "_chain_" + std::to_string(links);
  m.comment = "Open planar chain of " + std::to_string(links) + " links, " +
              (zigzag ? "zig-zag" : "straight") + ", written " + (leafFirst ? "leaf-first" : "root-first") +
              ": joint_i (revolute about z) at (0.1 (i-1), " + (zigzag ? "0 or 0.05 alternately" : "0") +
              ") joins link_(i-1) (link_0 = ground) and link_i.\n"
              "No loop, nothing redundant: every tree equation is independent by construction.\n"
              "Closed form: planar DOF N, Gruebler 3(N+1 - N - 1) + N = N, redundant 0; spatial the same.";
  m.links.reserve(links + 1);
  m.connections.reserve(links);
  m.links.push_back(link("ground", {point(0) - Eigen::Vector3d(0.05, 0, 0), point(0)}));
  for (int k = 1; k <= links; ++k) {
    const int i = leafFirst ? links + 1 - k : k;
    m.links.push_back(link(name(i), {point(i - 1), point(i)}));
  }
  for (int k = 1; k <= links; ++k) {
    const int i = leafFirst ? links + 1 - k : k;
    m.connections.push_back(makeRevolute("joint_" + std::to_string(i), name(i - 1), name(i), point(i - 1),
                                         Eigen::Vector3d::UnitZ()));
  }
  m.treeJointsLeafFirst = leafFirst;
  m.visualRadius = 0.01;
  m.expectations = expectChain(links);
  return m;
}

// ---------------------------------------------------------------------------------------------------------
std::vector<FamilyExpectation> expectStar(int arms) {
  return {expectation("planar", arms + 1, arms + 1), expectation("spatial", arms + 1, arms + 1)};
}

MechanismDescription makeStar(int arms) {
  const double radius = std::max(0.1, 0.1 * arms / (2.0 * M_PI));
  auto direction = [&](int i) {
    const double angle = 2.0 * M_PI * i / arms;
    return Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
  };
  MechanismDescription m;
  m.name = "star_" + std::to_string(arms);
  m.comment =
      "A hub on a revolute at the ground's origin carrying " + std::to_string(arms) +
      " arms: joint_i (revolute about z) at angle 2 pi i / N on a circle of radius " +
      std::to_string(radius) +
      " m joins the hub and arm_i, 0.1 m long, pointing outwards.\n"
      "No loop, nothing redundant: every tree equation is independent by construction.\n"
      "Closed form: planar DOF N+1, Gruebler 3(N+2 - (N+1) - 1) + N+1 = N+1, redundant 0; spatial the "
      "same.";
  m.links.reserve(arms + 2);
  m.connections.reserve(arms + 1);
  m.links.push_back(link("ground", {Eigen::Vector3d(-0.05, 0, 0), Eigen::Vector3d::Zero()}));
  std::vector<Eigen::Vector3d> hubPoints{Eigen::Vector3d::Zero()};
  for (int i = 1; i <= arms; ++i)
    hubPoints.push_back(radius * direction(i));
  m.links.push_back(link("hub", hubPoints));
  for (int i = 1; i <= arms; ++i) {
    m.links.push_back(
        link("arm_" + std::to_string(i), {radius * direction(i), (radius + 0.1) * direction(i)}));
  }
  m.connections.push_back(
      makeRevolute("hub_joint", "ground", "hub", Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()));
  for (int i = 1; i <= arms; ++i) {
    m.connections.push_back(makeRevolute("joint_" + std::to_string(i), "hub", "arm_" + std::to_string(i),
                                         radius * direction(i), Eigen::Vector3d::UnitZ()));
  }
  m.visualRadius = 0.01;
  m.expectations = expectStar(arms);
  return m;
}

// ---------------------------------------------------------------------------------------------------------
std::vector<FamilyExpectation> expectRing(int links) {
  return {expectation("planar", links - 3, links - 3), expectation("spatial", links - 3, links - 6)};
}

MechanismDescription makeRing(int links) {
  const double side = 0.1;
  const double radius = side / (2.0 * std::sin(M_PI / links));
  auto vertex = [&](int i) {
    const double angle = 2.0 * M_PI * (i % links) / links;
    return Eigen::Vector3d(radius * std::cos(angle), radius * std::sin(angle), 0.0);
  };
  auto name = [](int i) { return "link_" + std::to_string(i); };

  MechanismDescription m;
  m.name = "ring_" + std::to_string(links);
  m.comment =
      "One loop of " + std::to_string(links) +
      " links on a circle: link_i is the side from vertex i to vertex i+1 of a regular polygon with\n"
      "0.1 m sides in the x-y plane, joint_i (revolute about z) at vertex i+1 joins link_i and link_(i+1);\n"
      "link_0 is the ground.\n"
      "Closed form: planar DOF N - 3, Gruebler 3(N - N - 1) + N = N - 3, redundant 0;\n"
      "spatial DOF N - 3, Gruebler 6(N - N - 1) + N = N - 6, redundant 3 (the loop's out-of-plane "
      "equations).";
  m.links.reserve(links);
  m.connections.reserve(links);
  for (int i = 0; i < links; ++i) {
    m.links.push_back(link(name(i), {vertex(i), vertex(i + 1)}));
  }
  for (int i = 0; i < links; ++i) {
    m.connections.push_back(makeRevolute("joint_" + std::to_string(i), name(i), name((i + 1) % links),
                                         vertex(i + 1), Eigen::Vector3d::UnitZ()));
  }
  m.visualRadius = 0.01;
  m.expectations = expectRing(links);
  return m;
}

// ---------------------------------------------------------------------------------------------------------
std::vector<FamilyExpectation> expectBarLattice(int rows, int columns) {
  return {expectation("planar", rows + columns - 1, rows + columns - 1)};
}

std::vector<FamilyExpectation> expectBracedLattice(int rows, int columns) {
  return {expectation("planar", 0, rows + columns - 1 - 2 * rows * columns)};
}

MechanismDescription makeBarLattice(int rows, int columns, bool braced) {
  const double cell = 0.5;
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  auto node = [&](int i, int j) { return Eigen::Vector3d(j * cell, i * cell, 0.0); };
  const std::string size = std::to_string(rows) + " x " + std::to_string(columns);

  MechanismDescription m;
  m.name = std::string(braced ? "braced_lattice_" : "bar_lattice_") + std::to_string(rows) + "x" +
           std::to_string(columns);
  m.comment =
      "Pin-jointed square bar lattice of " + size +
      " cells (0.5 m), x-y plane, axes along z. Every cell edge is a bar link:\n"
      "h_i_j from node (i, j) to (i, j+1), v_i_j from node (i, j) to (i+1, j); node (i, j) is at (0.5 j, 0.5 "
      "i).\n"
      "At a node where k bars meet, the first of them (h before v) is pinned to each of the k - 1 others\n"
      "(pin_i_j_t): the k bars share one point, nothing redundant. h_0_0 is the ground.\n"
      "As a bar framework: n = (R+1)(C+1) nodes, b = 2RC + R + C bars, no self-stress, so\n"
      "2n - b - 3 = R + C - 1 internal mechanisms (Bolker & Crapo 1977: one shear per row and column).\n"
      "As links: b links, 2b - n pins: planar Gruebler 3(b - 1) - 2(2b - n) = R + C - 1.\n";
  if (braced) {
    m.comment +=
        "Braced: a passive cable in both diagonals of every cell (diag_i_j_a from node (i, j) to (i+1, "
        "j+1),\n"
        "diag_i_j_b from (i, j+1) to (i+1, j)), written taut: rigid (the bracing graph is complete), DOF 0;\n"
        "the 2RC taut cables count as distance constraints: Gruebler R + C - 1 - 2RC, states of self-stress\n"
        "2RC - (R + C - 1) (each cell's second diagonal, and the first diagonals beyond the R + C - 1 that\n"
        "make the grid rigid).\n"
        "Closed form: planar DOF 0, Gruebler R + C - 1 - 2RC, redundant 2RC - R - C + 1.";
  } else {
    m.comment += "Closed form: planar DOF R + C - 1, Gruebler R + C - 1, redundant 0.";
  }
  const int bars = 2 * rows * columns + rows + columns;
  const int nodes = (rows + 1) * (columns + 1);
  m.links.reserve(bars);
  m.connections.reserve(2 * bars - nodes);
  // Links row by row: the horizontal bars of row i, then the vertical bars above them.
  for (int i = 0; i <= rows; ++i) {
    for (int j = 0; j < columns; ++j) {
      m.links.push_back(link(ij("h_", i, j), {node(i, j), node(i, j + 1)}));
    }
    if (i < rows) {
      for (int j = 0; j <= columns; ++j) {
        m.links.push_back(link(ij("v_", i, j), {node(i, j), node(i + 1, j)}));
      }
    }
  }
  for (int i = 0; i <= rows; ++i) {
    for (int j = 0; j <= columns; ++j) {
      std::vector<std::string> bars;  // at node (i, j): h left, h right, v below, v above
      if (j > 0)
        bars.push_back(ij("h_", i, j - 1));
      if (j < columns)
        bars.push_back(ij("h_", i, j));
      if (i > 0)
        bars.push_back(ij("v_", i - 1, j));
      if (i < rows)
        bars.push_back(ij("v_", i, j));
      for (size_t t = 1; t < bars.size(); ++t) {
        m.connections.push_back(
            makeRevolute(ij("pin_", i, j) + "_" + std::to_string(t), bars[0], bars[t], node(i, j), z));
      }
    }
  }
  if (braced) {
    m.cables.reserve(2 * rows * columns);
    const double diagonal = cell * std::sqrt(2.0);
    for (int i = 0; i < rows; ++i) {
      for (int j = 0; j < columns; ++j) {
        m.cables.push_back(CableDescription{ij("diag_", i, j) + "_a", ij("h_", i, j), node(i, j),
                                            ij("h_", i + 1, j), node(i + 1, j + 1), diagonal, false});
        m.cables.push_back(CableDescription{ij("diag_", i, j) + "_b", ij("h_", i, j), node(i, j + 1),
                                            ij("h_", i + 1, j), node(i + 1, j), diagonal, false});
      }
    }
  }
  m.visualRadius = 0.01;
  m.expectations = braced ? expectBracedLattice(rows, columns) : expectBarLattice(rows, columns);
  return m;
}

// ---------------------------------------------------------------------------------------------------------
std::vector<FamilyExpectation> expectTrussMast(int bays) {
  return {expectation("spatial", 0, -3 * bays)};
}

MechanismDescription makeTrussMast(int bays) {
  const double circumradius = 0.5;
  const double height = 0.6;
  auto node = [&](int level, int c) {
    const double angle = 90 * kDeg + 120 * kDeg * (c % 3);
    return Eigen::Vector3d(circumradius * std::cos(angle), circumradius * std::sin(angle), level * height);
  };
  auto level = [](int l) { return l == 0 ? std::string("ground") : "level_" + std::to_string(l); };

  MechanismDescription m;
  m.name = "truss_mast_" + std::to_string(bays);
  m.comment =
      "Spatial truss mast of " + std::to_string(bays) +
      " triangular-prism bays along z (equilateral triangles of circumradius 0.5 m, bays 0.6 m high).\n"
      "Level l's three nodes and three battens are one rigid link level_l (level 0 is the ground): a "
      "triangle\n"
      "of bars is rigid and carries no self-stress, so this is the bar framework exactly (a bar link "
      "between\n"
      "two ball joints would add an idle spin per bar). Bay l (levels l-1 to l): longerons long_l_c from "
      "node\n"
      "c to node c, both diagonals of every side face, diag_l_c_a from node c (below) to node c+1 (above) "
      "and\n"
      "diag_l_c_b from node c+1 (below) to node c (above), all distance_constraints (bars with ball ends).\n"
      "With one diagonal per face a bay is an octahedron (rigid); the second diagonals add 3 self-stresses.\n"
      "Framework: j = 3(N+1) nodes, b = 12N + 3 bars, Maxwell b - 3j + 6 = s - m = 3N, m = 0.\n"
      "Closed form (mode spatial): DOF 0, Gruebler 6N - 9N = -3N, redundant 3N.";
  m.links.reserve(bays + 1);
  m.connections.reserve(9 * bays);
  for (int l = 0; l <= bays; ++l) {
    m.links.push_back(link(level(l), {node(l, 0), node(l, 1), node(l, 2), node(l, 0)}));
  }
  for (int l = 1; l <= bays; ++l) {
    for (int c = 0; c < 3; ++c) {
      const std::string tag = ij("", l, c);
      m.connections.push_back(
          makeDistance("long_" + tag, level(l - 1), node(l - 1, c), level(l), node(l, c)));
      m.connections.push_back(
          makeDistance("diag_" + tag + "_a", level(l - 1), node(l - 1, c), level(l), node(l, c + 1)));
      m.connections.push_back(
          makeDistance("diag_" + tag + "_b", level(l - 1), node(l - 1, c + 1), level(l), node(l, c)));
    }
  }
  m.visualRadius = 0.01;
  m.expectations = expectTrussMast(bays);
  return m;
}

// ---------------------------------------------------------------------------------------------------------
MechanismDescription makeRingPantographNet(int units, double openingDeg, double deployedOpeningDeg) {
  MechanismDescription m = makeHobermanRing(units, openingDeg);
  const HobermanRingGeometry now(units, openingDeg), deployed(units, deployedOpeningDeg);
  const double hoop = (deployed.kink(1) - deployed.kink(0)).norm();
  const double diagonal = (deployed.place(1, deployed.a2) - deployed.kink(0)).norm();
  char angles[120];
  std::snprintf(angles, sizeof(angles), "%g deg (deployed at %g deg)", openingDeg, deployedOpeningDeg);
  m.name = "ring_pantograph_net_" + std::to_string(units);
  m.comment =
      "Ring pantograph of " + std::to_string(units) +
      " angulated SLE units with a cable net (after You & Pellegrino 1997), written at opening " + angles +
      ".\nThe ring is hoberman_ring's (below): it expands as the opening between the first arms of each unit"
      "\ndecreases. Cable net, 2N passive cables at their deployed lengths: hoop_j from kink_j to kink_(j+1)"
      "\nand diagonal_j from kink_j to pin_ab_(j+1) (the outer pin of the next unit); both lengthen"
      "\nmonotonically as the ring deploys, so they are slack folded and taut deployed. active_unit0 (active)"
      "\nfrom bar_0_a's end 1 to bar_0_b's end 1: shortening it closes unit 0's first arms and deploys the "
      "ring.\n"
      "Expected (planar): folded DOF 1, Gruebler -3, redundant 4; deployed DOF 0, Gruebler -3 - 2N,\n"
      "2N + 3 states of self-stress (the bare ring's 4, and 2N - 1 cables beyond the first).\n" +
      m.comment;
  auto bar = [](int j, char side) { return "bar_" + std::to_string(j) + "_" + side; };
  m.cables.reserve(2 * units + 1);
  for (int j = 0; j < units; ++j) {
    const int next = (j + 1) % units;
    m.cables.push_back(CableDescription{"hoop_" + std::to_string(j), bar(j, 'a'), now.kink(j), bar(next, 'a'),
                                        now.kink(next), hoop, false});
    m.cables.push_back(CableDescription{"diagonal_" + std::to_string(j), bar(j, 'a'), now.kink(j),
                                        bar(next, 'a'), now.place(next, now.a2), diagonal, false});
  }
  m.cables.push_back(CableDescription{"active_unit0", bar(0, 'a'), now.place(0, now.a1), bar(0, 'b'),
                                      now.place(0, now.b1), (now.a1 - now.b1).norm(), true});
  const bool isDeployed = std::abs(openingDeg - deployedOpeningDeg) < 1e-12;
  m.expectations = {expectation("planar", isDeployed ? 0 : 1, isDeployed ? -3 - 2 * units : -3)};
  return m;
}

}  // namespace mobility_analysis
