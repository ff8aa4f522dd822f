#pragma once

#include <vector>

#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis {

/**
 * @brief Reusable equation groups between the two bodies of a joint (García de Jalón & Bayo, ch. 3).
 *
 * Counts are (spatial, planar): CoincidentPoint p_A - p_B = 0 (3, 2); ParallelAxis u_A x u_B = 0 on the
 * components that are not degenerate (2, 1); PointOnAxisLine u_A x (p_B - p_A) = 0 likewise (2, 1);
 * FixedTwist a·b = const for one direction of each body that turns about the axis (1, 1); AxisAngle
 * u_A·v_B = cos(gamma) (1, -); PointInPlane (p_B - p_A)·u_A = 0 (1, -); Distance |p_B - p_A|^2 = L^2 (1, 1).
 */
enum class Primitive { CoincidentPoint, ParallelAxis, PointOnAxisLine, FixedTwist, AxisAngle, PointInPlane, Distance };

/// Number of scalar equations of @p primitive in the space of dimension @p dim (3 spatial, 2 planar).
int equationCount(Primitive primitive, int dim);

/// Which joint elements a primitive's equations read (so phase 1 of the model building adds only those).
struct PrimitiveElements {
  bool points = false;    ///< A point of the joint on each body.
  bool axis1 = false;     ///< The axis on link1 (a line or a plane normal).
  bool bothAxes = false;  ///< The axis on each body (universal: the second axis on link2).
};

/**
 * @brief One row of the primitive table: its equation counts and the elements it reads. The equations
 * themselves are written by the primitive's writer in src/core/coordinates/JointEquations.cpp, and their
 * algebra (value, gradient, Hessian) lives in the form types of coordinates/EquationForms.hpp.
 */
struct PrimitiveSpec {
  Primitive primitive;
  const char* name;      ///< "coincident_point", … (the EquationKind it writes).
  int spatialEquations;  ///< lambda = 6.
  int planarEquations;   ///< lambda = 3.
  PrimitiveElements elements;
};

/// @return The table row of @p primitive.
const PrimitiveSpec& getPrimitiveSpec(Primitive primitive);

/// @return The elements @p primitive reads.
inline PrimitiveElements primitiveElements(Primitive primitive) { return getPrimitiveSpec(primitive).elements; }

/// How a joint acts when the mechanism is analysed in the plane.
enum class PlanarForm {
  Pin,     ///< Turns about the plane normal: {CoincidentPoint}, freedom 1.
  Slider,  ///< Slides along an in-plane axis: {ParallelAxis, PointOnAxisLine}, freedom 1.
  Weld,    ///< No relative motion: {CoincidentPoint, FixedTwist}, freedom 0.
  Free,    ///< No constraint in the plane, freedom 3.
  Invalid  ///< The joint's axis does not allow motion in the plane.
};

/// One row of the joint table: everything the Jacobian, the equation count and Grübler's count read.
struct JointTypeSpec {
  JointType type;
  int spatialFreedom;                        ///< F_i for lambda = 6.
  std::vector<Primitive> spatialPrimitives;  ///< Sum of equation counts = 6 - spatialFreedom.
  bool needsAxis;                            ///< Whether its axis direction matters (parallel, line, plane).
};

/// @return The table row of @p type.
const JointTypeSpec& getJointTypeSpec(JointType type);

/// @return The equation groups of a planar form (Free and Invalid: none).
const std::vector<Primitive>& planarPrimitives(PlanarForm form);

/// @return The planar freedom F_i (lambda = 3) of @p form.
int planarFreedom(PlanarForm form);

/**
 * @brief How @p joint acts in the plane with normal @p normal (world frame).
 * @param[in] joint the joint.
 * @param[in] axisWorld the joint axis in the world frame at the assembled pose (unit).
 * @param[in] axis2World universal only: the second axis in the world frame (unit).
 * @param[in] normal the plane normal (unit).
 */
PlanarForm classifyPlanar(const Joint& joint, const Eigen::Vector3d& axisWorld, const Eigen::Vector3d& axis2World,
                          const Eigen::Vector3d& normal);

}  // namespace mobility_analysis
