#include <cmath>
#include <cstdio>

#include "mobility_analysis/Tolerances.hpp"
#include "mobility_analysis/coordinates/ModelBuilder.hpp"

namespace mobility_analysis {

namespace {

/// A cable's primitives: a taut passive cable is a distance constraint; an active or slack one constrains
/// nothing.
std::optional<Diagnostic> cablePrimitives(ModelBuilder& builder, size_t j) {
  const Joint& joint = builder.mechanism.joints[j];
  const LinkPoses& poses = builder.poses;
  const double distance =
      ((poses[joint.link1] * joint.frame1.translation()) - (poses[joint.link2] * joint.frame2.translation()))
          .norm();
  const bool taut = std::abs(distance - joint.length) <= tolerances::kCableTaut * joint.length;
  if (joint.cableType == CableType::Passive && distance > joint.length * (1.0 + tolerances::kCableTaut)) {
    char what[160];
    std::snprintf(what, sizeof(what), "its ends are %.6g m apart, longer than its length %.6g m", distance,
                  joint.length);
    return makeDiagnostic(builder.mechanism.file, "cable", joint.name, what);
  }
  if (joint.cableType == CableType::Active || !taut) {
    builder.model.jointActive[j] = false;
    builder.model.jointFreedom[j] = -1;
  }
  return std::nullopt;
}

}  // namespace

std::optional<Diagnostic> addJointElements(ModelBuilder& builder) {
  const Mechanism& mechanism = builder.mechanism;
  CoordinateModel& model = builder.model;
  const double lc = model.characteristicLength;
  builder.connections.assign(mechanism.joints.size(), ConnectionElements{});
  // At most four elements a connection and three a body (bases): reserved, not regrown.
  const size_t elements = 4 * mechanism.joints.size() + 3 * mechanism.links.size();
  model.elements.reserve(elements);
  builder.world.reserve(elements);
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const Joint& joint = mechanism.joints[j];
    ConnectionElements& c = builder.connections[j];
    if (joint.kind == ConnectionKind::Coupling) {
      model.jointFreedom[j] = model.lambda - 1;  // one equation on the elements of the two joints it couples
      continue;
    }
    const auto& axes = builder.axes[j];
    c.axisWorld = axes.first;
    // The connection's primitives in this mode: the joint-type table (JointTypes.cpp), or its planar form.
    if (joint.kind == ConnectionKind::DistanceConstraint || joint.kind == ConnectionKind::Cable) {
      if (joint.kind == ConnectionKind::Cable) {
        if (std::optional<Diagnostic> error = cablePrimitives(builder, j))
          return error;
        if (!model.jointActive[j])
          continue;
      }
      static const std::vector<Primitive> kDistance = {Primitive::Distance};
      c.primitives = kDistance;
      model.jointFreedom[j] = model.lambda - 1;
    } else if (builder.planar()) {
      const PlanarForm form = classifyPlanar(joint, axes.first, axes.second, model.planeNormal);
      if (form == PlanarForm::Invalid) {
        char what[240];
        std::snprintf(
            what, sizeof(what),
            "%s axis (%.3g, %.3g, %.3g) does not allow motion in the plane with normal (%.3g, %.3g, "
            "%.3g); analyse it with mode spatial",
            toString(joint.type), axes.first.x(), axes.first.y(), axes.first.z(), model.planeNormal.x(),
            model.planeNormal.y(), model.planeNormal.z());
        return makeDiagnostic(mechanism.file, toString(joint.kind), joint.name, what);
      }
      c.primitives = planarPrimitives(form);
      model.jointFreedom[j] = planarFreedom(form);
    } else {
      const JointTypeSpec& spec = getJointTypeSpec(joint.type);
      c.primitives = spec.spatialPrimitives;
      model.jointFreedom[j] = spec.spatialFreedom;
    }
    // The elements the primitives read: points at the joint on both sides, the axis on link1, and the axis
    // (universal: the second axis) on link2.
    bool needPoints = false, needAxes = false, needAxis1 = false;
    for (Primitive p : c.primitives) {
      const PrimitiveElements uses = primitiveElements(p);
      needPoints |= uses.points;
      needAxes |= uses.bothAxes;
      needAxis1 |= uses.axis1;
    }
    const int at = static_cast<int>(j);
    if (needPoints) {
      c.point1 =
          builder.addElement(joint.link1, true, joint.frame1.translation() / lc, ElementRole::JointPoint, at);
      c.point2 =
          builder.addElement(joint.link2, true, joint.frame2.translation() / lc, ElementRole::JointPoint, at);
    }
    if (needAxes || needAxis1) {
      c.axis1 = builder.addElement(joint.link1, false, joint.frame1.linear() * joint.axis,
                                   ElementRole::JointAxis, at);
    }
    if (needAxes) {
      const bool universal = joint.type == JointType::Universal;
      c.axis2 = builder.addElement(joint.link2, false,
                                   joint.frame2.linear() * (universal ? joint.axis2 : joint.axis),
                                   universal ? ElementRole::JointSecondAxis : ElementRole::JointAxis, at);
    }
  }
  return std::nullopt;
}

}  // namespace mobility_analysis
