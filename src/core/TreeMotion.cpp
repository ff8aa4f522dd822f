#include "mobility_analysis/TreeMotion.hpp"

#include <algorithm>

namespace mobility_analysis {

namespace {

/// One motion mode of the tree: a turn about `axis` through `centre`, or a slide along `axis` (model coordinates).
struct Mode {
  bool turn = true;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
};

/// Velocity of an element (point or unit vector) at @p x under @p mode, in the model's coordinates.
Eigen::Vector3d velocity(const Mode& mode, bool isPoint, const Eigen::Vector3d& x, int dim) {
  if (!mode.turn) return isPoint ? mode.axis : Eigen::Vector3d::Zero();
  const Eigen::Vector3d r = isPoint ? (x - mode.centre).eval() : x;
  if (dim == 2) return Eigen::Vector3d(-r.y(), r.x(), 0.0);  // a turn about the plane normal
  return mode.axis.cross(r);
}

}  // namespace

std::optional<OrderedRank> computeOrderedRankOverTree(const Mechanism& mechanism, const CoordinateModel& model,
                                                      const Eigen::Ref<const Eigen::VectorXd>& q,
                                                      const SparseJacobian& J, double tolerance) {
  const int dim = model.dim;
  const int n = model.numCoordinates();
  const int m = model.numConstraints();
  const double lc = model.characteristicLength;
  auto project = [&](const Eigen::Vector3d& w) {
    return dim == 3 ? w : Eigen::Vector3d(w.dot(model.planeE1), w.dot(model.planeE2), 0.0);
  };

  // Tree structure and the world frame of every tree joint at the assembled pose.
  const size_t numLinks = mechanism.links.size();
  std::vector<int> parentJoint(numLinks, -1), depth(numLinks, 0);
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    if (mechanism.joints[j].kind == ConnectionKind::TreeJoint) parentJoint[mechanism.joints[j].link2] = static_cast<int>(j);
  }
  for (size_t l = 0; l < numLinks; ++l) {
    for (int b = static_cast<int>(l); parentJoint[b] >= 0; b = mechanism.joints[parentJoint[b]].link1) ++depth[l];
  }
  const LinkPoses poses = recoverPoses(model, q, LinkPoses(numLinks, Eigen::Isometry3d::Identity()));

  // Modes of every tree joint in document order (root outward), then the ground's rigid motions.
  std::vector<std::vector<int>> jointModes(mechanism.joints.size());
  std::vector<Mode> modes;
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const Joint& joint = mechanism.joints[j];
    if (joint.kind != ConnectionKind::TreeJoint) continue;
    const Eigen::Isometry3d frame = poses[joint.link1] * joint.frame1;
    const Eigen::Vector3d centre = project(frame.translation() / lc);
    const Eigen::Vector3d axis = frame.linear() * joint.axis;
    std::vector<Mode> own;
    switch (joint.type) {
      case JointType::Revolute:
      case JointType::Continuous: own.push_back(Mode{true, axis, centre}); break;
      case JointType::Prismatic: own.push_back(Mode{false, project(axis), centre}); break;
      case JointType::Fixed: break;
      case JointType::Floating:
        // Slides along, and turns about, the frame axes through the joint origin (in the plane: x, y, turn).
        for (int k = 0; k < dim; ++k) own.push_back(Mode{false, Eigen::Vector3d::Unit(k), centre});
        if (dim == 2) own.push_back(Mode{true, Eigen::Vector3d::UnitZ(), centre});
        for (int k = 0; dim == 3 && k < 3; ++k) own.push_back(Mode{true, Eigen::Vector3d::Unit(k), centre});
        break;
      case JointType::Planar: {
        // Two slides in its plane and the turn about its normal.
        const Eigen::Vector3d u = axis.unitOrthogonal();
        if (dim == 3) {
          own.push_back(Mode{false, u, centre});
          own.push_back(Mode{false, axis.cross(u), centre});
        } else {
          own.push_back(Mode{false, Eigen::Vector3d::UnitX(), centre});
          own.push_back(Mode{false, Eigen::Vector3d::UnitY(), centre});
        }
        own.push_back(Mode{true, axis, centre});
        break;
      }
      default: return std::nullopt;  // not a URDF tree type
    }
    for (const Mode& mode : own) {
      jointModes[j].push_back(static_cast<int>(modes.size()));
      modes.push_back(mode);
    }
  }
  std::vector<int> rootModes;
  for (int k = 0; k < (dim == 3 ? 6 : 3); ++k) {
    rootModes.push_back(static_cast<int>(modes.size()));
    if (dim == 3) {
      modes.push_back(Mode{k >= 3, Eigen::Vector3d::Unit(k % 3), Eigen::Vector3d::Zero()});
    } else {
      modes.push_back(Mode{k == 2, k == 2 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::Unit(k), Eigen::Vector3d::Zero()});
    }
  }

  // Rows before the first loop element: rigid links and tree joints, independent by construction.
  int firstLoopRow = m;
  for (int r = 0; r < m; ++r) {
    const ConstraintEquation& eq = model.equations[r];
    if (eq.source == EquationSource::Boundary ||
        (eq.source == EquationSource::Joint && mechanism.joints[eq.element].kind != ConnectionKind::TreeJoint)) {
      firstLoopRow = r;
      break;
    }
  }
  if (n - firstLoopRow != static_cast<int>(modes.size())) return std::nullopt;

  std::vector<int> elementOfColumn(n);
  for (size_t e = 0; e < model.elements.size(); ++e) {
    for (int i = 0; i < dim; ++i) elementOfColumn[model.elements[e].offset + i] = static_cast<int>(e);
  }

  // L = J_loop N_T: each later row against the modes of the joints on the tree path between its links.
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::VectorXd rowScale(m - firstLoopRow);
  std::vector<std::vector<int>> rowPathJoints(m - firstLoopRow);
  for (int r = firstLoopRow; r < m; ++r) {
    const int row = r - firstLoopRow;
    rowScale(row) = J.row(r).norm();
    std::vector<int> bodies;
    for (SparseJacobian::InnerIterator it(J, r); it; ++it) {
      const int body = model.elements[elementOfColumn[it.col()]].body;
      if (std::find(bodies.begin(), bodies.end(), body) == bodies.end()) bodies.push_back(body);
    }
    // Joints on the path between the row's links: climb from the deepest link until all fronts meet; the joints
    // above the meeting link move every end of the row rigidly and leave the equation unchanged. Each joint on
    // the path moves the row's links on its side only.
    const bool boundary = model.equations[r].source == EquationSource::Boundary;
    std::vector<std::pair<int, std::vector<int>>> fronts;
    for (int body : bodies) fronts.push_back({body, {body}});
    std::vector<std::pair<int, std::vector<int>>> pathJoints;
    while (fronts.size() > 1) {
      size_t deepest = 0;
      for (size_t i = 1; i < fronts.size(); ++i) {
        if (depth[fronts[i].first] > depth[fronts[deepest].first]) deepest = i;
      }
      const int joint = parentJoint[fronts[deepest].first];
      if (joint < 0) break;
      pathJoints.push_back({joint, fronts[deepest].second});
      fronts[deepest].first = mechanism.joints[joint].link1;
      for (size_t i = 0; i < fronts.size(); ++i) {
        if (i != deepest && fronts[i].first == fronts[deepest].first) {
          fronts[i].second.insert(fronts[i].second.end(), fronts[deepest].second.begin(), fronts[deepest].second.end());
          fronts.erase(fronts.begin() + static_cast<long>(deepest));
          break;
        }
      }
    }
    for (const auto& entry : pathJoints) rowPathJoints[row].push_back(entry.first);
    auto addModes = [&](const std::vector<int>& rowModes, const std::vector<int>* movingBodies) {
      for (int k : rowModes) {
        double value = 0.0;
        for (SparseJacobian::InnerIterator it(J, r); it; ++it) {
          const Element& element = model.elements[elementOfColumn[it.col()]];
          if (movingBodies != nullptr &&
              std::find(movingBodies->begin(), movingBodies->end(), element.body) == movingBodies->end()) {
            continue;
          }
          const Eigen::Vector3d x = dim == 3 ? Eigen::Vector3d(q.segment<3>(element.offset))
                                             : Eigen::Vector3d(q(element.offset), q(element.offset + 1), 0.0);
          value += it.value() * velocity(modes[k], element.isPoint, x, dim)[it.col() - element.offset];
        }
        if (value != 0.0) triplets.emplace_back(row, k, value);
      }
    };
    for (const auto& [joint, moving] : pathJoints) addModes(jointModes[joint], &moving);
    if (boundary) addModes(rootModes, nullptr);
  }
  SparseJacobian L(m - firstLoopRow, static_cast<int>(modes.size()));
  L.setFromTriplets(triplets.begin(), triplets.end());
  const OrderedRank projected = computeOrderedRank(L, tolerance, true, &rowScale);

  OrderedRank result;
  result.numCoordinates = n;
  result.tolerance = tolerance;
  result.rank = firstLoopRow + projected.rank;
  result.redundant.assign(m, false);
  result.nullityTrace.resize(m);
  for (int r = 0; r < firstLoopRow; ++r) result.nullityTrace[r] = n - (r + 1);
  for (int r = firstLoopRow; r < m; ++r) {
    result.redundant[r] = projected.redundant[r - firstLoopRow];
    result.nullityTrace[r] = projected.nullityTrace[r - firstLoopRow] + n - firstLoopRow - static_cast<int>(modes.size());
  }
  // First rows of each link and tree joint, for naming the members of a dependency.
  std::vector<int> firstRowOfLink(numLinks, -1), firstRowOfJoint(mechanism.joints.size(), -1);
  for (int r = 0; r < firstLoopRow; ++r) {
    const ConstraintEquation& eq = model.equations[r];
    std::vector<int>& first = eq.source == EquationSource::Link ? firstRowOfLink : firstRowOfJoint;
    if (first[eq.element] < 0) first[eq.element] = r;
  }
  for (const std::vector<int>& dependency : projected.dependencies) {
    std::vector<int> rows;
    for (int row : dependency) {
      rows.push_back(row + firstLoopRow);
      for (int joint : rowPathJoints[row]) {
        if (firstRowOfJoint[joint] >= 0) rows.push_back(firstRowOfJoint[joint]);
        for (int link : {mechanism.joints[joint].link1, mechanism.joints[joint].link2}) {
          if (firstRowOfLink[link] >= 0) rows.push_back(firstRowOfLink[link]);
        }
      }
    }
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    result.dependencies.push_back(rows);
  }
  result.smallestKeptPivot = projected.smallestKeptPivot;
  result.largestDroppedResidual = projected.largestDroppedResidual;
  return result;
}

}  // namespace mobility_analysis
