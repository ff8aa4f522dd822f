#include "mobility_analysis/NaturalCoordinates.hpp"

#include <cmath>
#include <cstdio>

#include <Eigen/Dense>

#include "mobility_analysis/Tolerances.hpp"
#include "mobility_analysis/coordinates/ModelBuilder.hpp"

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

const char kAxisNames[] = {'x', 'y', 'z'};

bool isSpatialOnly(JointType type) {
  return type == JointType::Spherical || type == JointType::Universal || type == JointType::Cylindrical ||
         type == JointType::Planar;
}

/// Per connection, its worldAxes at the pose (zero for a coupling, which has no axis, and the second axis
/// zero but for a universal joint): computed once for the plane's normal and the joint elements.
using ConnectionAxes = std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>;

ConnectionAxes computeConnectionAxes(const Mechanism& mechanism, const LinkPoses& poses) {
  ConnectionAxes axes(mechanism.joints.size(), {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()});
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const Joint& joint = mechanism.joints[j];
    if (joint.kind == ConnectionKind::Coupling)
      continue;
    // The second axis is read for a universal joint only (classifyPlanar): the others skip its product.
    if (joint.type == JointType::Universal)
      axes[j] = worldAxes(joint, poses);
    else
      axes[j].first = worldAxis(joint, poses);
  }
  return axes;
}

/// A normal candidate: the first revolute axis, else the normal of two slide axes, else the root's z.
Eigen::Vector3d candidateNormal(const Mechanism& mechanism, const ConnectionAxes& axes) {
  std::vector<Eigen::Vector3d> slides;
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const Joint& joint = mechanism.joints[j];
    if (joint.kind == ConnectionKind::DistanceConstraint || joint.kind == ConnectionKind::Cable ||
        joint.kind == ConnectionKind::Coupling)
      continue;
    const Eigen::Vector3d axis = axes[j].first;
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

/// findPlaneNormal with the connections' axes at @p poses given.
std::optional<Eigen::Vector3d> findPlaneNormalOf(const Mechanism& mechanism, const LinkPoses& poses,
                                                 const ConnectionAxes& axes) {
  for (const Joint& joint : mechanism.joints) {
    if (joint.kind != ConnectionKind::DistanceConstraint && joint.kind != ConnectionKind::Cable &&
        joint.kind != ConnectionKind::Coupling && isSpatialOnly(joint.type)) {
      return std::nullopt;
    }
  }
  const Eigen::Vector3d normal = candidateNormal(mechanism, axes);
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const Joint& joint = mechanism.joints[j];
    if (joint.kind == ConnectionKind::DistanceConstraint || joint.kind == ConnectionKind::Cable ||
        joint.kind == ConnectionKind::Coupling)
      continue;
    if (classifyPlanar(joint, axes[j].first, axes[j].second, normal) == PlanarForm::Invalid) {
      return std::nullopt;
    }
  }
  // A distance constraint or cable carries no axis, so the test above says nothing about it: one that leaves
  // the plane (a truss mast's longeron) makes the model spatial, else a model of distance constraints alone
  // would be called planar whatever its shape.
  for (const Joint& joint : mechanism.joints) {
    if (joint.kind != ConnectionKind::DistanceConstraint && joint.kind != ConnectionKind::Cable)
      continue;
    const Eigen::Vector3d span =
        poses[joint.link1] * joint.frame1.translation() - poses[joint.link2] * joint.frame2.translation();
    if (std::abs(span.dot(normal)) > tolerances::kPlanarAxis * span.norm())
      return std::nullopt;
  }
  return normal;
}

}  // namespace

std::optional<Eigen::Vector3d> findPlaneNormal(const Mechanism& mechanism, const LinkPoses& poses) {
  return findPlaneNormalOf(mechanism, poses, computeConnectionAxes(mechanism, poses));
}

namespace {

/// Room for each body's elements at once (at most two a connection end, three of its own basis): one
/// allocation per body instead of three as its list grows.
void reserveBodyElements(const Mechanism& mechanism, CoordinateModel& model) {
  std::vector<size_t> room(mechanism.links.size(), 3);
  for (const Joint& joint : mechanism.joints) {
    if (joint.kind != ConnectionKind::Coupling) {
      room[joint.link1] += 2;
      room[joint.link2] += 2;
    }
  }
  for (size_t l = 0; l < mechanism.links.size(); ++l)
    model.bodyElements[l].reserve(room[l]);
}

}  // namespace

Result<CoordinateModel> buildCoordinateModel(const Mechanism& mechanism, const LinkPoses& poses,
                                             AnalysisMode mode, double characteristicLength) {
  CoordinateModel model;
  model.characteristicLength = characteristicLength;
  ConnectionAxes axes = computeConnectionAxes(mechanism, poses);
  const std::optional<Eigen::Vector3d> planeNormal = findPlaneNormalOf(mechanism, poses, axes);
  const bool planar = mode == AnalysisMode::Planar || (mode == AnalysisMode::Auto && planeNormal.has_value());
  model.mode = planar ? AnalysisMode::Planar : AnalysisMode::Spatial;
  model.dim = planar ? 2 : 3;
  model.lambda = planar ? 3 : 6;
  if (planar) {
    model.planeNormal = planeNormal ? *planeNormal : candidateNormal(mechanism, axes);
    // e1 along the root's x projected into the plane, so the planar coordinates read like the URDF's.
    Eigen::Vector3d e1 =
        Eigen::Vector3d::UnitX() - model.planeNormal.dot(Eigen::Vector3d::UnitX()) * model.planeNormal;
    if (e1.norm() < tolerances::kIndependentDirection) {
      e1 = model.planeNormal.unitOrthogonal();
    }
    model.planeE1 = e1.normalized();
    model.planeE2 = model.planeNormal.cross(model.planeE1);
  }
  model.bodyElements.assign(mechanism.links.size(), {});
  reserveBodyElements(mechanism, model);
  model.linkNames.reserve(mechanism.links.size());
  for (const Link& link : mechanism.links)
    model.linkNames.push_back(link.name);
  model.jointNames.reserve(mechanism.joints.size());
  for (const Joint& joint : mechanism.joints)
    model.jointNames.push_back(joint.name);
  model.jointFreedom.assign(mechanism.joints.size(), 0);
  model.jointActive.assign(mechanism.joints.size(), true);

  // The phases of ModelBuilder.hpp, in order; each lives in its own file under src/core/coordinates/.
  ModelBuilder builder(mechanism, poses, model);
  builder.axes = std::move(axes);
  if (std::optional<Diagnostic> error = addJointElements(builder))
    return *error;
  addBodyBases(builder);
  orderCoordinates(builder);
  addRigidLinkEquations(builder);
  addJointEquations(builder);
  addBoundaryEquations(builder);
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
      // A body whose elements are all collinear fixes its line but not its spin about it: turn the
      // reference's line onto the new one by the least rotation (h = sigma u v^T: local u goes to world v).
      const Eigen::Vector3d singular = svd.singularValues();
      if (singular(1) < 1e-9 * singular(0)) {
        const Eigen::Vector3d referenceLine = reference[b].linear() * svd.matrixU().col(0);
        rotation =
            Eigen::Quaterniond::FromTwoVectors(referenceLine, svd.matrixV().col(0)).toRotationMatrix() *
            reference[b].linear();
      }
    }
    poses[b].linear() = rotation;
    poses[b].translation() = (worldCentroid - rotation * localCentroid) * lc;
  }
  return poses;
}

std::string elementLabel(const CoordinateModel& model, int element) {
  const Element& e = model.elements[element];
  const std::string& link = model.linkNames[e.body];
  switch (e.role) {
    case ElementRole::JointPoint:
      return "P(" + link + "@" + model.jointNames[e.joint] + ")";
    case ElementRole::JointAxis:
      return "u(" + link + "@" + model.jointNames[e.joint] + ")";
    case ElementRole::JointSecondAxis:
      return "v(" + link + "@" + model.jointNames[e.joint] + ")";
    case ElementRole::Origin:
      return "O(" + link + ")";
    case ElementRole::Auxiliary1:
      return "aux1(" + link + ")";
    case ElementRole::Auxiliary2:
      return "aux2(" + link + ")";
  }
  return "?";
}

std::string describeEquation(const CoordinateModel& model, int row) {
  const ConstraintEquation& eq = model.equations[row];
  const bool planar = model.dim == 2;
  auto label = [&](int element) { return elementLabel(model, element); };
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
      std::string text = label(eq.target()) + " = ";
      if (eq.origin() >= 0)
        text += label(eq.origin()) + " + ";
      text += number(eq.coefficients.x()) + " " + name(eq.d1()) + " + " + number(eq.coefficients.y()) +
              (planar ? " J" + name(eq.d1())
                      : " " + name(eq.d2()) + " + " + number(eq.coefficients.z()) + " d1 x d2");
      return text + axis;
    }
    case EquationKind::CoincidentPoint:
      return label(eq.a.head) + " - " + label(eq.a.tail) + " = 0" + axis;
    case EquationKind::FixedCoordinate:
      return label(eq.a.head) + "_" + kAxisNames[eq.component] + " = " + number(eq.value) +
             (model.elements[eq.a.head].isPoint ? " Lc" : "");
    case EquationKind::Coupling: {
      const CouplingTerms& terms = model.couplings[eq.coupling()];
      auto value = [&](const JointValueOperand& o) {
        return o.prismatic ? "s(" + label(o.aHead) + " -> " + label(o.bHead) + ")"
                           : "angle(" + label(o.aHead) + ", " + label(o.bHead) + ")";
      };
      auto sum = [&](const JointValueOperand& first,
                     const std::vector<std::pair<JointValueOperand, double>>& more) {
        std::string text = value(first);
        for (const auto& [o, weight] : more)
          text += " + " + (weight == 1.0 ? "" : number(weight) + " ") + value(o);
        return more.empty() ? text : "(" + text + ")";
      };
      return sum(terms.follower, terms.moreFollowers) + " = " + number(terms.multiplier) + " " +
             sum(terms.leader, terms.moreLeaders) + " + " + number(terms.offset) +
             (terms.follower.prismatic ? " Lc" : " rad");
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
