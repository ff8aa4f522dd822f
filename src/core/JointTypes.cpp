#include "mobility_analysis/JointTypes.hpp"

#include <cmath>

#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

// One row per type; the equation counts of the primitives sum to 6 - F (spatial, lambda = 6).
const JointTypeSpec kJointTypes[] = {
    // Revolute: point coincidence 3 + axis parallelism 2 = 5 equations, leaves the turn about the axis.
    {JointType::Revolute, 1, {Primitive::CoincidentPoint, Primitive::ParallelAxis}, true},
    // Continuous: a revolute without limits; the same 5 equations.
    {JointType::Continuous, 1, {Primitive::CoincidentPoint, Primitive::ParallelAxis}, true},
    // Prismatic: axis parallelism 2 + point on the axis line 2 + no turn about the axis 1 = 5.
    {JointType::Prismatic, 1, {Primitive::ParallelAxis, Primitive::PointOnAxisLine, Primitive::FixedTwist}, true},
    // Cylindrical: axis parallelism 2 + point on the axis line 2 = 4, leaves turn and slide.
    {JointType::Cylindrical, 2, {Primitive::ParallelAxis, Primitive::PointOnAxisLine}, true},
    // Spherical: point coincidence 3, leaves three turns.
    {JointType::Spherical, 3, {Primitive::CoincidentPoint}, false},
    // Universal: point coincidence 3 + the angle between the two cross axes 1 = 4.
    {JointType::Universal, 2, {Primitive::CoincidentPoint, Primitive::AxisAngle}, true},
    // Planar (URDF): normals parallel 2 + point stays in the plane 1 = 3, leaves two slides and a turn.
    {JointType::Planar, 3, {Primitive::ParallelAxis, Primitive::PointInPlane}, true},
    // Fixed: point coincidence 3 + axis parallelism 2 + no turn 1 = 6.
    {JointType::Fixed, 0, {Primitive::CoincidentPoint, Primitive::ParallelAxis, Primitive::FixedTwist}, true},
    // Floating: constrains nothing (a link held only by loop joints hangs by it).
    {JointType::Floating, 6, {}, false},
};

// One row per primitive: equation counts (spatial, planar) and the joint elements it reads
// {points, axis1, bothAxes}.
const PrimitiveSpec kPrimitives[] = {
    // p_A - p_B = 0.
    {Primitive::CoincidentPoint, "coincident_point", 3, 2, {true, false, false}},
    // u_A x u_B = 0 on the non-degenerate components.
    {Primitive::ParallelAxis, "parallel_axis", 2, 1, {false, false, true}},
    // u_A x (p_B - p_A) = 0 on the non-degenerate components.
    {Primitive::PointOnAxisLine, "point_on_axis_line", 2, 1, {true, true, false}},
    // a.b, (a x b)_k or (a x b).c constant for directions of the two bodies' bases that see the turn.
    {Primitive::FixedTwist, "fixed_twist", 1, 1, {false, false, false}},
    // u_A.v_B = cos(gamma).
    {Primitive::AxisAngle, "axis_angle", 1, 0, {false, false, true}},
    // (p_B - p_A).u_A = 0.
    {Primitive::PointInPlane, "point_in_plane", 1, 0, {true, true, false}},
    // |p_B - p_A|^2 = L^2.
    {Primitive::Distance, "distance_constraint", 1, 1, {true, false, false}},
};

}  // namespace

const PrimitiveSpec& getPrimitiveSpec(Primitive primitive) {
  for (const PrimitiveSpec& spec : kPrimitives) {
    if (spec.primitive == primitive)
      return spec;
  }
  return kPrimitives[0];  // unreachable: every enumerator has a row
}

int equationCount(Primitive primitive, int dim) {
  const PrimitiveSpec& spec = getPrimitiveSpec(primitive);
  return dim == 3 ? spec.spatialEquations : spec.planarEquations;
}

const JointTypeSpec& getJointTypeSpec(JointType type) {
  for (const JointTypeSpec& spec : kJointTypes) {
    if (spec.type == type) {
      return spec;
    }
  }
  return kJointTypes[0];  // unreachable: every enumerator has a row
}

const std::vector<Primitive>& planarPrimitives(PlanarForm form) {
  // Static, as the spatial rows of kJointTypes: a copy per connection would be an allocation each.
  static const std::vector<Primitive> kPin = {Primitive::CoincidentPoint};
  static const std::vector<Primitive> kSlider = {Primitive::ParallelAxis, Primitive::PointOnAxisLine};
  static const std::vector<Primitive> kWeld = {Primitive::CoincidentPoint, Primitive::FixedTwist};
  static const std::vector<Primitive> kNone;
  switch (form) {
    case PlanarForm::Pin: return kPin;
    case PlanarForm::Slider: return kSlider;
    case PlanarForm::Weld: return kWeld;
    case PlanarForm::Free:
    case PlanarForm::Invalid: return kNone;
  }
  return kNone;
}

int planarFreedom(PlanarForm form) {
  switch (form) {
    case PlanarForm::Pin:
    case PlanarForm::Slider: return 1;
    case PlanarForm::Weld: return 0;
    case PlanarForm::Free: return 3;
    case PlanarForm::Invalid: return 0;
  }
  return 0;
}

PlanarForm classifyPlanar(const Joint& joint, const Eigen::Vector3d& axisWorld, const Eigen::Vector3d& axis2World,
                          const Eigen::Vector3d& normal) {
  const bool alongNormal = axisWorld.cross(normal).norm() < tolerances::kPlanarAxis;
  const bool inPlane = std::abs(axisWorld.dot(normal)) < tolerances::kPlanarAxis;
  switch (joint.type) {
    case JointType::Revolute:
    case JointType::Continuous: return alongNormal ? PlanarForm::Pin : PlanarForm::Invalid;
    case JointType::Prismatic: return inPlane ? PlanarForm::Slider : PlanarForm::Invalid;
    case JointType::Cylindrical:
      return alongNormal ? PlanarForm::Pin : (inPlane ? PlanarForm::Slider : PlanarForm::Invalid);
    case JointType::Spherical: return PlanarForm::Pin;
    case JointType::Universal:
      return (alongNormal || axis2World.cross(normal).norm() < tolerances::kPlanarAxis) ? PlanarForm::Pin
                                                                                          : PlanarForm::Weld;
    case JointType::Planar: return alongNormal ? PlanarForm::Free : PlanarForm::Invalid;
    case JointType::Fixed: return PlanarForm::Weld;
    case JointType::Floating: return PlanarForm::Free;
  }
  return PlanarForm::Invalid;
}

}  // namespace mobility_analysis
