#include "mobility_analysis/analysis/PassiveFreedoms.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <set>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "mobility_analysis/coordinates/EquationForms.hpp"

namespace mobility_analysis {

namespace {

/// A twist of the group is a first-order motion when |A xi| is below this fraction of |A| |xi| [-].
constexpr double kTwistNullity = 1e-8;
/// The finite check turns or slides the group this far [rad] or [normalised length].
constexpr double kFiniteStep = 0.05;
/// ... and accepts the motion when no constraint moves more than this [normalised length].
constexpr double kFiniteResidual = 1e-9;
/// Longest chain of links an idle group may be.
constexpr size_t kMaxGroup = 3;

/// The finite rigid motion exp(xi) of a twist (omega, v) (Murray, Li & Sastry, eq. 2.36).
Eigen::Isometry3d exponential(const Eigen::Vector3d& omega, const Eigen::Vector3d& v) {
  Eigen::Isometry3d g = Eigen::Isometry3d::Identity();
  const double angle = omega.norm();
  if (angle < 1e-12) {
    g.translation() = v;
    return g;
  }
  const Eigen::Vector3d w = omega / angle, u = v / angle;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, w).toRotationMatrix();
  g.linear() = R;
  g.translation() = (Eigen::Matrix3d::Identity() - R) * w.cross(u) + w * w.dot(u) * angle;
  return g;
}

/// One row of T: the velocity of one coordinate per twist component (lambda of the 6 used, the rest zero).
using TwistRow = Eigen::Matrix<double, 1, 6>;

/// @return Whether sigma_min(A) > @p bound is certain from G = A^T A (its top-left L x L block):
/// sigma_min(A)^2
///         is at least 1 / |G^-1|_F.
template <int L>
bool clearlyFullRank(const Eigen::Matrix<double, 6, 6>& gram, double bound) {
  const Eigen::Matrix<double, L, L> g = gram.template topLeftCorner<L, L>();
  const Eigen::LLT<Eigen::Matrix<double, L, L>> llt(g);
  if (llt.info() != Eigen::Success)
    return false;
  const double inverseNorm = llt.solve(Eigen::Matrix<double, L, L>::Identity()).norm();
  return std::isfinite(inverseNorm) && inverseNorm > 0.0 && std::sqrt(1.0 / inverseNorm) > bound;
}

}  // namespace

PassiveFreedoms findPassiveFreedoms(const Mechanism& mechanism, const CoordinateModel& model,
                                    const Eigen::Ref<const Eigen::VectorXd>& q, const SparseJacobian& J,
                                    const PassiveFreedomsOptions& options) {
  PassiveFreedoms result;
  const int numLinks = static_cast<int>(mechanism.links.size());
  const int dim = model.dim;
  const bool planar = dim == 2;
  const int lambda = model.lambda;
  // Connections that constrain, and the links they join.
  std::vector<int> equationsOf(mechanism.joints.size(), 0);
  for (const ConstraintEquation& eq : model.equations) {
    if (eq.source == EquationSource::Joint)
      ++equationsOf[eq.element];
  }
  std::vector<std::vector<int>> connectionsAt(numLinks);
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    if (equationsOf[j] == 0)
      continue;
    connectionsAt[mechanism.joints[j].link1].push_back(static_cast<int>(j));
    connectionsAt[mechanism.joints[j].link2].push_back(static_cast<int>(j));
  }
  const int numCoordinates = model.numCoordinates();
  // Each row's norm once (a row is in up to 3 kMaxGroup groups), by the same expression as before.
  std::vector<double> rowNorm(static_cast<size_t>(J.rows()));
  for (Eigen::Index r = 0; r < J.rows(); ++r)
    rowNorm[static_cast<size_t>(r)] = J.row(r).norm();
  auto element3 = [&](int e) {
    const int o = model.elements[e].offset;
    return dim == 3 ? Eigen::Vector3d(q.segment<3>(o)) : Eigen::Vector3d(q(o), q(o + 1), 0.0);
  };
  // The row of T for coordinate k of element e: d(x_k)/d(omega, v), from -[x]x and (points) I; in the plane
  // the components omega_z, v_x, v_y.
  auto twistRow = [&](int e, int k) {
    const int o = model.elements[e].offset;
    const double point = model.elements[e].isPoint ? 1.0 : 0.0;
    TwistRow t = TwistRow::Zero();
    if (planar) {  // omega_z, v_x, v_y of x_k: (-y, 1, 0) and (x, 0, 1) for a point
      if (k == 0)
        t.head<3>() << -q(o + 1), point, 0.0;
      else
        t.head<3>() << q(o), 0.0, point;
      return t;
    }
    const double x = q(o), y = q(o + 1), z = q(o + 2);
    if (k == 0)
      t << 0.0, z, -y, point, 0.0, 0.0;
    else if (k == 1)
      t << -z, 0.0, x, 0.0, point, 0.0;
    else
      t << y, -x, 0.0, 0.0, 0.0, point;
    return t;
  };

  // The end-connection bound (PassiveFreedomsOptions, with its proof): per link l, F_l = the sum over the
  // rows r touching l of |a_{r,l}|^2, where a_{r,l} is row r (scaled to unit norm) on l's columns times T;
  // and for each of the two connections of a link that may be in a group, the Gram matrix of a_{r,l} over
  // that connection's rows, valid when each of those rows touches the connection's two links only.
  const bool bound = options.endConnectionBound;
  std::vector<double> linkFrobenius;
  std::vector<double> endGram;  // per link, per connection slot 0 or 1: lambda x lambda
  std::vector<char> endValid;   // per link and slot
  const size_t gramSize = static_cast<size_t>(lambda * lambda);
  if (bound) {
    std::vector<int> columnElement(static_cast<size_t>(numCoordinates), -1),
        columnLink(static_cast<size_t>(numCoordinates), -1);
    for (size_t l = 0; l < model.bodyElements.size(); ++l) {
      for (int e : model.bodyElements[l]) {
        for (int k = 0; k < dim; ++k) {
          columnElement[static_cast<size_t>(model.elements[e].offset + k)] = e;
          columnLink[static_cast<size_t>(model.elements[e].offset + k)] = static_cast<int>(l);
        }
      }
    }
    linkFrobenius.assign(static_cast<size_t>(numLinks), 0.0);
    endGram.assign(static_cast<size_t>(numLinks) * 2 * gramSize, 0.0);
    endValid.assign(static_cast<size_t>(numLinks) * 2, 1);
    auto slotOf = [&](int link, int joint) {
      const std::vector<int>& at = connectionsAt[link];
      return at.size() != 2 ? -1 : at[0] == joint ? 0 : at[1] == joint ? 1 : -1;
    };
    constexpr size_t kLinksPerRow = 4;
    std::array<std::pair<int, TwistRow>, kLinksPerRow> perLink;
    for (Eigen::Index r = 0; r < J.rows(); ++r) {
      size_t used = 0;
      bool overflow = false;
      const double norm = rowNorm[static_cast<size_t>(r)];
      for (SparseJacobian::InnerIterator it(J, r); it; ++it) {
        const int l = columnLink[static_cast<size_t>(it.col())];
        size_t slot = 0;
        while (slot < used && perLink[slot].first != l)
          ++slot;
        if (slot == used) {
          if (used == kLinksPerRow) {  // a row on more than four links: no bound for the links it touches
            overflow = true;
            linkFrobenius[static_cast<size_t>(l)] = std::numeric_limits<double>::infinity();
            continue;
          }
          perLink[used++] = {l, TwistRow::Zero()};
        }
        const int e = columnElement[static_cast<size_t>(it.col())];
        perLink[slot].second +=
            (it.value() / norm) * twistRow(e, static_cast<int>(it.col()) - model.elements[e].offset);
      }
      const ConstraintEquation& eq = model.equations[static_cast<size_t>(r)];
      const Joint* joint = eq.source == EquationSource::Joint ? &mechanism.joints[eq.element] : nullptr;
      bool twoLinks = joint != nullptr && !overflow;
      for (size_t s = 0; s < used; ++s)
        twoLinks = twoLinks && (perLink[s].first == joint->link1 || perLink[s].first == joint->link2);
      for (size_t s = 0; s < used; ++s) {
        const int l = perLink[s].first;
        linkFrobenius[static_cast<size_t>(l)] +=
            overflow ? std::numeric_limits<double>::infinity() : perLink[s].second.squaredNorm();
        if (joint == nullptr)
          continue;
        const int end = slotOf(l, eq.element);
        if (end < 0)
          continue;
        const size_t at = static_cast<size_t>(l) * 2 + static_cast<size_t>(end);
        double* gram = &endGram[at * gramSize];
        const TwistRow& a = perLink[s].second;
        for (int r1 = 0; r1 < lambda; ++r1) {
          for (int c1 = 0; c1 < lambda; ++c1)
            gram[r1 * lambda + c1] += a(r1) * a(c1);
        }
      }
      if (joint != nullptr && !twoLinks) {  // this connection's rows are not all rows of A on the end link
        for (int l : {joint->link1, joint->link2}) {
          const int end = slotOf(l, eq.element);
          if (end >= 0)
            endValid[static_cast<size_t>(l) * 2 + static_cast<size_t>(end)] = 0;
        }
      }
    }
  }
  // Whether the group's two end connections alone prove that no twist of it passes the nullity test of the
  // search (PassiveFreedomsOptions): true settles the group with no motion; false decides nothing.
  auto rigidByEnds = [&](const std::vector<int>& path) {
    Eigen::Matrix<double, 6, 6> gram = Eigen::Matrix<double, 6, 6>::Zero();
    double frobenius2 = 0.0;
    int ends = 0;
    for (int l : path) {
      frobenius2 += linkFrobenius[static_cast<size_t>(l)];
      for (size_t s = 0; s < 2; ++s) {
        const Joint& joint = mechanism.joints[connectionsAt[l][s]];
        const int other = joint.link1 == l ? joint.link2 : joint.link1;
        if (std::find(path.begin(), path.end(), other) != path.end())
          continue;
        const size_t at = static_cast<size_t>(l) * 2 + s;
        if (!endValid[at])
          return false;
        ++ends;
        const double* end = &endGram[at * gramSize];
        for (int r1 = 0; r1 < lambda; ++r1) {
          for (int c1 = 0; c1 < lambda; ++c1)
            gram(r1, c1) += end[r1 * lambda + c1];
        }
      }
    }
    frobenius2 *= static_cast<double>(path.size());
    if (ends != 2 || !std::isfinite(frobenius2))
      return false;
    const double limit = 100.0 * kTwistNullity * std::max(std::sqrt(frobenius2), 1.0);
    return planar ? clearlyFullRank<3>(gram, limit) : clearlyFullRank<6>(gram, limit);
  };

  // Candidate groups: every link with two connections but the ground, and chains of such links. Each group's
  // links sorted and padded with -1, so that the groups sort (and are taken) as sorted vectors would. A group
  // the end-connection bound settles has no motion and is not kept (the order of the others is unchanged).
  using Group = std::array<int, kMaxGroup>;
  std::vector<Group> groups;
  auto addGroup = [&](const std::vector<int>& path) {
    if (path.front() > path.back())
      return;  // the same links are met from the other end, as the reversed path
    if (bound && rigidByEnds(path)) {
      ++result.groupsRigidByEnds;
      return;
    }
    Group group;
    group.fill(-1);
    for (size_t i = 0; i < path.size(); ++i) {  // insertion sort of at most kMaxGroup links
      size_t k = i;
      for (; k > 0 && group[k - 1] > path[i]; --k)
        group[k] = group[k - 1];
      group[k] = path[i];
    }
    groups.push_back(group);
  };
  std::vector<int> chain;
  std::function<void(std::vector<int>&)> extend = [&](std::vector<int>& path) {
    if (path.size() >= kMaxGroup)
      return;
    const int last = path.back();
    if (connectionsAt[last].size() != 2)
      return;
    for (int j : connectionsAt[last]) {
      const Joint& joint = mechanism.joints[j];
      const int next = joint.link1 == last ? joint.link2 : joint.link1;
      if (next == mechanism.rootLink || connectionsAt[next].size() != 2 ||
          std::find(path.begin(), path.end(), next) != path.end())
        continue;
      path.push_back(next);
      addGroup(path);
      extend(path);
      path.pop_back();
    }
  };
  for (int l = 0; l < numLinks; ++l) {
    if (l == mechanism.rootLink || connectionsAt[l].size() != 2)
      continue;
    chain.assign(1, l);
    addGroup(chain);
    extend(chain);
  }
  std::sort(groups.begin(), groups.end());
  groups.erase(std::unique(groups.begin(), groups.end()), groups.end());
  if (groups.empty())
    return result;

  // Column access, made when a group first needs it (none does on a serial chain).
  Eigen::SparseMatrix<double> Jc;
  bool haveColumns = false;
  std::vector<char> inGroup(numLinks, 0);

  // Motions kept, each as (coordinate, value) over its group's coordinates, and the motions at each link: a
  // group is compared with those sharing one of its links only, and nothing here costs more than the group's
  // neighbourhood (a chain of 10^5 links has 3 10^5 candidate groups).
  std::vector<std::vector<std::pair<int, double>>> accepted;
  std::vector<std::vector<int>> acceptedAt(numLinks);
  std::vector<int> localColumn(model.numCoordinates(), -1);
  Eigen::VectorXd moved;  // q, copied when a first twist is stepped
  // Work space of one group, reused (a chain of 10^5 links has 3 10^5 groups: no allocation per group).
  std::vector<int> group, outside, elements, columns, rows;
  std::vector<TwistRow> twistRows;  // the rows of T below (lambda entries, zero beyond)
  for (const Group& padded : groups) {
    group.assign(padded.begin(), std::find(padded.begin(), padded.end(), -1));
    for (int l : group)
      inGroup[l] = 1;
    struct Reset {  // inGroup back to all zero however this group's iteration ends
      std::vector<char>& flags;
      const std::vector<int>& links;
      ~Reset() {
        for (int l : links)
          flags[l] = 0;
      }
    } reset{inGroup, group};
    // T: coordinates of the group's elements per twist component (space: omega, v; plane: omega_z, v_x, v_y).
    // Its end connections must reach at least two other links: a link turning on connections to one link
    // only (a door on its hinges, a robot's last link) is that link's output, not an idle motion.
    outside.clear();
    for (int l : group) {
      for (int j : connectionsAt[l]) {
        const Joint& joint = mechanism.joints[j];
        if (!inGroup[joint.link1])
          outside.push_back(joint.link1);
        if (!inGroup[joint.link2])
          outside.push_back(joint.link2);
      }
    }
    std::sort(outside.begin(), outside.end());
    outside.erase(std::unique(outside.begin(), outside.end()), outside.end());
    int ends = 0;
    for (int l : group) {
      for (int j : connectionsAt[l])
        ends += inGroup[mechanism.joints[j].link1] && inGroup[mechanism.joints[j].link2] ? 0 : 1;
    }
    if (outside.size() < 2 || ends != 2)
      continue;
    ++result.groupsSearched;
    elements.clear();
    for (int l : group)
      elements.insert(elements.end(), model.bodyElements[l].begin(), model.bodyElements[l].end());
    columns.clear();
    twistRows.clear();
    for (int e : elements) {
      for (int k = 0; k < dim; ++k) {
        columns.push_back(model.elements[e].offset + k);
        twistRows.push_back(twistRow(e, k));
      }
    }
    // A = J(rows touching the group, group columns) T, rows scaled to unit norm.
    rows.clear();
    if (!haveColumns) {
      Jc = J;
      haveColumns = true;
    }
    for (int c : columns) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(Jc, c); it; ++it)
        rows.push_back(static_cast<int>(it.row()));
    }
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    for (size_t c = 0; c < columns.size(); ++c)
      localColumn[columns[c]] = static_cast<int>(c);
    // Most groups (every link of a serial chain) have no null twist at all. sigma_min(A)^2 is at least
    // 1 / |(A^T A)^-1|_F and sigma_max(A) at most |A|_F: when these bounds clear the nullity test a
    // hundredfold (far beyond what rounding in A^T A can move them), no twist can pass it and the SVD is
    // skipped; otherwise it decides exactly as before. A^T A is summed row by row in fixed-size storage (at
    // most 6 x 6), A itself is built only for the SVD.
    if (static_cast<int>(rows.size()) >= lambda) {
      Eigen::Matrix<double, 6, 6> gram = Eigen::Matrix<double, 6, 6>::Zero();
      double frobenius2 = 0.0;
      TwistRow a;
      for (int r : rows) {
        a.setZero();
        const double norm = rowNorm[static_cast<size_t>(r)];
        for (SparseJacobian::InnerIterator it(J, r); it; ++it) {
          const int c = localColumn[it.col()];
          if (c >= 0)
            a += (it.value() / norm) * twistRows[static_cast<size_t>(c)];
        }
        gram.noalias() += a.transpose() * a;
        frobenius2 += a.squaredNorm();
      }
      const double bound = 100.0 * kTwistNullity * std::max(std::sqrt(frobenius2), 1.0);
      if (planar ? clearlyFullRank<3>(gram, bound) : clearlyFullRank<6>(gram, bound)) {
        for (int c : columns)
          localColumn[c] = -1;
        continue;
      }
    }
    Eigen::MatrixXd T(static_cast<Eigen::Index>(twistRows.size()), lambda);
    for (size_t c = 0; c < twistRows.size(); ++c)
      T.row(static_cast<Eigen::Index>(c)) = twistRows[c].head(lambda);
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rows.size()), lambda);
    for (size_t r = 0; r < rows.size(); ++r) {
      const double norm = rowNorm[static_cast<size_t>(rows[r])];
      for (SparseJacobian::InnerIterator it(J, rows[r]); it; ++it) {
        const int c = localColumn[it.col()];
        if (c >= 0)
          A.row(static_cast<Eigen::Index>(r)) += (it.value() / norm) * T.row(c);
      }
    }
    for (int c : columns)
      localColumn[c] = -1;
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
    const Eigen::VectorXd sigma = svd.singularValues();
    const double largest = sigma.size() > 0 ? sigma(0) : 0.0;
    for (int k = 0; k < lambda; ++k) {
      if (k < sigma.size() && sigma(k) > kTwistNullity * std::max(largest, 1.0))
        continue;
      Eigen::VectorXd xi = svd.matrixV().col(k);
      Eigen::Vector3d omega, v;
      if (planar) {
        omega = Eigen::Vector3d(0.0, 0.0, xi(0));
        v = Eigen::Vector3d(xi(1), xi(2), 0.0);
      } else {
        omega = xi.head<3>();
        v = xi.tail<3>();
      }
      // Finite: the group moved by exp(step xi) keeps every constraint.
      const double scale = kFiniteStep / std::max(omega.norm(), v.norm());
      const Eigen::Isometry3d g = exponential(scale * omega, scale * v);
      // (moved is q outside the group: one copy for all groups, put back after each.)
      if (moved.size() == 0)
        moved = q;
      for (int e : elements) {
        const Eigen::Vector3d x = element3(e);
        const Eigen::Vector3d y = model.elements[e].isPoint ? (g * x).eval() : (g.linear() * x).eval();
        moved.segment(model.elements[e].offset, dim) = y.head(dim);
      }
      // Only the rows touching the group can change.
      const ElementView before(model, q), after(model, moved);
      double change = 0.0;
      for (int r : rows) {
        const ConstraintEquation& eq = model.equations[r];
        change = std::max(change, std::abs(visitForm(eq.form, [&](auto form) {
                            return form.value(after, eq) - form.value(before, eq);
                          })));
      }
      for (int e : elements)
        moved.segment(model.elements[e].offset, dim) = q.segment(model.elements[e].offset, dim);
      if (change > kFiniteResidual)
        continue;
      // Independent of the motions already kept (only those sharing a link can be dependent), compared over
      // the coordinates they move (every other coordinate is zero in all of them).
      std::vector<std::pair<int, double>> motion;
      const Eigen::VectorXd local = T * xi;
      for (size_t c = 0; c < columns.size(); ++c)
        motion.emplace_back(columns[c], local(static_cast<Eigen::Index>(c)));
      std::vector<int> overlapping;
      for (int l : group) {
        for (int a : acceptedAt[l]) {
          if (std::find(overlapping.begin(), overlapping.end(), a) == overlapping.end())
            overlapping.push_back(a);
        }
      }
      std::sort(overlapping.begin(), overlapping.end());
      if (!overlapping.empty()) {
        std::vector<int> support;
        auto columnOf = [&](int coordinate) {
          if (localColumn[coordinate] < 0) {
            localColumn[coordinate] = static_cast<int>(support.size());
            support.push_back(coordinate);
          }
          return localColumn[coordinate];
        };
        for (int a : overlapping) {
          for (const auto& entry : accepted[a])
            columnOf(entry.first);
        }
        for (const auto& entry : motion)
          columnOf(entry.first);
        Eigen::MatrixXd stack = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(support.size()),
                                                      static_cast<Eigen::Index>(overlapping.size()) + 1);
        auto fill = [&](const std::vector<std::pair<int, double>>& vector, Eigen::Index column) {
          for (const auto& [coordinate, value] : vector)
            stack(localColumn[coordinate], column) = value;
          stack.col(column).normalize();
        };
        for (size_t a = 0; a < overlapping.size(); ++a)
          fill(accepted[overlapping[a]], static_cast<Eigen::Index>(a));
        fill(motion, stack.cols() - 1);
        for (int coordinate : support)
          localColumn[coordinate] = -1;
        Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(stack);
        qr.setThreshold(1e-6);
        if (qr.rank() < stack.cols())
          continue;
      }
      for (int l : group)
        acceptedAt[l].push_back(static_cast<int>(accepted.size()));
      accepted.push_back(std::move(motion));
      // The phrase: the group, what it does, and the connections it turns or slides between.
      PassiveMotion passive;
      std::string names;
      for (int l : group) {
        passive.links.push_back(mechanism.links[l].name);
        names += (names.empty() ? "" : "-") + mechanism.links[l].name;
      }
      std::vector<int> ends;
      std::set<std::string> types;
      for (int l : group) {
        for (int j : connectionsAt[l]) {
          const Joint& joint = mechanism.joints[j];
          if (inGroup[joint.link1] && inGroup[joint.link2])
            continue;
          ends.push_back(j);
          types.insert(joint.kind == ConnectionKind::DistanceConstraint ? "distance" : toString(joint.type));
        }
      }
      std::string endText;
      for (size_t i = 0; i < ends.size(); ++i)
        endText += (i == 0 ? "" : (i + 1 == ends.size() ? " and " : ", ")) + mechanism.joints[ends[i]].name;
      const std::string jointWord =
          types.size() == 1 && *types.begin() == "spherical"   ? "ball joints"
          : types.size() == 1 && *types.begin() == "prismatic" ? "prismatic joints"
          : types.size() == 1 && (*types.begin() == "revolute" || *types.begin() == "continuous")
              ? "revolute joints"
              : "joints";
      const std::string subject = (group.size() == 1 ? "link " : "chain ") + names;
      if (omega.norm() < 1e-9 * v.norm()) {
        passive.description = subject + " slides along the line of its " + jointWord + " " + endText;
      } else if (std::abs(omega.normalized().dot(v)) > 1e-6 * v.norm() + 1e-12) {
        passive.description = subject + " screws about the line of its " + jointWord + " " + endText;
      } else {
        passive.description = subject + " spins about the line through its " + jointWord + " " + endText;
      }
      result.motions.push_back(std::move(passive));
    }
  }
  result.dof = static_cast<int>(result.motions.size());
  return result;
}

}  // namespace mobility_analysis
