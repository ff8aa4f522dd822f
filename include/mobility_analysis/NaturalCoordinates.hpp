#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "mobility_analysis/CouplingEquation.hpp"
#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/JointTypes.hpp"
#include "mobility_analysis/Kinematics.hpp"
#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis {

/// Requested analysis mode (DESIGN.md §2).
enum class AnalysisMode { Auto, Planar, Spatial };

/// @return "auto", "planar" or "spatial".
const char* toString(AnalysisMode mode);
/// @return The mode spelled @p text, or a Diagnostic.
Result<AnalysisMode> parseAnalysisMode(const std::string& text);

/// Where a constraint equation comes from; also the order of the phases (DESIGN.md §3).
enum class EquationSource : unsigned char { Link, Joint, Boundary };
/// @return "link", "joint" or "boundary".
const char* toString(EquationSource source);

/// What an element is on its body; with the body and joint names it spells the element's label.
enum class ElementRole : unsigned char {
  JointPoint,       ///< "P(link@joint)"
  JointAxis,        ///< "u(link@joint)"
  JointSecondAxis,  ///< "v(link@joint)": a universal joint's second axis
  Origin,           ///< "O(link)"
  Auxiliary1,       ///< "aux1(link)"
  Auxiliary2,       ///< "aux2(link)"
};

/**
 * @brief A basic point or unit vector of one body: the natural coordinates (García de Jalón & Bayo, ch. 3).
 *
 * Its label ("P(crank@j2)", "u(crank@j2)", "aux1(rod)") is written on demand by elementLabel: a model of
 * 10^6 equations only ever names the elements of the equations it reports.
 */
struct Element {
  // (The integers and the two one-byte members side by side, then the vector: 40 bytes, not 48 with padding.)
  int body = -1;          ///< Link index.
  int joint = -1;         ///< The joint it sits at (JointPoint, JointAxis, JointSecondAxis), else -1.
  int offset = 0;         ///< First coordinate in q.
  bool isPoint = true;    ///< Point or unit vector.
  ElementRole role = ElementRole::JointPoint;
  Eigen::Vector3d local;  ///< In the body frame, point divided by the characteristic length.
};

/// A vector of the body as a function of q: element `head`, minus point `tail` when tail >= 0.
struct Direction {
  int head = -1;
  int tail = -1;
};

/// The algebraic form of one scalar equation f(q) = 0.
enum class EquationForm : unsigned char {
  Dot,          ///< a·b - value
  Cross,        ///< (a x b)_component - value; planar: a_x b_y - a_y b_x - value
  Component,    ///< a_component - value
  Combination,  ///< (x_target - x_origin - c0 d1 - c1 d2 - c2 d1 x d2)_component; planar: d2 := J d1, no c2
                ///< term
  Triple,       ///< (a x b).c - value (space only)
  Coupling,     ///< v_f(q) - m v_l(q) - c, CoordinateModel::couplings[coupling] (CouplingEquation.hpp)
};

/// What an equation means, for names and for tests.
enum class EquationKind : unsigned char {
  LinkDistance,
  UnitNorm,
  LinkDotProduct,
  LinearCombination,
  CoincidentPoint,
  ParallelAxis,
  PointOnAxisLine,
  FixedTwist,
  AxisAngle,
  PointInPlane,
  Distance,
  FixedCoordinate,
  Coupling
};
/// @return "distance", "unit_norm", … (snake_case, as in the JSON report).
const char* toString(EquationKind kind);

/// One scalar constraint equation, tagged with its source element.
///
/// 64 bytes: a model has 10^6 of these, and their first touch was a sixth of building a 10^5-link chain's
/// model when they were 96. The byte-sized tags come first, then the operands; a Combination, which has no
/// operands a, b, c of its own, keeps its basis directions and its two elements in them (d1(), d2(),
/// target(), origin()), and a Coupling its index in c (coupling()). Read each through the accessor of the
/// equation's form.
struct ConstraintEquation {
  EquationSource source = EquationSource::Link;
  EquationKind kind = EquationKind::LinkDistance;
  EquationForm form = EquationForm::Dot;
  unsigned char component = 0;  ///< Cross, Component, Combination: the coordinate (0, 1, 2).
  int element = -1;             ///< Link index (Link, Boundary) or joint index (Joint).
  Direction a, b;               ///< Operands (Dot, Cross: a and b; Component: a; Triple: a, b and c).
  Direction c;                  ///< Triple: the third operand.
  double value = 0.0;           ///< Dot, Cross, Component, Triple: the constant.
  Eigen::Vector3d coefficients = Eigen::Vector3d::Zero();  ///< Combination: c0, c1, c2.

  /// Combination: the body's basis directions (planar: d2 unused).
  Direction& d1() { return a; }
  const Direction& d1() const { return a; }
  Direction& d2() { return b; }
  const Direction& d2() const { return b; }
  /// Combination: the element expressed.
  int& target() { return c.head; }
  int target() const { return c.head; }
  /// Combination: the body's base point (points only), else -1.
  int& origin() { return c.tail; }
  int origin() const { return c.tail; }
  /// Coupling: index into CoordinateModel::couplings.
  int& coupling() { return c.head; }
  int coupling() const { return c.head; }
};
static_assert(sizeof(ConstraintEquation) == 64, "ConstraintEquation has padding or a member too many");

/// The mechanism in natural coordinates: elements, their coordinates at the assembled pose and the equations.
struct CoordinateModel {
  int dim = 3;                                             ///< 3 spatial, 2 planar.
  int lambda = 6;                                          ///< 6 spatial, 3 planar.
  AnalysisMode mode = AnalysisMode::Spatial;               ///< Planar or Spatial (never Auto).
  Eigen::Vector3d planeNormal = Eigen::Vector3d::UnitZ();  ///< Planar: normal; (e1, e2) span the plane.
  Eigen::Vector3d planeE1 = Eigen::Vector3d::UnitX();
  Eigen::Vector3d planeE2 = Eigen::Vector3d::UnitY();
  double characteristicLength = 1.0;  ///< [m] lengths are divided by it.
  std::vector<Element> elements;
  std::vector<ConstraintEquation> equations;  ///< In contract order: links, joints, boundary.
  std::vector<CouplingTerms> couplings;       ///< The operands of the Coupling equations.
  std::vector<int> jointFreedom;  ///< F_i of each connection in this mode (-1: ignored, e.g. slack cable).
  std::vector<bool> jointActive;  ///< Whether a connection contributes equations (cables: taut passive).
  std::vector<std::vector<int>> bodyElements;  ///< Element indices of each link.
  std::vector<std::string> linkNames;          ///< Per link (the elements' labels).
  std::vector<std::string> jointNames;         ///< Per connection (the elements' labels).
  Eigen::VectorXd q0;  ///< Coordinates at the pose the model was built at (dim num_coordinates).
  int numCoordinates() const { return static_cast<int>(q0.size()); }
  int numConstraints() const { return static_cast<int>(equations.size()); }
};

/// @return Element @p element's label, e.g. "P(crank@j2)" (ElementRole).
std::string elementLabel(const CoordinateModel& model, int element);

/**
 * @brief The readable form of equation @p row, e.g. "|P(crank@j2) - P(crank@j1)|^2 = 1 Lc^2".
 *
 * Written on demand: a model of 10^6 equations only ever shows its redundant ones.
 */
std::string describeEquation(const CoordinateModel& model, int row);

/// @return The plane normal if the mechanism is planar by the rule of DESIGN.md §2 at @p poses, else nothing.
std::optional<Eigen::Vector3d> findPlaneNormal(const Mechanism& mechanism, const LinkPoses& poses);

/**
 * @brief Converts the mechanism at @p poses to natural coordinates and writes the equations in contract
 * order.
 *
 * Rigid links: a base point p0 and directions d1, d2 (planar: d1), with d_i·d_j fixed (3 or 1 equations), and
 * every other element a linear combination of them (3 or 2 equations each), so each body keeps exactly
 * lambda freedoms. Joints: the primitives of their JointTypeSpec row. Boundary: the ground's lambda rigid
 * freedoms fixed. Hence num_coordinates - num_constraints equals the Grübler count.
 * @note The phases (elements at joints, body bases, coordinate order, rigid-link, joint and boundary
 * equations) live one per file under src/core/coordinates/ (coordinates/ModelBuilder.hpp); a joint type's
 * equations are its JointTypeSpec row's primitives, written in JointEquations.cpp, with their algebra (value,
 * gradient, Hessian) in coordinates/EquationForms.hpp.
 * @param[in] mechanism the mechanism.
 * @param[in] poses link poses at which the loops close (or nearly: the assembly's starting point).
 * @param[in] mode Auto, Planar or Spatial.
 * @param[in] characteristicLength [m] (see computeCharacteristicLength).
 * @return The model, or a Diagnostic (e.g. a revolute axis not normal to the plane in planar mode).
 */
Result<CoordinateModel> buildCoordinateModel(const Mechanism& mechanism, const LinkPoses& poses,
                                             AnalysisMode mode, double characteristicLength);

/**
 * @brief Natural coordinates of every element at @p poses in @p model's space (projected for planar models).
 * @return q (dim model.numCoordinates()).
 */
Eigen::VectorXd computeCoordinates(const CoordinateModel& model, const LinkPoses& poses);

/**
 * @brief Recovers link poses from coordinates by fitting each body's elements (Kabsch); planar models keep
 *        the out-of-plane part of @p reference.
 */
LinkPoses recoverPoses(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const LinkPoses& reference);

}  // namespace mobility_analysis
