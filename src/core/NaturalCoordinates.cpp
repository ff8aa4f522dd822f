#include "mobility_analysis/NaturalCoordinates.hpp"

#include <cmath>
#include <cstdio>

#include <Eigen/Dense>

#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

const char* toString(AnalysisMode mode) {
  switch (mode) {
    case AnalysisMode::Auto:
      return "auto";
    case AnalysisMode::Planar:
      return "planar";
    case AnalysisMode::Spatial:
      return "spatial";
  }
  return "unknown";
}

Result<AnalysisMode> parseAnalysisMode(const std::string& text) {
  if (text == "auto" || text.empty())
    return AnalysisMode::Auto;
  if (text == "planar")
    return AnalysisMode::Planar;
  if (text == "spatial")
    return AnalysisMode::Spatial;
  return makeDiagnostic("", "mode", text, "is not one of auto, planar, spatial");
}

const char* toString(EquationSource source) {
  switch (source) {
    case EquationSource::Link:
      return "link";
    case EquationSource::Joint:
      return "joint";
    case EquationSource::Boundary:
      return "boundary";
  }
  return "unknown";
}

const char* toString(EquationKind kind) {
  switch (kind) {
    case EquationKind::LinkDistance:
      return "distance";
    case EquationKind::UnitNorm:
      return "unit_norm";
    case EquationKind::LinkDotProduct:
      return "dot_product";
    case EquationKind::LinearCombination:
      return "linear_combination";
    case EquationKind::CoincidentPoint:
      return "coincident_point";
    case EquationKind::ParallelAxis:
      return "parallel_axis";
    case EquationKind::PointOnAxisLine:
      return "point_on_axis_line";
    case EquationKind::FixedTwist:
      return "fixed_twist";
    case EquationKind::AxisAngle:
      return "axis_angle";
    case EquationKind::PointInPlane:
      return "point_in_plane";
    case EquationKind::Distance:
      return "distance_constraint";
    case EquationKind::FixedCoordinate:
      return "fixed_coordinate";
    case EquationKind::Coupling:
      return "coupling";
  }
  return "unknown";
}

namespace {

/// A twist equation whose rate under the turn is below this (relative to its operands' lengths) does not see
/// the turn; the triple-product form is used instead [-].
constexpr double kDegenerateTwistRate = 1e-6;

const char kAxisNames[] = {'x', 'y', 'z'};

/// Joint axis (and universal second axis) of a connection in the world frame.
std::pair<Eigen::Vector3d, Eigen::Vector3d> worldAxes(const Joint& joint, const LinkPoses& poses) {
  const Eigen::Matrix3d r1 = poses[joint.link1].linear() * joint.frame1.linear();
  const Eigen::Matrix3d r2 = poses[joint.link2].linear() * joint.frame2.linear();
  return {r1 * joint.axis, r2 * joint.axis2};
}

bool isSpatialOnly(JointType type) {
  return type == JointType::Spherical || type == JointType::Universal || type == JointType::Cylindrical ||
         type == JointType::Planar;
}

/// A normal candidate: the first revolute axis, else the normal of two slide axes, else the root's z.
Eigen::Vector3d candidateNormal(const Mechanism& mechanism, const LinkPoses& poses) {
  std::vector<Eigen::Vector3d> slides;
  for (const Joint& joint : mechanism.joints) {
    if (joint.kind == ConnectionKind::DistanceConstraint || joint.kind == ConnectionKind::Cable ||
        joint.kind == ConnectionKind::Coupling)
      continue;
    const Eigen::Vector3d axis = worldAxes(joint, poses).first;
    if (joint.type == JointType::Revolute || joint.type == JointType::Continuous)
      return axis;
    if (joint.type == JointType::Prismatic)
      slides.push_back(axis);
  }
  for (size_t i = 0; i < slides.size(); ++i) {
    for (size_t j = i + 1; j < slides.size(); ++j) {
      const Eigen::Vector3d n = slides[i].cross(slides[j]);
      if (n.norm() > tolerances::kIndependentDirection)
        return n.normalized();
    }
  }
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  if (!slides.empty() && std::abs(slides[0].dot(n)) > tolerances::kPlanarAxis) {
    n = slides[0].unitOrthogonal();
  }
  return n;
}

struct ElementBuilder {
  const Mechanism& mechanism;
  const LinkPoses& poses;
  CoordinateModel& model;
  std::vector<Eigen::Vector3d> world;  ///< Element values at the pose (normalised, full 3-D).

  int add(int body, bool isPoint, const Eigen::Vector3d& local, std::string label) {
    Element e;
    e.body = body;
    e.isPoint = isPoint;
    e.local = local;
    e.label = std::move(label);
    model.elements.push_back(e);
    world.push_back(
        isPoint ? (poses[body].linear() * local + poses[body].translation() / model.characteristicLength)
                : (poses[body].linear() * local).eval());
    model.bodyElements[body].push_back(static_cast<int>(model.elements.size()) - 1);
    return static_cast<int>(model.elements.size()) - 1;
  }
};

/// Per connection: the elements its equations use on each side (-1 when not needed).
struct ConnectionElements {
  int point1 = -1, point2 = -1, axis1 = -1, axis2 = -1;
  std::vector<Primitive> primitives;
  Eigen::Vector3d axisWorld = Eigen::Vector3d::UnitZ();
};

/// Body basis of the rigid-link equations: base point p0 and directions d1, d2 (planar: d1).
struct BodyBasis {
  int p0 = -1;
  Direction d1, d2;
};

}  // namespace

std::optional<Eigen::Vector3d> findPlaneNormal(const Mechanism& mechanism, const LinkPoses& poses) {
  for (const Joint& joint : mechanism.joints) {
    if (joint.kind != ConnectionKind::DistanceConstraint && joint.kind != ConnectionKind::Cable &&
        joint.kind != ConnectionKind::Coupling && isSpatialOnly(joint.type)) {
      return std::nullopt;
    }
  }
  const Eigen::Vector3d normal = candidateNormal(mechanism, poses);
  for (const Joint& joint : mechanism.joints) {
    if (joint.kind == ConnectionKind::DistanceConstraint || joint.kind == ConnectionKind::Cable ||
        joint.kind == ConnectionKind::Coupling)
      continue;
    const auto axes = worldAxes(joint, poses);
    if (classifyPlanar(joint, axes.first, axes.second, normal) == PlanarForm::Invalid) {
      return std::nullopt;
    }
  }
  return normal;
}

Result<CoordinateModel> buildCoordinateModel(const Mechanism& mechanism, const LinkPoses& poses,
                                             AnalysisMode mode, double characteristicLength) {
  CoordinateModel model;
  model.characteristicLength = characteristicLength;
  const std::optional<Eigen::Vector3d> planeNormal = findPlaneNormal(mechanism, poses);
  const bool planar = mode == AnalysisMode::Planar || (mode == AnalysisMode::Auto && planeNormal.has_value());
  model.mode = planar ? AnalysisMode::Planar : AnalysisMode::Spatial;
  model.dim = planar ? 2 : 3;
  model.lambda = planar ? 3 : 6;
  const int dim = model.dim;
  if (planar) {
    model.planeNormal = planeNormal ? *planeNormal : candidateNormal(mechanism, poses);
    // e1 along the root's x projected into the plane, so the planar coordinates read like the URDF's.
    Eigen::Vector3d e1 =
        Eigen::Vector3d::UnitX() - model.planeNormal.dot(Eigen::Vector3d::UnitX()) * model.planeNormal;
    if (e1.norm() < tolerances::kIndependentDirection) {
      e1 = model.planeNormal.unitOrthogonal();
    }
    model.planeE1 = e1.normalized();
    model.planeE2 = model.planeNormal.cross(model.planeE1);
  }
  const double lc = characteristicLength;
  model.bodyElements.assign(mechanism.links.size(), {});
  model.jointFreedom.assign(mechanism.joints.size(), 0);
  model.jointActive.assign(mechanism.joints.size(), true);
  ElementBuilder builder{mechanism, poses, model, {}};

  // 1. Elements at the joints, and each connection's equation groups in this mode.
  std::vector<ConnectionElements> connections(mechanism.joints.size());
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const Joint& joint = mechanism.joints[j];
    ConnectionElements& c = connections[j];
    if (joint.kind == ConnectionKind::Coupling) {
      model.jointFreedom[j] = model.lambda - 1;  // one equation, on the elements of the two joints it couples
      continue;
    }
    const auto axes = worldAxes(joint, poses);
    c.axisWorld = axes.first;
    if (joint.kind == ConnectionKind::DistanceConstraint || joint.kind == ConnectionKind::Cable) {
      if (joint.kind == ConnectionKind::Cable) {
        const double distance = ((poses[joint.link1] * joint.frame1.translation()) -
                                 (poses[joint.link2] * joint.frame2.translation()))
                                    .norm();
        const bool taut = std::abs(distance - joint.length) <= tolerances::kCableTaut * joint.length;
        if (joint.cableType == CableType::Passive &&
            distance > joint.length * (1.0 + tolerances::kCableTaut)) {
          char what[160];
          std::snprintf(what, sizeof(what), "its ends are %.6g m apart, longer than its length %.6g m",
                        distance, joint.length);
          return makeDiagnostic(mechanism.file, "cable", joint.name, what);
        }
        if (joint.cableType == CableType::Active || !taut) {
          model.jointActive[j] = false;
          model.jointFreedom[j] = -1;
          continue;
        }
      }
      c.primitives = {Primitive::Distance};
      model.jointFreedom[j] = model.lambda - 1;
    } else if (planar) {
      const PlanarForm form = classifyPlanar(joint, axes.first, axes.second, model.planeNormal);
      if (form == PlanarForm::Invalid) {
        char what[240];
        std::snprintf(
            what, sizeof(what),
            "%s axis (%.3g, %.3g, %.3g) does not allow motion in the plane with normal (%.3g, %.3g, %.3g); "
            "analyse it with mode spatial",
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
    bool needPoints = false, needAxes = false, needAxis1 = false;
    for (Primitive p : c.primitives) {
      needPoints |= p == Primitive::CoincidentPoint || p == Primitive::PointOnAxisLine ||
                    p == Primitive::PointInPlane || p == Primitive::Distance;
      needAxes |= p == Primitive::ParallelAxis || p == Primitive::AxisAngle;
      needAxis1 |= p == Primitive::PointOnAxisLine || p == Primitive::PointInPlane;
    }
    const std::string& n1 = mechanism.links[joint.link1].name;
    const std::string& n2 = mechanism.links[joint.link2].name;
    if (needPoints) {
      c.point1 =
          builder.add(joint.link1, true, joint.frame1.translation() / lc, "P(" + n1 + "@" + joint.name + ")");
      c.point2 =
          builder.add(joint.link2, true, joint.frame2.translation() / lc, "P(" + n2 + "@" + joint.name + ")");
    }
    if (needAxes || needAxis1) {
      c.axis1 = builder.add(joint.link1, false, joint.frame1.linear() * joint.axis,
                            "u(" + n1 + "@" + joint.name + ")");
    }
    if (needAxes) {
      const bool universal = joint.type == JointType::Universal;
      c.axis2 =
          builder.add(joint.link2, false, joint.frame2.linear() * (universal ? joint.axis2 : joint.axis),
                      (universal ? "v(" : "u(") + n2 + "@" + joint.name + ")");
    }
  }

  // In the plane an element is its projection; vectors along the normal carry no planar information.
  auto coordinates = [&](int e) -> Eigen::Vector3d {
    const Eigen::Vector3d& w = builder.world[e];
    return planar ? Eigen::Vector3d(w.dot(model.planeE1), w.dot(model.planeE2), 0.0) : w;
  };
  auto directionValue = [&](const Direction& d) -> Eigen::Vector3d {
    return d.tail < 0 ? coordinates(d.head) : (coordinates(d.head) - coordinates(d.tail)).eval();
  };
  // 2. Body bases: p0 and the best-conditioned directions; auxiliary unit vectors where the joints give too
  // few.
  std::vector<BodyBasis> bases(mechanism.links.size());
  for (size_t b = 0; b < mechanism.links.size(); ++b) {
    const int body = static_cast<int>(b);
    const std::string& name = mechanism.links[b].name;
    BodyBasis& basis = bases[b];
    for (int e : model.bodyElements[b]) {
      if (model.elements[e].isPoint) {
        basis.p0 = e;
        break;
      }
    }
    if (basis.p0 < 0) {
      basis.p0 = builder.add(body, true, Eigen::Vector3d::Zero(), "O(" + name + ")");
    }
    std::vector<Direction> candidates;
    for (int e : model.bodyElements[b]) {
      if (e == basis.p0)
        continue;
      candidates.push_back(Direction{e, model.elements[e].isPoint ? basis.p0 : -1});
    }
    double best = tolerances::kIndependentDirection;
    for (const Direction& d : candidates) {
      const double norm = directionValue(d).norm();
      if (norm > best * (1.0 + 1e-9)) {
        best = norm;
        basis.d1 = d;
      }
    }
    const Eigen::Matrix3d rotation = poses[b].linear();
    if (basis.d1.head < 0) {
      // No direction from the joints (a body on one pin or ball): a unit vector of its own frame.
      Eigen::Vector3d local = Eigen::Vector3d::UnitX();
      if (planar) {
        const Eigen::Vector3d n = rotation.transpose() * model.planeNormal;
        local = (local - n.dot(local) * n).norm() > 0.5 ? (local - n.dot(local) * n).normalized().eval()
                                                        : n.unitOrthogonal();
      }
      basis.d1 = Direction{builder.add(body, false, local, "aux1(" + name + ")"), -1};
    }
    if (!planar) {
      const Eigen::Vector3d d1 = directionValue(basis.d1);
      double bestSine = tolerances::kIndependentDirection;
      for (const Direction& d : candidates) {
        if (d.head == basis.d1.head)
          continue;
        const Eigen::Vector3d v = directionValue(d);
        const double perpendicular = d1.cross(v).norm() / d1.norm();
        const double sine = perpendicular / std::max(v.norm(), 1e-300);
        if (sine > tolerances::kIndependentDirection && perpendicular > bestSine * (1.0 + 1e-9)) {
          bestSine = perpendicular;
          basis.d2 = d;
        }
      }
      if (basis.d2.head < 0) {
        // A rod, or a body whose joint elements are all on one line: its spin needs a second direction.
        const Eigen::Vector3d worldAux = d1.unitOrthogonal();
        basis.d2 =
            Direction{builder.add(body, false, rotation.transpose() * worldAux, "aux2(" + name + ")"), -1};
      }
    }
  }

  // 3. Coordinates: elements grouped by body (document order of links), dim numbers each.
  {
    int offset = 0;
    std::vector<Element> ordered;
    std::vector<int> newIndex(model.elements.size());
    std::vector<Eigen::Vector3d> orderedWorld;
    for (size_t b = 0; b < mechanism.links.size(); ++b) {
      for (int e : model.bodyElements[b]) {
        newIndex[e] = static_cast<int>(ordered.size());
        ordered.push_back(model.elements[e]);
        ordered.back().offset = offset;
        orderedWorld.push_back(builder.world[e]);
        offset += dim;
      }
    }
    auto remap = [&](Direction& d) {
      if (d.head >= 0)
        d.head = newIndex[d.head];
      if (d.tail >= 0)
        d.tail = newIndex[d.tail];
    };
    for (BodyBasis& basis : bases) {
      basis.p0 = newIndex[basis.p0];
      remap(basis.d1);
      remap(basis.d2);
    }
    for (ConnectionElements& c : connections) {
      for (int* e : {&c.point1, &c.point2, &c.axis1, &c.axis2}) {
        if (*e >= 0)
          *e = newIndex[*e];
      }
    }
    for (std::vector<int>& list : model.bodyElements) {
      for (int& e : list)
        e = newIndex[e];
    }
    model.elements = std::move(ordered);
    builder.world = std::move(orderedWorld);
    model.q0.resize(offset);
    for (size_t e = 0; e < model.elements.size(); ++e) {
      model.q0.segment(model.elements[e].offset, dim) = coordinates(static_cast<int>(e)).head(dim);
    }
  }

  auto addEquation = [&](ConstraintEquation eq) { model.equations.push_back(std::move(eq)); };

  // A coupled tree joint's value from its elements (CouplingEquation.hpp): a prismatic joint's two points on
  // its axis; a revolute joint's axis (planar: the normal) and the direction of each body most normal to it.
  auto makeOperand = [&](int t) {
    const Joint& tree = mechanism.joints[t];
    const ConnectionElements& ct = connections[t];
    JointValueOperand o;
    o.prismatic = tree.type == JointType::Prismatic;
    o.axis = planar && !o.prismatic ? -1 : ct.axis1;
    if (o.prismatic) {
      o.aHead = ct.point1;
      o.bHead = ct.point2;
      return o;
    }
    const Eigen::Vector3d u = o.axis < 0 ? Eigen::Vector3d::UnitZ() : coordinates(o.axis).normalized().eval();
    auto mostNormal = [&](const BodyBasis& basis) {
      Direction best = basis.d1;
      double bestSine = -1.0;
      for (const Direction& d : {basis.d1, basis.d2}) {
        if (d.head < 0)
          continue;
        const Eigen::Vector3d v = directionValue(d);
        const double sine = (v - v.dot(u) * u).norm() / std::max(v.norm(), 1e-300);
        if (sine > bestSine) {
          bestSine = sine;
          best = d;
        }
      }
      return best;
    };
    const Direction a = mostNormal(bases[tree.link1]);
    const Direction b = mostNormal(bases[tree.link2]);
    o.aHead = a.head;
    o.aTail = a.tail;
    o.bHead = b.head;
    o.bTail = b.tail;
    // theta_0: the angle between a and b with b turned back to the joint's zero (its two frames aligned).
    const Eigen::Matrix3d aligned = poses[tree.link1].linear() * tree.frame1.linear() *
                                    tree.frame2.linear().transpose() * poses[tree.link2].linear().transpose();
    const Eigen::Vector3d bWorld = b.tail < 0 ? builder.world[b.head] : (builder.world[b.head] - builder.world[b.tail]).eval();
    const Eigen::Vector3d bRest =
        planar ? Eigen::Vector3d((aligned * bWorld).dot(model.planeE1), (aligned * bWorld).dot(model.planeE2), 0.0)
               : (aligned * bWorld).eval();
    const Eigen::Vector3d av = directionValue(a);
    o.rest = std::atan2(u.dot(av.cross(bRest)), av.dot(bRest) - av.dot(u) * bRest.dot(u));
    return o;
  };
  auto makeCouplingTerms = [&](const Joint& coupling) {
    CouplingTerms terms;
    terms.follower = makeOperand(coupling.follower);
    terms.leader = makeOperand(coupling.leader);
    // v_f [SI] = m v_l [SI] + c, with prismatic values in normalised lengths: scale by lc.
    const double followerScale = terms.follower.prismatic ? lc : 1.0;
    const double leaderScale = terms.leader.prismatic ? lc : 1.0;
    terms.multiplier = coupling.multiplier * leaderScale / followerScale;
    terms.offset = coupling.offset / followerScale;
    return terms;
  };

  // 4. Rigid-link equations (links in document order): basis dot products, then linear combinations.
  for (size_t b = 0; b < mechanism.links.size(); ++b) {
    const BodyBasis& basis = bases[b];
    std::vector<Direction> dirs = {basis.d1};
    if (!planar)
      dirs.push_back(basis.d2);
    for (size_t i = 0; i < dirs.size(); ++i) {
      for (size_t j = i; j < dirs.size(); ++j) {
        ConstraintEquation eq;
        eq.source = EquationSource::Link;
        eq.element = static_cast<int>(b);
        eq.form = EquationForm::Dot;
        eq.a = dirs[i];
        eq.b = dirs[j];
        eq.value = directionValue(dirs[i]).dot(directionValue(dirs[j]));
        if (i == j && dirs[i].tail < 0) {
          eq.kind = EquationKind::UnitNorm;
          eq.value = 1.0;
        } else if (i == j) {
          eq.kind = EquationKind::LinkDistance;
        } else {
          eq.kind = EquationKind::LinkDotProduct;
        }
        addEquation(eq);
      }
    }
    const Eigen::Vector3d d1 = directionValue(basis.d1);
    Eigen::Matrix3d frame;
    if (planar) {
      frame.col(0) = d1;
      frame.col(1) = Eigen::Vector3d(-d1.y(), d1.x(), 0.0);
      frame.col(2) = Eigen::Vector3d::UnitZ();
    } else {
      const Eigen::Vector3d d2 = directionValue(basis.d2);
      frame.col(0) = d1;
      frame.col(1) = d2;
      frame.col(2) = d1.cross(d2);
    }
    const Eigen::PartialPivLU<Eigen::Matrix3d> lu(frame);
    for (int e : model.bodyElements[b]) {
      if (e == basis.p0 || e == basis.d1.head || (!planar && e == basis.d2.head))
        continue;
      const bool isPoint = model.elements[e].isPoint;
      const Eigen::Vector3d rhs = isPoint ? (coordinates(e) - coordinates(basis.p0)).eval() : coordinates(e);
      const Eigen::Vector3d coefficients = lu.solve(rhs);
      for (int k = 0; k < dim; ++k) {
        ConstraintEquation eq;
        eq.source = EquationSource::Link;
        eq.element = static_cast<int>(b);
        eq.kind = EquationKind::LinearCombination;
        eq.form = EquationForm::Combination;
        eq.component = k;
        eq.target = e;
        eq.origin = isPoint ? basis.p0 : -1;
        eq.d1 = basis.d1;
        eq.d2 = basis.d2;
        eq.coefficients = coefficients;
        if (planar)
          eq.coefficients.z() = 0.0;
        addEquation(eq);
      }
    }
  }

  // 5. Joint equations: tree joints, distance constraints, cables, loop joints (the loader's order).
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    if (!model.jointActive[j])
      continue;
    const Joint& joint = mechanism.joints[j];
    const ConnectionElements& c = connections[j];
    auto base = [&](EquationKind kind, EquationForm form) {
      ConstraintEquation eq;
      eq.source = EquationSource::Joint;
      eq.element = static_cast<int>(j);
      eq.kind = kind;
      eq.form = form;
      return eq;
    };
    if (joint.kind == ConnectionKind::Coupling) {
      ConstraintEquation eq = base(EquationKind::Coupling, EquationForm::Coupling);
      eq.coupling = static_cast<int>(model.couplings.size());
      model.couplings.push_back(makeCouplingTerms(joint));
      addEquation(eq);
      continue;
    }
    // Cross-product components: drop the one along the axis' largest component (it is degenerate there).
    auto crossComponents = [&](int axisElement) {
      std::vector<int> components;
      if (planar)
        return std::vector<int>{2};
      const Eigen::Vector3d axis = coordinates(axisElement);
      int largest = 0;
      axis.cwiseAbs().maxCoeff(&largest);
      for (int k = 0; k < 3; ++k) {
        if (k != largest)
          components.push_back(k);
      }
      return components;
    };
    for (Primitive primitive : c.primitives) {
      switch (primitive) {
        case Primitive::CoincidentPoint:
          for (int k = 0; k < dim; ++k) {
            ConstraintEquation eq = base(EquationKind::CoincidentPoint, EquationForm::Component);
            eq.a = Direction{c.point1, c.point2};
            eq.component = k;
            addEquation(eq);
          }
          break;
        case Primitive::ParallelAxis:
        case Primitive::PointOnAxisLine:
          for (int k : crossComponents(c.axis1)) {
            const bool parallel = primitive == Primitive::ParallelAxis;
            ConstraintEquation eq = base(
                parallel ? EquationKind::ParallelAxis : EquationKind::PointOnAxisLine, EquationForm::Cross);
            eq.a = Direction{c.axis1, -1};
            eq.b = parallel ? Direction{c.axis2, -1} : Direction{c.point2, c.point1};
            eq.component = k;
            addEquation(eq);
          }
          break;
        case Primitive::FixedTwist: {
          // One direction of each body whose product changes when one turns about the axis:
          // d(a.b)/d(theta) = n.(b x a), n the axis (planar: the normal).
          const Eigen::Vector3d n = planar ? Eigen::Vector3d::UnitZ() : coordinates(c.axis1).normalized();
          const BodyBasis& basisA = bases[joint.link1];
          const BodyBasis& basisB = bases[joint.link2];
          std::vector<Direction> dirsA = {basisA.d1}, dirsB = {basisB.d1};
          if (!planar) {
            dirsA.push_back(basisA.d2);
            dirsB.push_back(basisB.d2);
          }
          // B's directions as they are when the two joint frames are aligned (the joint's rest orientation).
          const Eigen::Matrix3d aligned = poses[joint.link1].linear() * joint.frame1.linear() *
                                          joint.frame2.linear().transpose() *
                                          poses[joint.link2].linear().transpose();
          auto project = [&](const Eigen::Vector3d& w) {
            return planar ? Eigen::Vector3d(w.dot(model.planeE1), w.dot(model.planeE2), 0.0) : w;
          };
          auto worldOf = [&](const Direction& d) {
            return d.tail < 0 ? builder.world[d.head]
                              : (builder.world[d.head] - builder.world[d.tail]).eval();
          };
          // Two candidate forms per pair: a.b (rate n.(b x a)) and (a x b)_k (rate (n (a.b) - b (a.n))_k), so
          // a pair of directions parallel to each other (two axes along the same normal) still sees the turn.
          double best = -1.0;
          ConstraintEquation eq = base(EquationKind::FixedTwist, EquationForm::Dot);
          for (const Direction& da : dirsA) {
            for (const Direction& db : dirsB) {
              const Eigen::Vector3d va = directionValue(da);
              const Eigen::Vector3d vb = project(aligned * worldOf(db));
              const double scale = va.norm() * vb.norm();
              const double dotRate = std::abs(n.dot(vb.cross(va))) / scale;
              if (dotRate > best * (1.0 + 1e-9)) {
                best = dotRate;
                eq.form = EquationForm::Dot;
                eq.a = da;
                eq.b = db;
                eq.value = va.dot(vb);
              }
              // In space a cross component is invariant under a rigid motion of the whole mechanism only
              // where a x b = 0, so that form is used for parallel pairs alone (in the plane it always is).
              const bool parallel = va.cross(vb).norm() <= 1e-9 * scale;
              const Eigen::Vector3d crossRate = (n * va.dot(vb) - vb * va.dot(n)) / scale;
              for (int k = planar ? 2 : 0; k < 3 && (planar || parallel); ++k) {
                const double rate = planar ? std::abs(va.dot(vb)) / scale : std::abs(crossRate[k]);
                if (rate > best * (1.0 + 1e-9)) {
                  best = rate;
                  eq.form = EquationForm::Cross;
                  eq.component = k;
                  eq.a = da;
                  eq.b = db;
                  eq.value = planar ? va.cross(vb)[k] : 0.0;
                }
              }
            }
          }
          // When every direction of both bodies lies in one plane with the axis (links that only carry
          // sliders along their plane, analysed in space), no pair sees the turn: the normal of one body's
          // two directions does, as the triple product (a x b).c with the other body's direction c.
          if (!planar && best < kDegenerateTwistRate && dirsA.size() == 2 && dirsB.size() == 2) {
            auto consider = [&](const Direction& a, const Direction& b, const Direction& c,
                                const Eigen::Vector3d& va, const Eigen::Vector3d& vb,
                                const Eigen::Vector3d& vc, bool pairTurns) {
              const Eigen::Vector3d normal = va.cross(vb);
              const double scale = va.norm() * vb.norm() * vc.norm();
              // The turning body's vectors move by n x v: the pair's normal by n x normal, or c by n x c.
              const double rate =
                  std::abs(pairTurns ? n.cross(normal).dot(vc) : normal.dot(n.cross(vc))) / scale;
              if (rate > best * (1.0 + 1e-9)) {
                best = rate;
                eq.form = EquationForm::Triple;
                eq.a = a;
                eq.b = b;
                eq.c = c;
                eq.value = normal.dot(vc);
              }
            };
            const Eigen::Vector3d a1 = directionValue(dirsA[0]), a2 = directionValue(dirsA[1]);
            const Eigen::Vector3d b1 = project(aligned * worldOf(dirsB[0]));
            const Eigen::Vector3d b2 = project(aligned * worldOf(dirsB[1]));
            for (int i = 0; i < 2; ++i) {
              consider(dirsA[0], dirsA[1], dirsB[i], a1, a2, i == 0 ? b1 : b2, false);
              consider(dirsB[0], dirsB[1], dirsA[i], b1, b2, i == 0 ? a1 : a2, true);
            }
          }
          addEquation(eq);
          break;
        }
        case Primitive::AxisAngle: {
          ConstraintEquation eq = base(EquationKind::AxisAngle, EquationForm::Dot);
          eq.a = Direction{c.axis1, -1};
          eq.b = Direction{c.axis2, -1};
          eq.value = joint.axis.dot(joint.axis2);
          addEquation(eq);
          break;
        }
        case Primitive::PointInPlane: {
          ConstraintEquation eq = base(EquationKind::PointInPlane, EquationForm::Dot);
          eq.a = Direction{c.point2, c.point1};
          eq.b = Direction{c.axis1, -1};
          eq.value = 0.0;
          addEquation(eq);
          break;
        }
        case Primitive::Distance: {
          ConstraintEquation eq = base(EquationKind::Distance, EquationForm::Dot);
          eq.a = Direction{c.point2, c.point1};
          eq.b = eq.a;
          const double length =
              joint.kind == ConnectionKind::Cable ? joint.length / lc : directionValue(eq.a).norm();
          eq.value = length * length;
          addEquation(eq);
          break;
        }
      }
    }
  }

  // 6. Boundary equations: the ground's lambda rigid freedoms, fixed by lambda of its coordinates.
  {
    const int root = mechanism.rootLink;
    const BodyBasis& basis = bases[root];
    auto fix = [&](int element, int k) {
      ConstraintEquation eq;
      eq.source = EquationSource::Boundary;
      eq.element = root;
      eq.kind = EquationKind::FixedCoordinate;
      eq.form = EquationForm::Component;
      eq.a = Direction{element, -1};
      eq.component = k;
      eq.value = coordinates(element)[k];
      addEquation(eq);
    };
    for (int k = 0; k < dim; ++k) {
      fix(basis.p0, k);
    }
    // Rotation omega moves a direction d by omega x d: coordinate k of d's head changes by omega.(d x e_k).
    // Pick the coordinates whose rows are best conditioned (largest |det|).
    if (planar) {
      const Eigen::Vector3d d1 = directionValue(basis.d1);
      fix(basis.d1.head, std::abs(d1.y()) >= std::abs(d1.x()) ? 0 : 1);
    } else {
      std::vector<std::pair<int, int>> rows;
      std::vector<Eigen::Vector3d> gradients;
      for (const Direction& d : {basis.d1, basis.d2}) {
        const Eigen::Vector3d v = directionValue(d);
        for (int k = 0; k < 3; ++k) {
          rows.emplace_back(d.head, k);
          gradients.push_back(v.cross(Eigen::Vector3d::Unit(k)));
        }
      }
      double best = -1.0;
      std::array<int, 3> chosen{0, 1, 2};
      for (int r0 = 0; r0 < 6; ++r0) {
        for (int r1 = r0 + 1; r1 < 6; ++r1) {
          for (int r2 = r1 + 1; r2 < 6; ++r2) {
            const double det = std::abs(gradients[r0].dot(gradients[r1].cross(gradients[r2])));
            if (det > best * (1.0 + 1e-12)) {
              best = det;
              chosen = {r0, r1, r2};
            }
          }
        }
      }
      for (int r : chosen) {
        fix(rows[r].first, rows[r].second);
      }
    }
  }
  return model;
}

Eigen::VectorXd computeCoordinates(const CoordinateModel& model, const LinkPoses& poses) {
  Eigen::VectorXd q(model.numCoordinates());
  for (const Element& e : model.elements) {
    const Eigen::Vector3d w =
        e.isPoint
            ? (poses[e.body].linear() * e.local + poses[e.body].translation() / model.characteristicLength)
                  .eval()
            : (poses[e.body].linear() * e.local).eval();
    if (model.dim == 3) {
      q.segment<3>(e.offset) = w;
    } else {
      q.segment<2>(e.offset) = Eigen::Vector2d(w.dot(model.planeE1), w.dot(model.planeE2));
    }
  }
  return q;
}

LinkPoses recoverPoses(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const LinkPoses& reference) {
  LinkPoses poses = reference;
  const double lc = model.characteristicLength;
  for (size_t b = 0; b < model.bodyElements.size(); ++b) {
    // Kabsch: the rotation R minimising sum |R local - world|^2 over the body's points (about their centroid)
    // and unit vectors, then the translation that matches the centroid.
    std::vector<Eigen::Vector3d> localPoints, worldPoints, localVectors, worldVectors;
    for (int e : model.bodyElements[b]) {
      const Element& element = model.elements[e];
      Eigen::Vector3d w = Eigen::Vector3d::Zero();
      if (model.dim == 3) {
        w = q.segment<3>(element.offset);
      } else {
        const Eigen::Vector3d ref = element.isPoint ? (reference[b] * (element.local * lc)) / lc
                                                    : (reference[b].linear() * element.local).eval();
        w = q(element.offset) * model.planeE1 + q(element.offset + 1) * model.planeE2 +
            ref.dot(model.planeNormal) * model.planeNormal;
      }
      (element.isPoint ? localPoints : localVectors).push_back(element.local);
      (element.isPoint ? worldPoints : worldVectors).push_back(w);
    }
    if (localPoints.empty())
      continue;
    Eigen::Vector3d localCentroid = Eigen::Vector3d::Zero(), worldCentroid = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < localPoints.size(); ++i) {
      localCentroid += localPoints[i];
      worldCentroid += worldPoints[i];
    }
    localCentroid /= static_cast<double>(localPoints.size());
    worldCentroid /= static_cast<double>(localPoints.size());
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < localPoints.size(); ++i) {
      h += (localPoints[i] - localCentroid) * (worldPoints[i] - worldCentroid).transpose();
    }
    for (size_t i = 0; i < localVectors.size(); ++i) {
      h += localVectors[i] * worldVectors[i].transpose();
    }
    Eigen::Matrix3d rotation = reference[b].linear();
    if (h.norm() > tolerances::kZeroVector) {
      const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
      Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
      d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
      rotation = svd.matrixV() * d * svd.matrixU().transpose();
      // A body whose elements are all collinear leaves its spin undetermined: keep the reference's.
      const Eigen::Vector3d singular = svd.singularValues();
      if (singular(1) < 1e-9 * singular(0)) {
        rotation = reference[b].linear();
      }
    }
    poses[b].linear() = rotation;
    poses[b].translation() = (worldCentroid - rotation * localCentroid) * lc;
  }
  return poses;
}

std::string describeEquation(const CoordinateModel& model, int row) {
  const ConstraintEquation& eq = model.equations[row];
  const bool planar = model.dim == 2;
  auto label = [&](int element) { return model.elements[element].label; };
  auto name = [&](const Direction& d) {
    return d.tail < 0 ? label(d.head) : "(" + label(d.head) + " - " + label(d.tail) + ")";
  };
  auto number = [](double value) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.6g", value);
    return std::string(text);
  };
  const std::string axis = std::string(" (") + kAxisNames[eq.component] + ")";
  switch (eq.kind) {
    case EquationKind::UnitNorm:
      return name(eq.a) + "." + name(eq.a) + " = 1";
    case EquationKind::LinkDistance:
    case EquationKind::Distance:
      return "|" + label(eq.a.head) + " - " + label(eq.a.tail) + "|^2 = " + number(eq.value) + " Lc^2";
    case EquationKind::LinearCombination: {
      std::string text = label(eq.target) + " = ";
      if (eq.origin >= 0)
        text += label(eq.origin) + " + ";
      text += number(eq.coefficients.x()) + " " + name(eq.d1) + " + " + number(eq.coefficients.y()) +
              (planar ? " J" + name(eq.d1)
                      : " " + name(eq.d2) + " + " + number(eq.coefficients.z()) + " d1 x d2");
      return text + axis;
    }
    case EquationKind::CoincidentPoint:
      return label(eq.a.head) + " - " + label(eq.a.tail) + " = 0" + axis;
    case EquationKind::FixedCoordinate:
      return label(eq.a.head) + "_" + kAxisNames[eq.component] + " = " + number(eq.value) +
             (model.elements[eq.a.head].isPoint ? " Lc" : "");
    case EquationKind::Coupling: {
      const CouplingTerms& terms = model.couplings[eq.coupling];
      auto value = [&](const JointValueOperand& o) {
        return o.prismatic ? "s(" + label(o.aHead) + " -> " + label(o.bHead) + ")"
                           : "angle(" + label(o.aHead) + ", " + label(o.bHead) + ")";
      };
      return value(terms.follower) + " = " + number(terms.multiplier) + " " + value(terms.leader) + " + " +
             number(terms.offset) + (terms.follower.prismatic ? " Lc" : " rad");
    }
    default:
      break;
  }
  // The remaining kinds read as their algebraic form.
  if (eq.form == EquationForm::Triple) {
    return "(" + name(eq.a) + " x " + name(eq.b) + ")." + name(eq.c) + " = " + number(eq.value);
  }
  if (eq.form == EquationForm::Cross) {
    return "(" + name(eq.a) + " x " + name(eq.b) + ")" +
           (planar ? std::string("") : std::string("_") + kAxisNames[eq.component]) + " = " +
           number(eq.value);
  }
  return name(eq.a) + "." + name(eq.b) + " = " + number(eq.value);
}

}  // namespace mobility_analysis
