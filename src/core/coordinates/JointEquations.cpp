#include <cmath>

#include "mobility_analysis/coordinates/ModelBuilder.hpp"

namespace mobility_analysis {

namespace {

/// A twist equation whose rate under the turn is below this (relative to its operands' lengths) does not see
/// the turn; the triple-product form is used instead [-].
constexpr double kDegenerateTwistRate = 1e-6;

/// What a primitive's writer gets: the builder, the joint and its elements, and where equations go.
struct JointContext {
  ModelBuilder& builder;
  int joint;
  const ConnectionElements& elements;

  const Joint& spec() const { return builder.mechanism.joints[joint]; }

  ConstraintEquation equation(EquationKind kind, EquationForm form) const {
    ConstraintEquation eq;
    eq.source = EquationSource::Joint;
    eq.element = joint;
    eq.kind = kind;
    eq.form = form;
    return eq;
  }

  void add(const ConstraintEquation& eq) const { builder.model.equations.push_back(eq); }

  /// Cross-product components: drop the one along the axis' largest component (it is degenerate there).
  std::vector<int> crossComponents(int axisElement) const {
    if (builder.planar())
      return {2};
    const Eigen::Vector3d axis = builder.coordinates(axisElement);
    int largest = 0;
    axis.cwiseAbs().maxCoeff(&largest);
    std::vector<int> components;
    for (int k = 0; k < 3; ++k) {
      if (k != largest)
        components.push_back(k);
    }
    return components;
  }
};

/// p_A - p_B = 0, one Component equation per coordinate.
void writeCoincidentPoint(const JointContext& c) {
  for (int k = 0; k < c.builder.model.dim; ++k) {
    ConstraintEquation eq = c.equation(EquationKind::CoincidentPoint, EquationForm::Component);
    eq.a = Direction{c.elements.point1, c.elements.point2};
    eq.component = k;
    c.add(eq);
  }
}

/// u_A x u_B = 0 (parallel) or u_A x (p_B - p_A) = 0 (on the line), on the non-degenerate components.
void writeCrossPrimitive(const JointContext& c, bool parallel) {
  for (int k : c.crossComponents(c.elements.axis1)) {
    ConstraintEquation eq = c.equation(parallel ? EquationKind::ParallelAxis : EquationKind::PointOnAxisLine,
                                       EquationForm::Cross);
    eq.a = Direction{c.elements.axis1, -1};
    eq.b = parallel ? Direction{c.elements.axis2, -1} : Direction{c.elements.point2, c.elements.point1};
    eq.component = k;
    c.add(eq);
  }
}

void writeParallelAxis(const JointContext& c) {
  writeCrossPrimitive(c, true);
}
void writePointOnAxisLine(const JointContext& c) {
  writeCrossPrimitive(c, false);
}

/**
 * No turn about the axis: one equation between a direction of each body's basis whose value changes when one
 * body turns about the axis n. Candidates: a.b (rate n.(b x a)), (a x b)_k for parallel pairs (rate
 * (n (a.b) - b (a.n))_k; in the plane always), and (a x b).c when every direction lies in one plane with
 * the axis. The candidate with the largest rate wins.
 */
void writeFixedTwist(const JointContext& c) {
  ModelBuilder& builder = c.builder;
  const bool planar = builder.planar();
  const Joint& joint = c.spec();
  const Eigen::Vector3d n =
      planar ? Eigen::Vector3d::UnitZ() : builder.coordinates(c.elements.axis1).normalized();
  const BodyBasis& basisA = builder.bases[joint.link1];
  const BodyBasis& basisB = builder.bases[joint.link2];
  std::vector<Direction> dirsA = {basisA.d1}, dirsB = {basisB.d1};
  if (!planar) {
    dirsA.push_back(basisA.d2);
    dirsB.push_back(basisB.d2);
  }
  // B's directions as they are when the two joint frames are aligned (the joint's rest orientation).
  const LinkPoses& poses = builder.poses;
  const Eigen::Matrix3d aligned = poses[joint.link1].linear() * joint.frame1.linear() *
                                  joint.frame2.linear().transpose() * poses[joint.link2].linear().transpose();
  double best = -1.0;
  ConstraintEquation eq = c.equation(EquationKind::FixedTwist, EquationForm::Dot);
  for (const Direction& da : dirsA) {
    for (const Direction& db : dirsB) {
      const Eigen::Vector3d va = builder.directionValue(da);
      const Eigen::Vector3d vb = builder.project(aligned * builder.worldOf(db));
      const double scale = va.norm() * vb.norm();
      const double dotRate = std::abs(n.dot(vb.cross(va))) / scale;
      if (dotRate > best * (1.0 + 1e-9)) {
        best = dotRate;
        eq.form = EquationForm::Dot;
        eq.a = da;
        eq.b = db;
        eq.value = va.dot(vb);
      }
      // In space a cross component is invariant under a rigid motion of the whole mechanism only where
      // a x b = 0, so that form is used for parallel pairs alone (in the plane it always is).
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
  // When every direction of both bodies lies in one plane with the axis (links that only carry sliders along
  // their plane, analysed in space), no pair sees the turn: the normal of one body's two directions does, as
  // the triple product (a x b).c with the other body's direction c.
  if (!planar && best < kDegenerateTwistRate && dirsA.size() == 2 && dirsB.size() == 2) {
    auto consider = [&](const Direction& a, const Direction& b, const Direction& cc,
                        const Eigen::Vector3d& va, const Eigen::Vector3d& vb, const Eigen::Vector3d& vc,
                        bool pairTurns) {
      const Eigen::Vector3d normal = va.cross(vb);
      const double scale = va.norm() * vb.norm() * vc.norm();
      // The turning body's vectors move by n x v: the pair's normal by n x normal, or c by n x c.
      const double rate = std::abs(pairTurns ? n.cross(normal).dot(vc) : normal.dot(n.cross(vc))) / scale;
      if (rate > best * (1.0 + 1e-9)) {
        best = rate;
        eq.form = EquationForm::Triple;
        eq.a = a;
        eq.b = b;
        eq.c = cc;
        eq.value = normal.dot(vc);
      }
    };
    const Eigen::Vector3d a1 = builder.directionValue(dirsA[0]), a2 = builder.directionValue(dirsA[1]);
    const Eigen::Vector3d b1 = builder.project(aligned * builder.worldOf(dirsB[0]));
    const Eigen::Vector3d b2 = builder.project(aligned * builder.worldOf(dirsB[1]));
    for (int i = 0; i < 2; ++i) {
      consider(dirsA[0], dirsA[1], dirsB[i], a1, a2, i == 0 ? b1 : b2, false);
      consider(dirsB[0], dirsB[1], dirsA[i], b1, b2, i == 0 ? a1 : a2, true);
    }
  }
  c.add(eq);
}

/// u_A.v_B = cos(gamma), the angle between the universal joint's two cross axes.
void writeAxisAngle(const JointContext& c) {
  ConstraintEquation eq = c.equation(EquationKind::AxisAngle, EquationForm::Dot);
  eq.a = Direction{c.elements.axis1, -1};
  eq.b = Direction{c.elements.axis2, -1};
  eq.value = c.spec().axis.dot(c.spec().axis2);
  c.add(eq);
}

/// (p_B - p_A).u_A = 0.
void writePointInPlane(const JointContext& c) {
  ConstraintEquation eq = c.equation(EquationKind::PointInPlane, EquationForm::Dot);
  eq.a = Direction{c.elements.point2, c.elements.point1};
  eq.b = Direction{c.elements.axis1, -1};
  eq.value = 0.0;
  c.add(eq);
}

/// |p_B - p_A|^2 = L^2 (a cable: its declared length; a distance constraint: the distance at the pose).
void writeDistance(const JointContext& c) {
  ConstraintEquation eq = c.equation(EquationKind::Distance, EquationForm::Dot);
  eq.a = Direction{c.elements.point2, c.elements.point1};
  eq.b = eq.a;
  const Joint& joint = c.spec();
  const double length = joint.kind == ConnectionKind::Cable
                            ? joint.length / c.builder.model.characteristicLength
                            : c.builder.directionValue(eq.a).norm();
  eq.value = length * length;
  c.add(eq);
}

using PrimitiveWriter = void (*)(const JointContext&);

/// The writer of each primitive: where a joint type's equations live (the table row lists the primitives).
PrimitiveWriter writerOf(Primitive primitive) {
  switch (primitive) {
    case Primitive::CoincidentPoint:
      return writeCoincidentPoint;
    case Primitive::ParallelAxis:
      return writeParallelAxis;
    case Primitive::PointOnAxisLine:
      return writePointOnAxisLine;
    case Primitive::FixedTwist:
      return writeFixedTwist;
    case Primitive::AxisAngle:
      return writeAxisAngle;
    case Primitive::PointInPlane:
      return writePointInPlane;
    case Primitive::Distance:
      return writeDistance;
  }
  return writeCoincidentPoint;  // unreachable: every enumerator has a case
}

}  // namespace

void addJointEquations(ModelBuilder& builder) {
  for (size_t j = 0; j < builder.mechanism.joints.size(); ++j) {
    if (!builder.model.jointActive[j])
      continue;
    const JointContext context{builder, static_cast<int>(j), builder.connections[j]};
    for (Primitive primitive : builder.connections[j].primitives)
      writerOf(primitive)(context);
  }
}

}  // namespace mobility_analysis
