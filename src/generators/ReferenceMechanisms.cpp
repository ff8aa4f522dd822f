#include "mobility_analysis/generators/ReferenceMechanisms.hpp"

#include "GeneratorParts.hpp"

#include <array>
#include <cassert>
#include <cmath>
#include <string>

namespace mobility_analysis {

namespace {

using generator_parts::expectation;
using generator_parts::kDeg;
using generator_parts::link;

Eigen::Vector3d planar(double x, double y) {
  return {x, y, 0.0};
}

Eigen::Vector3d unitCircle(double angle) {
  return {std::cos(angle), std::sin(angle), 0.0};
}

/**
 * Intersection of the circles (c0, r0) and (c1, r1) in the x–y plane, on the left of c0 → c1 when
 * @p left, else on the right. Assumes the circles intersect (the generators choose such geometry).
 */
Eigen::Vector2d intersectCircles(const Eigen::Vector2d& c0, double r0, const Eigen::Vector2d& c1, double r1,
                                 bool left) {
  const Eigen::Vector2d d = c1 - c0;
  const double dist = d.norm();
  const double along = (r0 * r0 - r1 * r1 + dist * dist) / (2.0 * dist);
  const double across = std::sqrt(std::max(0.0, r0 * r0 - along * along));
  const Eigen::Vector2d u = d / dist;
  const Eigen::Vector2d n(-u.y(), u.x());
  return c0 + along * u + (left ? across : -across) * n;
}

/// Standard DH transform A = Rz(θ) Tz(d) Tx(a) Rx(α).
Eigen::Isometry3d dhTransform(double theta, double d, double a, double alpha) {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  transform.rotate(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()));
  transform.translate(Eigen::Vector3d(0.0, 0.0, d));
  transform.translate(Eigen::Vector3d(a, 0.0, 0.0));
  transform.rotate(Eigen::AngleAxisd(alpha, Eigen::Vector3d::UnitX()));
  return transform;
}

/**
 * Second Bennett angle for the DH links (a1, α1), (a2, α2), (a1, α1), (a2, α2):
 * tan(θ1/2) tan(θ2/2) = sin((α2+α1)/2) / sin((α2−α1)/2), θ3 = −θ1, θ4 = −θ2.
 */
double bennettSecondAngle(double alpha1, double alpha2, double theta1) {
  const double k = std::sin(0.5 * (alpha2 + alpha1)) / std::sin(0.5 * (alpha2 - alpha1));
  return 2.0 * std::atan(k / std::tan(0.5 * theta1));
}

/// The four joint frames F0..F3 (joint i on z of F_{i-1}) of a Bennett loop starting at @p base.
std::array<Eigen::Isometry3d, 5> bennettFrames(const Eigen::Isometry3d& base, double a1, double alpha1,
                                               double a2, double alpha2, double theta1) {
  const double theta2 = bennettSecondAngle(alpha1, alpha2, theta1);
  std::array<Eigen::Isometry3d, 5> frames;
  frames[0] = base;
  frames[1] = frames[0] * dhTransform(theta1, 0.0, a1, alpha1);
  frames[2] = frames[1] * dhTransform(theta2, 0.0, a2, alpha2);
  frames[3] = frames[2] * dhTransform(-theta1, 0.0, a1, alpha1);
  frames[4] = frames[3] * dhTransform(-theta2, 0.0, a2, alpha2);
  assert((frames[4].matrix() - base.matrix()).norm() < 1e-12 && "Bennett loop does not close");
  return frames;
}

}  // namespace

MechanismDescription makeFourBar(double crankAngle) {
  const double groundLength = 1.0;
  const double crank = 0.35;
  const double coupler = 1.1;
  const double rocker = 0.8;
  const Eigen::Vector2d a(0.0, 0.0);
  const Eigen::Vector2d d(groundLength, 0.0);
  const Eigen::Vector2d b = a + crank * Eigen::Vector2d(std::cos(crankAngle), std::sin(crankAngle));
  const Eigen::Vector2d c = intersectCircles(b, coupler, d, rocker, true);
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  auto p = [](const Eigen::Vector2d& v) { return planar(v.x(), v.y()); };

  MechanismDescription m;
  m.name = "four_bar";
  m.comment =
      "Planar Grashof crank-rocker in the x-y plane, all axes along z. Ground A(0,0)-D(1,0), crank AB 0.35,\n"
      "coupler BC 1.1, rocker CD 0.8 [m]: shortest + longest = 1.45 < 1.8 = sum of the others, the crank is "
      "the\n"
      "shortest link, so it turns fully. Crank at 60 deg; C is the open-branch intersection of the circles\n"
      "(B, 1.1) and (D, 0.8). The loop is closed by loop joint rocker_ground.";
  m.links = {link("ground", {p(a), p(d)}), link("crank", {p(a), p(b)}), link("coupler", {p(b), p(c)}),
             link("rocker", {p(c), p(d)})};
  m.connections = {makeRevolute("ground_crank", "ground", "crank", p(a), z),
                   makeRevolute("crank_coupler", "crank", "coupler", p(b), z),
                   makeRevolute("coupler_rocker", "coupler", "rocker", p(c), z),
                   makeRevolute("rocker_ground", "rocker", "ground", p(d), z)};
  m.expectations = {expectation("planar", 1, 1), expectation("spatial", 1, -2)};
  return m;
}

MechanismDescription makePuma560() {
  // Standard DH rows (θ, d, a, α); α1 = −90° as in the contract's table.
  const std::array<double, 6> d = {0.0, 0.0, 0.15005, 0.4318, 0.0, 0.0};
  const std::array<double, 6> a = {0.0, 0.4318, 0.0203, 0.0, 0.0, 0.0};
  const std::array<double, 6> alpha = {-90 * kDeg, 0.0, -90 * kDeg, 90 * kDeg, -90 * kDeg, 0.0};
  const std::array<double, 6> theta = {20 * kDeg, -35 * kDeg, 50 * kDeg, 30 * kDeg, -40 * kDeg, 15 * kDeg};

  MechanismDescription m;
  m.name = "puma560";
  m.comment =
      "PUMA 560, open chain, standard DH A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i):\n"
      "a = (0, 0.4318, 0.0203, 0, 0, 0), d = (0, 0, 0.15005, 0.4318, 0, 0) [m],\n"
      "alpha = (-90, 0, -90, 90, -90, 0) deg, posed at theta = (20, -35, 50, 30, -40, 15) deg (baked into "
      "the\n"
      "joint origins; joint values in the file are 0). Joint i turns about z of DH frame i-1.";
  m.visualRadius = 0.02;
  m.links.push_back(link("base"));
  Eigen::Isometry3d previous = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 6; ++i) {
    const Eigen::Isometry3d next = previous * dhTransform(theta[i], d[i], a[i], alpha[i]);
    const std::string name = "link" + std::to_string(i + 1);
    const Eigen::Vector3d elbow = previous * Eigen::Vector3d(0.0, 0.0, d[i]);
    std::vector<Eigen::Vector3d> path = {previous.translation(), elbow, next.translation()};
    if (i == 5) {
      path.push_back(next * Eigen::Vector3d(0.0, 0.0, 0.06));
    }
    m.links.push_back(link(name, path));
    Connection joint =
        makeRevolute("joint" + std::to_string(i + 1), i == 0 ? "base" : "link" + std::to_string(i), name,
                     previous.translation(), previous.linear().col(2));
    // The joint frame turns with link i, so each URDF origin reads Tz(d) Tx(a) Rx(α) Rz(θ_next).
    joint.frame = previous * Eigen::AngleAxisd(theta[i], Eigen::Vector3d::UnitZ());
    m.connections.push_back(joint);
    previous = next;
  }
  m.links.front().visualPath = {Eigen::Vector3d(0, 0, -0.6), Eigen::Vector3d::Zero()};
  m.expectations = {expectation("spatial", 6, 6)};
  return m;
}

MechanismDescription makeParallelogramCrank() {
  const double crank = 0.4;
  const double angle = 65 * kDeg;
  const Eigen::Vector3d e = crank * unitCircle(angle);
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d a0 = planar(0.0, 0.0);
  const Eigen::Vector3d p0 = planar(0.5, 0.0);
  const Eigen::Vector3d b0 = planar(1.0, 0.0);

  MechanismDescription m;
  m.name = "parallelogram_crank";
  m.comment =
      "Parallelogram with a third crank (the lecture's example), x-y plane, axes along z. Ground pivots\n"
      "(0,0), (0.5,0), (1,0); three equal parallel cranks crank_a, pq, crank_b of 0.4 m at 65 deg; the "
      "coupler\n"
      "joins their tips, so it is the ground translated by the crank vector at every crank angle.\n"
      "Any one of the three cranks can be removed without changing the motion: link pq is redundant.";
  m.links = {link("ground", {a0, b0}), link("crank_a", {a0, a0 + e}), link("crank_b", {b0, b0 + e}),
             link("pq", {p0, p0 + e}), link("coupler", {a0 + e, b0 + e})};
  m.connections = {makeRevolute("ground_crank_a", "ground", "crank_a", a0, z),
                   makeRevolute("crank_a_coupler", "crank_a", "coupler", a0 + e, z),
                   makeRevolute("ground_crank_b", "ground", "crank_b", b0, z),
                   makeRevolute("crank_b_coupler", "crank_b", "coupler", b0 + e, z),
                   makeRevolute("ground_pq", "ground", "pq", p0, z),
                   makeRevolute("pq_coupler", "pq", "coupler", p0 + e, z)};
  m.expectations = {expectation("planar", 1, 0), expectation("spatial", 1, -6)};
  return m;
}

MechanismDescription makeThreeSliders() {
  const Eigen::Vector3d v0 = planar(0.0, 0.0);
  const Eigen::Vector3d v1 = planar(1.0, 0.0);
  const Eigen::Vector3d v2 = planar(0.5, std::sqrt(3.0) / 2.0);
  const Eigen::Vector3d centre = (v0 + v1 + v2) / 3.0;

  MechanismDescription m;
  m.name = "three_sliders";
  m.comment =
      "Three links (ground, link_b, link_c) pairwise joined by sliders along the sides of the equilateral\n"
      "triangle (0,0), (1,0), (0.5, sqrt(3)/2) [m], x-y plane. Slides s1 u1 + s2 u2 + s3 u3 = 0 with\n"
      "u1 + u2 + u3 = 0 force s1 = s2 = s3: one freedom, one equation too many in the plane.";
  m.links = {link("ground", {centre, 0.5 * (v0 + v1), centre, 0.5 * (v2 + v0)}),
             link("link_b", {centre, 0.5 * (v0 + v1), centre, 0.5 * (v1 + v2)}),
             link("link_c", {centre, 0.5 * (v1 + v2), centre, 0.5 * (v2 + v0)})};
  m.connections = {makePrismatic("slide_ab", "ground", "link_b", 0.5 * (v0 + v1), v1 - v0),
                   makePrismatic("slide_bc", "link_b", "link_c", 0.5 * (v1 + v2), v2 - v1),
                   makePrismatic("slide_ca", "link_c", "ground", 0.5 * (v2 + v0), v0 - v2)};
  m.expectations = {expectation("planar", 1, 0), expectation("spatial", 1, -3)};
  return m;
}

MechanismDescription makeRppr() {
  const Eigen::Vector3d a = planar(0.0, 0.0);
  const Eigen::Vector3d d = planar(1.0, 0.0);
  const Eigen::Vector3d s1 = planar(0.35, 0.0);
  const Eigen::Vector3d s2 = planar(0.65, 0.0);
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();

  MechanismDescription m;
  m.name = "rppr";
  m.comment =
      "RPPR in the x-y plane: link1 pinned to the ground at A(0,0), link3 at D(1,0); the middle link2 slides "
      "on\n"
      "link1 at (0.35,0) and on link3 at (0.65,0), both slides along x, i.e. collinear with AD. Both slide "
      "lines\n"
      "of link2 must pass through A and D, so the cranks are locked and link2 slides along AD: DOF 1 "
      "(passive\n"
      "slide), Gruebler 1, nothing redundant.";
  m.links = {link("ground", {a, d}), link("link1", {a, s1}), link("link2", {s1 - 0.1 * x, s2 + 0.1 * x}),
             link("link3", {s2, d})};
  m.connections = {
      makeRevolute("pivot_a", "ground", "link1", a, z), makePrismatic("slide_1", "link1", "link2", s1, x),
      makePrismatic("slide_2", "link2", "link3", s2, x), makeRevolute("pivot_d", "link3", "ground", d, z)};
  m.expectations = {expectation("planar", 1, 1), expectation("spatial", 1, -2)};
  return m;
}

MechanismDescription makeBennett(double scale, double theta1) {
  const double a = 0.6;
  const double alpha = 40 * kDeg;
  const double beta = 70 * kDeg;
  const double b = a * std::sin(beta) / std::sin(alpha);
  const std::array<Eigen::Isometry3d, 5> f =
      bennettFrames(Eigen::Isometry3d::Identity(), a, alpha, b, beta, theta1);
  const double theta2 = bennettSecondAngle(alpha, beta, theta1);
  const std::array<double, 4> theta = {theta1, theta2, -theta1, -theta2};
  const std::array<const char*, 4> names = {"ground", "link1", "link2", "link3"};

  MechanismDescription m;
  m.name = scale == 1.0 ? "bennett" : "bennett_scaled";
  m.comment =
      "Bennett 4R. Standard DH A_i = Rz(theta_i) Tx(a_i) Rx(alpha_i), offsets 0, links (a, alpha), (b, "
      "beta),\n"
      "(a, alpha), (b, beta) with a = 0.6 m, alpha = 40 deg, beta = 70 deg, b = a sin(beta)/sin(alpha) = " +
      std::to_string(b) +
      " m.\n"
      "Closure (checked numerically, the convention of the contract holds as written):\n"
      "tan(theta1/2) tan(theta2/2) = sin((beta+alpha)/2) / sin((beta-alpha)/2), theta3 = -theta1, theta4 = "
      "-theta2;\n"
      "theta1 = " +
      std::to_string(theta1 / kDeg) + " deg, theta2 = " + std::to_string(theta2 / kDeg) +
      " deg. Joint j(i) turns about z of DH frame i-1;\n"
      "the loop is closed by loop joint j4 (link3 - ground)." +
      (scale == 1.0 ? std::string() : "\nAll lengths multiplied by " + std::to_string(scale) + ".");
  // Link k spans DH frames k-1 → k (the ground spans F3 → F0); joint k+1 sits on z of F_k, joins link k and
  // link k+1 and turns with link k+1, so its frame is F_k Rz(θ_{k+1}).
  for (int i = 0; i < 4; ++i) {
    m.links.push_back(link(names[i], {f[(i + 3) % 4].translation(), f[i].translation()}));
  }
  for (int i = 0; i < 4; ++i) {
    Connection joint = makeRevolute("j" + std::to_string(i + 1), names[i], names[(i + 1) % 4],
                                    f[i].translation(), f[i].linear().col(2));
    joint.frame = f[i] * Eigen::AngleAxisd(theta[i], Eigen::Vector3d::UnitZ());
    m.connections.push_back(joint);
  }
  m.visualRadius = 0.02;
  m.expectations = {expectation("spatial", 1, -2)};
  if (scale != 1.0) {
    scaleMechanism(m, scale);
  }
  return m;
}

MechanismDescription makeSarrus(double height) {
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d ey = Eigen::Vector3d::UnitY();
  // Limb A moves in the plane x = 0 (hinges along x), limb B in the plane y = 0 (hinges along y).
  const Eigen::Vector3d groundA(0.0, -0.5, 0.0);
  const Eigen::Vector3d topA(0.0, -0.5, height);
  const Eigen::Vector2d kneeA2 = intersectCircles({-0.5, 0.0}, 0.55, {-0.5, height}, 0.65, false);
  const Eigen::Vector3d kneeA(0.0, kneeA2.x(), kneeA2.y());
  const Eigen::Vector3d groundB(0.5, 0.0, 0.0);
  const Eigen::Vector3d topB(0.5, 0.0, height);
  const Eigen::Vector2d kneeB2 = intersectCircles({0.5, 0.0}, 0.6, {0.5, height}, 0.6, false);
  const Eigen::Vector3d kneeB(kneeB2.x(), 0.0, kneeB2.y());

  MechanismDescription m;
  m.name = "sarrus";
  m.comment =
      "Sarrus 6R. Ground and top plate joined by limb A (hinges along x at (0,-0.5,0), knee, (0,-0.5,h); "
      "links\n"
      "0.55 and 0.65 m) and limb B (hinges along y at (0.5,0,0), knee, (0.5,0,h); links 0.6 and 0.6 m),\n"
      "h = 0.8 m, knees bent outwards. Limb A lets the plate move in y-z and turn about x, limb B in x-z "
      "and\n"
      "about y: only the translation along z is common, for any h. Loop closed by loop joint limb_b_ground.";
  m.links = {link("ground", {groundA, groundB}),  link("limb_a_lower", {groundA, kneeA}),
             link("limb_a_upper", {kneeA, topA}), link("top", {topA, topB}),
             link("limb_b_upper", {topB, kneeB}), link("limb_b_lower", {kneeB, groundB})};
  m.connections = {makeRevolute("limb_a_ground", "ground", "limb_a_lower", groundA, ex),
                   makeRevolute("limb_a_knee", "limb_a_lower", "limb_a_upper", kneeA, ex),
                   makeRevolute("limb_a_top", "limb_a_upper", "top", topA, ex),
                   makeRevolute("limb_b_top", "top", "limb_b_upper", topB, ey),
                   makeRevolute("limb_b_knee", "limb_b_upper", "limb_b_lower", kneeB, ey),
                   makeRevolute("limb_b_ground", "limb_b_lower", "ground", groundB, ey)};
  m.visualRadius = 0.015;
  m.expectations = {expectation("spatial", 1, 0)};
  return m;
}

MechanismDescription makeBricard() {
  // Half-turn about the z axis: H(x, y, z) = (−x, −y, z).
  auto halfTurn = [](const Eigen::Vector3d& v) { return Eigen::Vector3d(-v.x(), -v.y(), v.z()); };
  std::array<Eigen::Vector3d, 6> points;
  std::array<Eigen::Vector3d, 6> axes;
  points[0] = {1.0, 0.2, 0.1};
  axes[0] = Eigen::Vector3d(0.3, 0.9, 0.4).normalized();
  points[1] = {0.4, 1.1, 0.6};
  axes[1] = Eigen::Vector3d(-0.8, 0.2, 0.5).normalized();
  points[2] = {-0.6, 0.7, 1.1};
  axes[2] = Eigen::Vector3d(0.2, -0.5, 0.9).normalized();
  for (int i = 0; i < 3; ++i) {
    points[i + 3] = halfTurn(points[i]);
    axes[i + 3] = halfTurn(axes[i]);
  }
  // Link i joins joint i and joint i+1; the ground joins joint 6 and joint 1.
  const std::array<const char*, 6> names = {"ground", "link1", "link2", "link3", "link4", "link5"};

  MechanismDescription m;
  m.name = "bricard";
  m.comment =
      "Line-symmetric Bricard 6R. Joint lines (point; direction, normalised):\n"
      "L1 (1, 0.2, 0.1; 0.3, 0.9, 0.4), L2 (0.4, 1.1, 0.6; -0.8, 0.2, 0.5), L3 (-0.6, 0.7, 1.1; 0.2, -0.5, "
      "0.9),\n"
      "L4..L6 = images of L1..L3 under the half-turn about the z axis, (x, y, z) -> (-x, -y, z). A 6R loop "
      "that\n"
      "is line-symmetric is mobile (Bricard): the symmetric motion keeps the loop closed. Joint i joins "
      "link\n"
      "i-1 and link i (link 0 = ground); loop closed by loop joint j6.";
  // Joint i+1 (on points[i]) joins link i and link i+1: link i spans points[i-1] → points[i].
  for (int i = 0; i < 6; ++i) {
    m.links.push_back(link(names[i], {points[(i + 5) % 6], points[i]}));
  }
  for (int i = 0; i < 6; ++i) {
    m.connections.push_back(
        makeRevolute("j" + std::to_string(i + 1), names[i], names[(i + 1) % 6], points[i], axes[i]));
  }
  m.visualRadius = 0.02;
  m.expectations = {expectation("spatial", 1, 0)};
  return m;
}

MechanismDescription makeGoldberg(double theta1) {
  const double a = 0.6;
  const double alpha = 40 * kDeg;
  const double k = std::sin(alpha) / a;
  const double beta = 70 * kDeg;
  const double b = std::sin(beta) / k;
  const double gamma = 55 * kDeg;
  const double c = std::sin(gamma) / k;
  const double delta = 50 * kDeg;
  // Loop I: L (b, β), A1 (a, α), B1 (b, β), C1 (a, α). Loop II shares L's frames F0 (turned by δ) and F1.
  const std::array<Eigen::Isometry3d, 5> f1 =
      bennettFrames(Eigen::Isometry3d::Identity(), b, beta, a, alpha, theta1);
  const Eigen::Isometry3d base2 = Eigen::Isometry3d(Eigen::AngleAxisd(delta, Eigen::Vector3d::UnitZ()));
  const std::array<Eigen::Isometry3d, 5> f2 = bennettFrames(base2, b, beta, c, gamma, theta1 - delta);
  assert((f1[1].matrix() - f2[1].matrix()).norm() < 1e-12 && "the two Bennett loops must share link L");

  MechanismDescription m;
  m.name = "goldberg";
  m.comment =
      "Goldberg 5R from two Bennett linkages sharing link L = (b, beta) and its two joints (standard DH\n"
      "Rz(theta) Tx(a) Rx(alpha), offsets 0). Bennett I: L, A1 (a, alpha), B1 (b, beta), C1 (a, alpha);\n"
      "Bennett II: L, A2 (c, gamma), B2 (b, beta), C2 (c, gamma); sin(alpha)/a = sin(beta)/b = "
      "sin(gamma)/c,\n"
      "a = 0.6 m, alpha = 40, beta = 70, gamma = 55 deg. Loop II's first frame is loop I's turned by\n"
      "delta = 50 deg about joint 1 (theta1' = theta1 - delta), so C1 and C2 keep their relative pose and "
      "are\n"
      "fused into the ground; L is removed; A1 and A2 keep the revolute about L's second joint.\n"
      "Links: ground (C1+C2), b1, a1, a2, b2; loop closed by loop joint g5. theta1 = " +
      std::to_string(theta1 / kDeg) + " deg.";
  const Eigen::Vector3d pB1 = f1[3].translation();
  const Eigen::Vector3d pA1 = f1[2].translation();
  const Eigen::Vector3d pL = f1[1].translation();
  const Eigen::Vector3d pA2 = f2[2].translation();
  const Eigen::Vector3d pB2 = f2[3].translation();
  m.links = {link("ground", {pB1, f1[0].translation(), pB2}), link("b1", {pB1, pA1}), link("a1", {pA1, pL}),
             link("a2", {pL, pA2}), link("b2", {pA2, pB2})};
  m.connections = {makeRevolute("g1", "ground", "b1", pB1, f1[3].linear().col(2)),
                   makeRevolute("g2", "b1", "a1", pA1, f1[2].linear().col(2)),
                   makeRevolute("g3", "a1", "a2", pL, f1[1].linear().col(2)),
                   makeRevolute("g4", "a2", "b2", pA2, f2[2].linear().col(2)),
                   makeRevolute("g5", "b2", "ground", pB2, f2[3].linear().col(2))};
  m.visualRadius = 0.02;
  m.expectations = {expectation("spatial", 1, -1)};
  return m;
}

MechanismDescription makeRssr() {
  const Eigen::Vector3d o1(0.0, 0.0, 0.0);
  const Eigen::Vector3d axis1 = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d o2(0.0, 1.0, 0.35);
  const Eigen::Vector3d axis2 = Eigen::Vector3d::UnitX();
  const double angle1 = 50 * kDeg;
  const double angle2 = 120 * kDeg;
  const Eigen::Vector3d s1 = o1 + Eigen::Vector3d(0.3 * std::cos(angle1), 0.3 * std::sin(angle1), 0.1);
  const Eigen::Vector3d s2 = o2 + Eigen::Vector3d(0.15, 0.4 * std::cos(angle2), 0.4 * std::sin(angle2));

  MechanismDescription m;
  m.name = "rssr";
  m.comment =
      "RSSR. Ground revolute 1: axis z through (0,0,0), crank1 to S1 = (0.3 cos 50, 0.3 sin 50, 0.1);\n"
      "ground revolute 2: axis x through (0,1,0.35) (skew to axis 1, distance 1 m), crank2 to\n"
      "S2 = (0.15, 1 + 0.4 cos 120, 0.35 + 0.4 sin 120) [m]. The rod S1-S2 is held only by the two spherical "
      "loop\n"
      "joints and hangs from the ground by a floating joint (which constrains nothing). DOF 2: the crank\n"
      "motion and the rod's spin about S1-S2.";
  LinkDescription rod = link("rod", {s1, s2});
  rod.floatingFrame = frameFromAxis(s1, s2 - s1);
  m.links = {link("ground", {o1, o1 + 0.2 * axis1, o2, o2 + 0.2 * axis2}),
             link("crank1", {o1, o1 + 0.1 * axis1, s1}), link("crank2", {o2, o2 + 0.15 * axis2, s2}), rod};
  m.connections = {makeRevolute("r1", "ground", "crank1", o1, axis1),
                   makeRevolute("r2", "ground", "crank2", o2, axis2),
                   makeSpherical("s1", "crank1", "rod", s1), makeSpherical("s2", "rod", "crank2", s2)};
  m.visualRadius = 0.015;
  m.expectations = {expectation("spatial", 2, 2)};
  return m;
}

MechanismDescription makePeaucellier(double crankAngle) {
  const double r = 1.0, arm = 3.0, side = 1.5;
  const Eigen::Vector2d o(0.0, 0.0), a(r, 0.0);
  const Eigen::Vector2d p = a + r * Eigen::Vector2d(std::cos(crankAngle), std::sin(crankAngle));
  const Eigen::Vector2d b = intersectCircles(o, arm, p, side, true);
  const Eigen::Vector2d d = intersectCircles(o, arm, p, side, false);
  const Eigen::Vector2d q = b + d - p;  // the rhombus' fourth corner
  assert(std::abs(p.norm() * q.norm() - (arm * arm - side * side)) < 1e-12 && "inversion does not hold");
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  auto v = [](const Eigen::Vector2d& w) { return planar(w.x(), w.y()); };

  MechanismDescription m;
  m.name = "peaucellier";
  m.comment =
      "Peaucellier-Lipkin straight-line linkage (Peaucellier 1864, Lipkin 1871; the inversor\n"
      "cell as in Hartenberg & Denavit, Kinematic Synthesis of Linkages, 1964), our own numbers,\n"
      "in the x-y plane, axes along z: ground pivots O(0,0) and A(1,0), crank AP 1 (so P runs on\n"
      "a circle through O), arms OB = OD = 3, rhombus PB = BQ = QD = DP = 1.5 [m]. O, P, Q are\n"
      "collinear with |OP| |OQ| = 3^2 - 1.5^2 = 6.75, so Q runs on the line x = 6.75 / 2 = 3.375.\n"
      "Written at crank angle " +
      std::to_string(crankAngle / kDeg) +
      " deg, B on the left of O->P, D on the right.\nLoops closed by loop joints pb_arm1, pd_arm2, bq_dq. "
      "Planar DOF 1.";
  m.links = {link("ground", {v(o), v(a)}), link("crank", {v(a), v(p)}), link("arm1", {v(o), v(b)}),
             link("arm2", {v(o), v(d)}),   link("pb", {v(p), v(b)}),    link("pd", {v(p), v(d)}),
             link("bq", {v(b), v(q)}),     link("dq", {v(d), v(q)})};
  m.connections = {
      makeRevolute("a_crank", "ground", "crank", v(a), z), makeRevolute("o_arm1", "ground", "arm1", v(o), z),
      makeRevolute("o_arm2", "ground", "arm2", v(o), z),   makeRevolute("crank_pb", "crank", "pb", v(p), z),
      makeRevolute("crank_pd", "crank", "pd", v(p), z),    makeRevolute("arm1_bq", "arm1", "bq", v(b), z),
      makeRevolute("arm2_dq", "arm2", "dq", v(d), z),      makeRevolute("pb_arm1", "pb", "arm1", v(b), z),
      makeRevolute("pd_arm2", "pd", "arm2", v(d), z),      makeRevolute("bq_dq", "bq", "dq", v(q), z)};
  m.visualRadius = 0.03;
  m.expectations = {expectation("planar", 1, 1), expectation("spatial", 1, -8)};
  return m;
}

}  // namespace mobility_analysis

namespace mobility_analysis {

MechanismDescription makeFlattenedFourBar() {
  // Change-point four-bar: crank + coupler = ground + rocker (0.4 + 0.9 = 1.0 + 0.3), drawn flat.
  const Eigen::Vector3d a = planar(0.0, 0.0), b = planar(0.4, 0.0), c = planar(1.3, 0.0),
                        d = planar(1.0, 0.0);
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  MechanismDescription m;
  m.name = "flattened_four_bar";
  m.comment =
      "Four-bar drawn flat: ground A(0,0)-D(1,0), crank AB 0.4, coupler BC 0.9, rocker CD 0.3 [m], all pins "
      "on\n"
      "the x axis (B = (0.4,0), C = (1.3,0)). crank + coupler = ground + rocker (1.3 = 1.3): a change-point\n"
      "four-bar, and the flat pose is where its two branches cross. First order: DOF 2 (the nullity), "
      "Gruebler 1,\n"
      "1 redundant equation; the mechanism moves along either branch with 1 DOF: finite_dof 1, singular, "
      "and\n"
      "the redundancy's cause is the configuration.";
  m.links = {link("ground", {a, d}), link("crank", {a, b}), link("coupler", {b, c}), link("rocker", {c, d})};
  m.connections = {makeRevolute("ground_crank", "ground", "crank", a, z),
                   makeRevolute("crank_coupler", "crank", "coupler", b, z),
                   makeRevolute("coupler_rocker", "coupler", "rocker", c, z),
                   makeRevolute("rocker_ground", "rocker", "ground", d, z)};
  m.expectations = {expectation("planar", 2, 1), expectation("spatial", 2, -2)};
  return m;
}

MechanismDescription makeParallelogramBifurcation() {
  const Eigen::Vector3d a = planar(0.0, 0.0), b = planar(0.5, 0.0), c = planar(1.5, 0.0),
                        d = planar(1.0, 0.0);
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  MechanismDescription m;
  m.name = "parallelogram_bifurcation";
  m.comment =
      "Parallelogram four-bar at its bifurcation pose: ground A(0,0)-D(1,0), cranks AB = DC = 0.5, coupler\n"
      "BC = 1 [m], both cranks along +x (B = (0.5,0), C = (1.5,0)), all pins collinear. Here the "
      "parallelogram\n"
      "branch and the anti-parallelogram branch cross. First order: DOF 2, Gruebler 1, 1 redundant "
      "equation;\n"
      "finite_dof 1, singular, cause configuration.";
  m.links = {link("ground", {a, d}), link("crank1", {a, b}), link("coupler", {b, c}), link("crank2", {c, d})};
  m.connections = {makeRevolute("ground_crank1", "ground", "crank1", a, z),
                   makeRevolute("crank1_coupler", "crank1", "coupler", b, z),
                   makeRevolute("coupler_crank2", "coupler", "crank2", c, z),
                   makeRevolute("crank2_ground", "crank2", "ground", d, z)};
  m.expectations = {expectation("planar", 2, 1), expectation("spatial", 2, -2)};
  return m;
}

MechanismDescription makeCollinearBars() {
  const Eigen::Vector3d a = planar(0.0, 0.0), b = planar(0.5, 0.0), c = planar(1.0, 0.0);
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  MechanismDescription m;
  m.name = "collinear_bars";
  m.comment =
      "Two equal bars collinear between two ground pins: A(0,0) and C(1,0) on the ground, bar1 A-B and bar2\n"
      "B-C of 0.5 m, B = (0.5,0) [m]. Gruebler 3 (3 - 1) - 3 * 2 = 0: a structure. B may move across the "
      "line\n"
      "to first order (DOF 1, 1 redundant equation), but not at all in fact: finite_dof 0, singular, cause\n"
      "configuration (the classic example of a first-order infinitesimal mechanism).";
  m.links = {link("ground", {a, c}), link("bar1", {a, b}), link("bar2", {b, c})};
  m.connections = {makeRevolute("pin_a", "ground", "bar1", a, z), makeRevolute("pin_b", "bar1", "bar2", b, z),
                   makeRevolute("pin_c", "bar2", "ground", c, z)};
  m.expectations = {expectation("planar", 1, 0), expectation("spatial", 1, -3)};
  return m;
}

MechanismDescription makeStewart6Sps() {
  // Base joints at radius 1 m, angles 120 k +- 15 deg; platform joints at radius 0.5 m, height 1 m, angles
  // 60 + 120 k +- 15 deg; leg i joins base joint i to the platform joint next to it.
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  MechanismDescription m;
  m.name = "stewart_6sps";
  m.comment =
      "Stewart-Gough platform, 6-SPS. Base ball joints B_i at radius 1 m, angles 120k -15 and 120k +15 deg\n"
      "(k = 0, 1, 2); platform ball joints P_i at radius 0.5 m, height 1 m, angles 120k - 45 and 120k + 45 "
      "deg;\n"
      "leg i runs from B_i to P_i: a cylinder (ball at B_i) and a piston (ball at P_i) joined by a "
      "prismatic\n"
      "joint along the leg at its midpoint. Cylinders, pistons' parents and the platform hang by floating\n"
      "joints. Gruebler 6 (14 - 18 - 1) + 6 (3 + 1 + 3) = 12 = DOF: the platform's 6 and each leg's spin "
      "about\n"
      "its own line (Tsai 1999: passive), so passive_dof 6, output_dof 6.";
  std::vector<Eigen::Vector3d> base, top;
  for (int k = 0; k < 3; ++k) {
    for (int s : {-1, 1}) {
      const double angleBase = (120.0 * k + 15.0 * s) * kDeg;
      const double angleTop = (120.0 * k + 45.0 * s) * kDeg;
      base.push_back(Eigen::Vector3d(std::cos(angleBase), std::sin(angleBase), 0.0));
      top.push_back(Eigen::Vector3d(0.5 * std::cos(angleTop), 0.5 * std::sin(angleTop), 1.0));
    }
  }
  LinkDescription platform = link("platform", {top[0], top[1], top[2], top[3], top[4], top[5], top[0]});
  platform.floatingFrame = frameFromAxis(Eigen::Vector3d(0.0, 0.0, 1.0), z);
  m.links = {link("ground", {base[0], base[1], base[2], base[3], base[4], base[5], base[0]}), platform};
  for (int i = 0; i < 6; ++i) {
    const std::string n = std::to_string(i + 1);
    const Eigen::Vector3d axis = (top[i] - base[i]).normalized();
    const Eigen::Vector3d middle = 0.5 * (base[i] + top[i]);
    LinkDescription cylinder = link("cylinder" + n, {base[i], middle});
    cylinder.floatingFrame = frameFromAxis(base[i], axis);
    m.links.push_back(cylinder);
    m.links.push_back(link("piston" + n, {middle, top[i]}));
    m.connections.push_back(makePrismatic("slide" + n, "cylinder" + n, "piston" + n, middle, axis));
  }
  for (int i = 0; i < 6; ++i) {
    const std::string n = std::to_string(i + 1);
    m.connections.push_back(makeSpherical("base_ball" + n, "ground", "cylinder" + n, base[i]));
    m.connections.push_back(makeSpherical("top_ball" + n, "piston" + n, "platform", top[i]));
  }
  m.visualRadius = 0.015;
  m.expectations = {expectation("spatial", 12, 12)};
  return m;
}

MechanismDescription makeDeltaRobot() {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const double baseRadius = 0.2, armLength = 0.2, armAngle = 30.0 * kDeg, platformRadius = 0.05;
  const double halfWidth = 0.03;
  const Eigen::Vector3d centre(0.0, 0.0, -0.35);
  MechanismDescription m;
  m.name = "delta_robot";
  m.comment =
      "Delta robot (Clavel) with ball-jointed parallelogram rods. Arm i (i = 0, 1, 2 at 0, 120, 240 deg):\n"
      "ground revolute at radius 0.2 m about the tangent t_i, arm 0.2 m long pointing out and 30 deg down;\n"
      "two balls at the arm's end E_i +- 0.03 t_i and two on the platform at C + 0.05 u_i +- 0.03 t_i with\n"
      "C = (0, 0, -0.35) m; each of the two rods of an arm joins a pair (the rods of an arm are equal and\n"
      "parallel: a parallelogram). Rods and platform hang by floating joints. Gruebler 6 (11 - 15 - 1) + 3 + "
      "36\n"
      "= 9 = DOF: the platform's 3 translations and each rod's spin about its own line (passive_dof 6,\n"
      "output_dof 3).";
  LinkDescription platform = link("platform");
  platform.floatingFrame = frameFromAxis(centre, z);
  m.links = {link("ground"), platform};
  std::vector<Connection> balls;
  for (int i = 0; i < 3; ++i) {
    const std::string n = std::to_string(i + 1);
    const double phi = 120.0 * i * kDeg;
    const Eigen::Vector3d u(std::cos(phi), std::sin(phi), 0.0), t(-std::sin(phi), std::cos(phi), 0.0);
    const Eigen::Vector3d pivot = baseRadius * u;
    const Eigen::Vector3d end = pivot + armLength * (std::cos(armAngle) * u - std::sin(armAngle) * z);
    m.links.push_back(link("arm" + n, {pivot, end}));
    m.connections.push_back(makeRevolute("shoulder" + n, "ground", "arm" + n, pivot, t));
    for (int s : {-1, 1}) {
      const std::string rod = "rod" + n + (s < 0 ? "a" : "b");
      const Eigen::Vector3d top = end + s * halfWidth * t;
      const Eigen::Vector3d bottom = centre + platformRadius * u + s * halfWidth * t;
      LinkDescription r = link(rod, {top, bottom});
      r.floatingFrame = frameFromAxis(top, bottom - top);
      m.links.push_back(r);
      balls.push_back(makeSpherical(rod + "_top", "arm" + n, rod, top));
      balls.push_back(makeSpherical(rod + "_bottom", rod, "platform", bottom));
    }
  }
  m.connections.insert(m.connections.end(), balls.begin(), balls.end());
  m.visualRadius = 0.008;
  m.expectations = {expectation("spatial", 9, 9)};
  return m;
}

}  // namespace mobility_analysis
