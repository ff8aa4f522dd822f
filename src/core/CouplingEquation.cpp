#include "mobility_analysis/CouplingEquation.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "mobility_analysis/NaturalCoordinates.hpp"
#include "mobility_analysis/coordinates/EquationForms.hpp"
#include "mobility_analysis/coordinates/ModelBuilder.hpp"

namespace mobility_analysis {

namespace {

Eigen::Vector3d element(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q, int e) {
  const int offset = model.elements[e].offset;
  return model.dim == 3 ? Eigen::Vector3d(q.segment<3>(offset))
                        : Eigen::Vector3d(q(offset), q(offset + 1), 0.0);
}

Eigen::Vector3d direction(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q, int head,
                          int tail) {
  return tail < 0 ? element(model, q, head) : (element(model, q, head) - element(model, q, tail)).eval();
}

Eigen::Vector3d axisOf(const JointValueOperand& o, const CoordinateModel& model,
                       const Eigen::Ref<const Eigen::VectorXd>& q) {
  return o.axis >= 0 ? element(model, q, o.axis) : Eigen::Vector3d::UnitZ().eval();
}

/// Accumulates d(value)/dq of one operand, times @p factor, by element.
void jointValueGradient(const JointValueOperand& o, const CoordinateModel& model,
                        const Eigen::Ref<const Eigen::VectorXd>& q, double factor,
                        std::map<int, Eigen::Vector3d>& byElement) {
  auto add = [&](int e, const Eigen::Vector3d& g) {
    auto it = byElement.emplace(e, Eigen::Vector3d::Zero()).first;
    it->second += factor * g;
  };
  const Eigen::Vector3d u = axisOf(o, model, q);
  if (o.prismatic) {
    const Eigen::Vector3d d = element(model, q, o.bHead) - element(model, q, o.aHead);
    add(o.bHead, u);
    add(o.aHead, -u);
    if (o.axis >= 0)
      add(o.axis, d);
    return;
  }
  const Eigen::Vector3d a = direction(model, q, o.aHead, o.aTail);
  const Eigen::Vector3d b = direction(model, q, o.bHead, o.bTail);
  const double au = a.dot(u), bu = b.dot(u);
  const double y = u.dot(a.cross(b));
  const double x = a.dot(b) - au * bu;
  const double r2 = std::max(x * x + y * y, 1e-300);
  // d atan2(y, x) = (x dy - y dx) / (x^2 + y^2)
  const Eigen::Vector3d ga = (x * b.cross(u) - y * (b - bu * u)) / r2;
  const Eigen::Vector3d gb = (x * u.cross(a) - y * (a - au * u)) / r2;
  add(o.aHead, ga);
  if (o.aTail >= 0)
    add(o.aTail, -ga);
  add(o.bHead, gb);
  if (o.bTail >= 0)
    add(o.bTail, -gb);
  if (o.axis >= 0)
    add(o.axis, (x * a.cross(b) + y * (bu * a + au * b)) / r2);
}

std::map<int, Eigen::Vector3d> gradientByElement(const CouplingTerms& terms, const CoordinateModel& model,
                                                 const Eigen::Ref<const Eigen::VectorXd>& q) {
  std::map<int, Eigen::Vector3d> byElement;
  jointValueGradient(terms.follower, model, q, 1.0, byElement);
  jointValueGradient(terms.leader, model, q, -terms.multiplier, byElement);
  for (const auto& [o, weight] : terms.moreFollowers)
    jointValueGradient(o, model, q, weight, byElement);
  for (const auto& [o, weight] : terms.moreLeaders)
    jointValueGradient(o, model, q, -terms.multiplier * weight, byElement);
  return byElement;
}

}  // namespace

double evaluateJointValue(const JointValueOperand& o, const CoordinateModel& model,
                          const Eigen::Ref<const Eigen::VectorXd>& q) {
  const Eigen::Vector3d u = axisOf(o, model, q);
  if (o.prismatic)
    return (element(model, q, o.bHead) - element(model, q, o.aHead)).dot(u) - o.rest;
  const Eigen::Vector3d a = direction(model, q, o.aHead, o.aTail);
  const Eigen::Vector3d b = direction(model, q, o.bHead, o.bTail);
  const double angle = std::atan2(u.dot(a.cross(b)), a.dot(b) - a.dot(u) * b.dot(u)) - o.rest;
  return std::remainder(angle, 2.0 * M_PI);
}

double evaluateCoupling(const CouplingTerms& terms, const CoordinateModel& model,
                        const Eigen::Ref<const Eigen::VectorXd>& q) {
  double follower = evaluateJointValue(terms.follower, model, q);
  double leader = evaluateJointValue(terms.leader, model, q);
  for (const auto& [o, weight] : terms.moreFollowers)
    follower += weight * evaluateJointValue(o, model, q);
  for (const auto& [o, weight] : terms.moreLeaders)
    leader += weight * evaluateJointValue(o, model, q);
  return follower - terms.multiplier * leader - terms.offset;
}

void appendCouplingGradient(const CouplingTerms& terms, const CoordinateModel& model,
                            const Eigen::Ref<const Eigen::VectorXd>& q, int row,
                            std::vector<Eigen::Triplet<double>>& triplets) {
  for (const auto& [e, g] : gradientByElement(terms, model, q)) {
    const int offset = model.elements[e].offset;
    for (int i = 0; i < model.dim; ++i) {
      if (g[i] != 0.0)
        triplets.emplace_back(row, offset + i, g[i]);
    }
  }
}

void computeCouplingHessian(const CouplingTerms& terms, const CoordinateModel& model,
                            const Eigen::Ref<const Eigen::VectorXd>& q, std::vector<int>& columns,
                            Eigen::MatrixXd& hessian) {
  columns.clear();
  for (const auto& entry : gradientByElement(terms, model, q)) {
    for (int i = 0; i < model.dim; ++i)
      columns.push_back(model.elements[entry.first].offset + i);
  }
  std::sort(columns.begin(), columns.end());
  const int n = static_cast<int>(columns.size());
  hessian.setZero(n, n);
  auto gradientAt = [&](const Eigen::VectorXd& point) {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
    for (const auto& [e, value] : gradientByElement(terms, model, point)) {
      for (int i = 0; i < model.dim; ++i) {
        const auto at = std::lower_bound(columns.begin(), columns.end(), model.elements[e].offset + i);
        g(at - columns.begin()) += value[i];
      }
    }
    return g;
  };
  constexpr double kStep = 1e-6;
  Eigen::VectorXd point = q;
  for (int j = 0; j < n; ++j) {
    point(columns[j]) = q(columns[j]) + kStep;
    const Eigen::VectorXd plus = gradientAt(point);
    point(columns[j]) = q(columns[j]) - kStep;
    const Eigen::VectorXd minus = gradientAt(point);
    point(columns[j]) = q(columns[j]);
    hessian.col(j) = (plus - minus) / (2.0 * kStep);
  }
  hessian = (0.5 * (hessian + hessian.transpose())).eval();
}

void addCouplingEquation(ModelBuilder& builder, int j) {
  const Mechanism& mechanism = builder.mechanism;
  CoordinateModel& model = builder.model;
  const bool planar = builder.planar();
  auto makeOperand = [&](int t) {
    const Joint& tree = mechanism.joints[t];
    const ConnectionElements& ct = builder.connections[t];
    JointValueOperand o;
    o.prismatic = tree.type == JointType::Prismatic;
    o.axis = planar && !o.prismatic ? -1 : ct.axis1;
    if (o.prismatic) {
      o.aHead = ct.point1;
      o.bHead = ct.point2;
      return o;
    }
    const Eigen::Vector3d u =
        o.axis < 0 ? Eigen::Vector3d::UnitZ().eval() : builder.coordinates(o.axis).normalized().eval();
    auto mostNormal = [&](const BodyBasis& basis) {
      Direction best = basis.d1;
      double bestSine = -1.0;
      for (const Direction& d : {basis.d1, basis.d2}) {
        if (d.head < 0)
          continue;
        const Eigen::Vector3d v = builder.directionValue(d);
        const double sine = (v - v.dot(u) * u).norm() / std::max(v.norm(), 1e-300);
        if (sine > bestSine) {
          bestSine = sine;
          best = d;
        }
      }
      return best;
    };
    const Direction a = mostNormal(builder.bases[tree.link1]);
    const Direction b = mostNormal(builder.bases[tree.link2]);
    o.aHead = a.head;
    o.aTail = a.tail;
    o.bHead = b.head;
    o.bTail = b.tail;
    // theta_0: the angle between a and b with b turned back to the joint's zero (its two frames aligned).
    const Eigen::Matrix3d aligned = builder.poses[tree.link1].linear() * tree.frame1.linear() *
                                    tree.frame2.linear().transpose() *
                                    builder.poses[tree.link2].linear().transpose();
    const Eigen::Vector3d bRest = builder.project(aligned * builder.worldOf(b));
    const Eigen::Vector3d av = builder.directionValue(a);
    o.rest = std::atan2(u.dot(av.cross(bRest)), av.dot(bRest) - av.dot(u) * bRest.dot(u));
    return o;
  };
  const Joint& coupling = mechanism.joints[j];
  CouplingTerms terms;
  terms.follower = makeOperand(coupling.follower);
  terms.leader = makeOperand(coupling.leader);
  for (const WeightedJoint& t : coupling.moreFollowers)
    terms.moreFollowers.emplace_back(makeOperand(t.joint), t.weight);
  for (const WeightedJoint& t : coupling.moreLeaders)
    terms.moreLeaders.emplace_back(makeOperand(t.joint), t.weight);
  // v_f [SI] = m v_l [SI] + c, with prismatic values in normalised lengths: scale by Lc.
  const double lc = model.characteristicLength;
  const double followerScale = terms.follower.prismatic ? lc : 1.0;
  const double leaderScale = terms.leader.prismatic ? lc : 1.0;
  terms.multiplier = coupling.multiplier * leaderScale / followerScale;
  terms.offset = coupling.offset / followerScale;
  ConstraintEquation eq;
  eq.source = EquationSource::Joint;
  eq.element = j;
  eq.kind = EquationKind::Coupling;
  eq.form = EquationForm::Coupling;
  eq.coupling() = static_cast<int>(model.couplings.size());
  model.couplings.push_back(terms);
  model.equations.push_back(eq);
}

double CouplingForm::value(const ElementView& v, const ConstraintEquation& eq) {
  return evaluateCoupling(v.model().couplings[eq.coupling()], v.model(), v.q());
}

void CouplingForm::gradient(const ElementView& v, const ConstraintEquation& eq, int row, GradientSink& sink) {
  appendCouplingGradient(v.model().couplings[eq.coupling()], v.model(), v.q(), row, sink);
}

void CouplingForm::hessian(const ElementView& v, const ConstraintEquation& eq, double weight,
                           HessianSink& sink) {
  std::vector<int> columns;
  Eigen::MatrixXd hessian;
  computeCouplingHessian(v.model().couplings[eq.coupling()], v.model(), v.q(), columns, hessian);
  for (size_t a = 0; a < columns.size(); ++a) {
    for (size_t b = 0; b < columns.size(); ++b) {
      if (hessian(a, b) != 0.0)
        sink.emplace_back(columns[a], columns[b], weight * hessian(a, b));
    }
  }
}

}  // namespace mobility_analysis
