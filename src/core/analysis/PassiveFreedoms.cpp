#include "mobility_analysis/analysis/PassiveFreedoms.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <set>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "../Buckets.hpp"
#include "../LocalRows.hpp"
#include "MotionSpan.hpp"
#include "mobility_analysis/coordinates/EquationForms.hpp"

namespace mobility_analysis {

namespace {

/// A twist of the group is a first-order motion when |A xi| is below this fraction of |A| |xi| [-].
constexpr double kTwistNullity = 1e-8;
/// The finite check turns or slides the group this far [rad] or [normalised length].
constexpr double kFiniteStep = 0.05;
/// ... and accepts the motion when no constraint moves more than this [normalised length].
constexpr double kFiniteResidual = 1e-9;
/// A motion (at unit norm) whose remainder off the span of the motions kept is at most this adds no
/// dimension to it (MotionSpan); the column-pivoted QR that compared motions before used the same threshold.
constexpr double kMotionIndependence = 1e-6;
/// A point lies on a line, and two unit directions are parallel, within this [Lc, or -] (the phrases only).
constexpr double kLineTolerance = 1e-6;
/// Most rigid bodies an idle group may be: links joined by welds (fixed connections) count as one, so a rod
/// written as two halves, each with its closure frame, welded at the middle (Gepetto's cut rods) is one.
constexpr size_t kMaxGroup = 3;
/// Most links an idle group may hold, welded ones included.
constexpr size_t kMaxGroupLinks = 2 * kMaxGroup;

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

/**
 * @brief The Cholesky factor of the symmetric @p m (lower triangle read) in its lower triangle, in place;
 *        false where Eigen::LLT reports a non-positive pivot.
 *
 * The operations and their order of Eigen's unblocked LLT (llt_inplace::unblocked: a pivot less the squares
 * of its row, the column below less the products with the rows above, divided by the pivot), so the factor
 * is Eigen's bit for bit; without its dynamic-size blocks and matrix-vector kernel, a third of the bound's
 * time on a chain (3 10^5 factorisations of 3 x 3 or 6 x 6).
 */
template <int L>
bool choleskyLower(Eigen::Matrix<double, L, L>& m) {
  for (int k = 0; k < L; ++k) {
    double x = m(k, k);
    if (k > 0) {
      double squares = m(k, 0) * m(k, 0);
      for (int j = 1; j < k; ++j)
        squares += m(k, j) * m(k, j);
      x -= squares;
    }
    if (x <= 0.0)
      return false;
    m(k, k) = x = std::sqrt(x);
    for (int i = k + 1; i < L; ++i) {
      if (k > 0) {
        double sum = 0.0;
        for (int j = 0; j < k; ++j)
          sum += m(i, j) * m(k, j);
        m(i, k) += -1.0 * sum;  // as Eigen's kernel adds alpha = -1 times the product
      }
      m(i, k) /= x;
    }
  }
  return true;
}

/// @return Whether sigma_min(A) > @p bound is certain from G = A^T A (L x L): sigma_min(A)^2 is at least
/// 1 / |G^-1|_F. Only the lower triangle of @p gram is read.
template <int L>
bool clearlyFullRank(const Eigen::Matrix<double, L, L>& gram, double bound) {
  Eigen::Matrix<double, L, L> factor = gram;
  if (!choleskyLower<L>(factor))
    return false;
  // G^-1 = L^-T L^-1, with L^-1 by forward substitution in fixed-size storage: llt.solve(Identity) went
  // through Eigen's general blocked triangular solver, half the search's time on a chain (3 10^5 calls).
  const Eigen::Matrix<double, L, L> lower = factor.template triangularView<Eigen::Lower>();
  Eigen::Matrix<double, L, L> inverseLower = Eigen::Matrix<double, L, L>::Zero();
  for (int c = 0; c < L; ++c) {
    inverseLower(c, c) = 1.0 / lower(c, c);
    for (int r = c + 1; r < L; ++r) {
      double sum = 0.0;
      for (int k = c; k < r; ++k)
        sum += lower(r, k) * inverseLower(k, c);
      inverseLower(r, c) = -sum / lower(r, r);
    }
  }
  const double inverseNorm = (inverseLower.transpose() * inverseLower).norm();
  return std::isfinite(inverseNorm) && inverseNorm > 0.0 && std::sqrt(1.0 / inverseNorm) > bound;
}

/// The mechanism at the pose q as the search reads it: the connections that constrain at each link, each
/// Jacobian row's norm, and the rows of T (the twist of a rigid group mapped onto its coordinates).
struct SearchContext {
  SearchContext(const Mechanism& mechanism, const CoordinateModel& model,
                const Eigen::Ref<const Eigen::VectorXd>& q, const SparseJacobian& J);

  /// Element @p e's point or unit vector at q (z = 0 in the plane).
  Eigen::Vector3d element3(int e) const;
  /// The row of T for coordinate @p k of element @p e: d(x_k)/d(omega, v) for the twist (omega, v) about
  /// the point @p about, from -[x - about]x (a point; -[x]x for a unit vector) and (points) I; in the plane
  /// the components omega_z, v_x, v_y.
  TwistRow twistRow(int e, int k, const Eigen::Vector3d& about) const;
  /// The point a group's twists are taken about: its link @p l's first point (the origin when it has none).
  /// Why not the origin of the model: far from it (a chain of 10^6 links is 10^5 m long) a twist about the
  /// origin mixes lengths of 10^5 with lengths of 1, its rows of T lose the digits the nullity test and the
  /// end-connection bound read, and every group went through the full search (3.6 s on that chain).
  const Eigen::Vector3d& twistOrigin(int l) const { return twistOrigin_[static_cast<size_t>(l)]; }
  /// The link that connection @p j joins to link @p l.
  int otherLink(int j, int l) const;

  const Mechanism& mechanism;
  const CoordinateModel& model;
  const Eigen::Ref<const Eigen::VectorXd>& q;
  const SparseJacobian& J;
  const int numLinks;
  const int dim;
  const bool planar;
  const int lambda;
  /// Per link, the connections that constrain it (in connection order).
  core_detail::BucketRange connectionsAt(int l) const { return connections_[l]; }
  std::vector<std::pair<int, int>> jointEnds;  ///< Per connection, link1 and link2 (read once: a Joint is
                                               ///< hundreds of bytes).
  std::vector<char> weld;                      ///< Per connection, whether it is a fixed joint (no body).
  std::vector<double> rowNorm;                 ///< Per row of J, its norm.
  std::vector<int> jointOfRow;                 ///< Per row of J, its connection (-1: a link's, the ground's).

 private:
  core_detail::Buckets connections_;  // per link
  std::vector<Eigen::Vector3d> twistOrigin_;  // per link
};

SearchContext::SearchContext(const Mechanism& mechanism, const CoordinateModel& model,
                             const Eigen::Ref<const Eigen::VectorXd>& q, const SparseJacobian& J)
    : mechanism(mechanism),
      model(model),
      q(q),
      J(J),
      numLinks(static_cast<int>(mechanism.links.size())),
      dim(model.dim),
      planar(model.dim == 2),
      lambda(model.lambda),
      jointEnds(mechanism.joints.size()),
      weld(mechanism.joints.size(), 0),
      rowNorm(static_cast<size_t>(J.rows())),
      connections_(numLinks) {
  // Connections that constrain, and the links they join (a connection joining a link to itself is listed
  // twice there, as before).
  // (One read of the equations, 110 bytes each, for the bound's rows too.)
  std::vector<int> equationsOf(mechanism.joints.size(), 0);
  jointOfRow.assign(model.equations.size(), -1);
  for (size_t r = 0; r < model.equations.size(); ++r) {
    const ConstraintEquation& eq = model.equations[r];
    if (eq.source == EquationSource::Joint) {
      ++equationsOf[eq.element];
      jointOfRow[r] = eq.element;
    }
  }
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    jointEnds[j] = {mechanism.joints[j].link1, mechanism.joints[j].link2};
    weld[j] = mechanism.joints[j].type == JointType::Fixed ? 1 : 0;
    if (equationsOf[j] == 0)
      continue;
    connections_.count(jointEnds[j].first);
    connections_.count(jointEnds[j].second);
  }
  connections_.allocate();
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    if (equationsOf[j] == 0)
      continue;
    connections_.add(jointEnds[j].first, static_cast<int>(j));
    connections_.add(jointEnds[j].second, static_cast<int>(j));
  }
  // Each row's norm once (a row is in up to 3 kMaxGroup groups).
  for (Eigen::Index r = 0; r < J.rows(); ++r)
    rowNorm[static_cast<size_t>(r)] = core_detail::rowNorm(J, r);
  twistOrigin_.assign(static_cast<size_t>(numLinks), Eigen::Vector3d::Zero());
  for (int l = 0; l < numLinks && static_cast<size_t>(l) < model.bodyElements.size(); ++l) {
    for (int e : model.bodyElements[l]) {
      if (model.elements[e].isPoint) {
        twistOrigin_[static_cast<size_t>(l)] = element3(e);
        break;
      }
    }
  }
}

Eigen::Vector3d SearchContext::element3(int e) const {
  const int o = model.elements[e].offset;
  return dim == 3 ? Eigen::Vector3d(q.segment<3>(o)) : Eigen::Vector3d(q(o), q(o + 1), 0.0);
}

TwistRow SearchContext::twistRow(int e, int k, const Eigen::Vector3d& about) const {
  const int o = model.elements[e].offset;
  const bool isPoint = model.elements[e].isPoint;
  const double point = isPoint ? 1.0 : 0.0;
  TwistRow t = TwistRow::Zero();
  if (planar) {  // omega_z, v_x, v_y of x_k: (-y, 1, 0) and (x, 0, 1) for a point
    if (k == 0)
      t.head<3>() << -(q(o + 1) - (isPoint ? about.y() : 0.0)), point, 0.0;
    else
      t.head<3>() << q(o) - (isPoint ? about.x() : 0.0), 0.0, point;
    return t;
  }
  const Eigen::Vector3d shift = isPoint ? about : Eigen::Vector3d::Zero();
  const double x = q(o) - shift.x(), y = q(o + 1) - shift.y(), z = q(o + 2) - shift.z();
  if (k == 0)
    t << 0.0, z, -y, point, 0.0, 0.0;
  else if (k == 1)
    t << -z, 0.0, x, 0.0, point, 0.0;
  else
    t << y, -x, 0.0, 0.0, 0.0, point;
  return t;
}

int SearchContext::otherLink(int j, int l) const {
  const std::pair<int, int>& ends = jointEnds[static_cast<size_t>(j)];
  return ends.first == l ? ends.second : ends.first;
}

/// The end-connection bound (PassiveFreedomsOptions, with its proof): per link l, F_l = the sum over the
/// rows r touching l of |a_{r,l}|^2, where a_{r,l} is row r (scaled to unit norm) on l's columns times T;
/// and for each of the two connections of a link that may be in a group, the Gram matrix of a_{r,l} over
/// that connection's rows, valid when each of those rows touches the connection's two links only.
class EndConnectionBound {
 public:
  explicit EndConnectionBound(const SearchContext& context);

  /// Whether the group's two end connections alone prove that no twist of it passes the nullity test of
  /// the search (PassiveFreedomsOptions): true settles the group with no motion; false decides nothing.
  bool rigidByEnds(const std::vector<int>& path) const;

 private:
  /// rigidByEnds for lambda = @p L: the Gram sums unrolled (3 10^5 groups on a chain of 10^5).
  template <int L>
  bool rigidByEndsOf(const std::vector<int>& path) const;
  static constexpr size_t kLinksPerRow = 4;
  /// Per coordinate, the element and the link that own it.
  struct ColumnOwner {
    int element = -1, link = -1;
  };
  using ColumnOwners = std::vector<ColumnOwner>;  // side by side: one cache line a column
  /// One row of J, scaled to unit norm, times T, split into its parts a_{r,l} on each link it touches.
  struct RowParts {
    std::array<std::pair<int, TwistRow>, kLinksPerRow> perLink;
    size_t used = 0;
    bool overflow = false;  ///< The row touches more than kLinksPerRow links.
  };

  ColumnOwners findColumnOwners() const;
  void splitRow(Eigen::Index r, const ColumnOwners& owners, RowParts& parts);
  void addRow(Eigen::Index r, const RowParts& parts);
  /// addRow for lambda = @p L (the Gram updates unrolled).
  template <int L>
  void addRowOf(Eigen::Index r, const RowParts& parts);
  /// Which of @p link's two connections @p joint is (0 or 1), or -1.
  int slotOf(int link, int joint) const;

  const SearchContext& context_;
  const size_t gramSize_;
  std::vector<double> linkFrobenius_;
  // Per link, per connection slot 0 or 1: the lower triangle of the lambda x lambda Gram matrix, row by row
  // (clearlyFullRank reads no other entry; 6 of 9 numbers in the plane, 21 of 36 in space).
  std::vector<double> endGram_;
  std::vector<char> endValid_;  // per link and slot
};

EndConnectionBound::EndConnectionBound(const SearchContext& context)
    : context_(context), gramSize_(static_cast<size_t>(context.lambda * (context.lambda + 1) / 2)) {
  const ColumnOwners owners = findColumnOwners();
  const size_t numLinks = static_cast<size_t>(context_.numLinks);
  linkFrobenius_.assign(numLinks, 0.0);
  endGram_.assign(numLinks * 2 * gramSize_, 0.0);
  endValid_.assign(numLinks * 2, 1);
  RowParts parts;
  for (Eigen::Index r = 0; r < context_.J.rows(); ++r) {
    splitRow(r, owners, parts);
    addRow(r, parts);
  }
}

EndConnectionBound::ColumnOwners EndConnectionBound::findColumnOwners() const {
  const CoordinateModel& model = context_.model;
  ColumnOwners owners(static_cast<size_t>(model.numCoordinates()));
  for (size_t l = 0; l < model.bodyElements.size(); ++l) {
    for (int e : model.bodyElements[l]) {
      for (int k = 0; k < context_.dim; ++k)
        owners[static_cast<size_t>(model.elements[e].offset + k)] = ColumnOwner{e, static_cast<int>(l)};
    }
  }
  return owners;
}

void EndConnectionBound::splitRow(Eigen::Index r, const ColumnOwners& owners, RowParts& parts) {
  parts.used = 0;
  parts.overflow = false;
  const double norm = context_.rowNorm[static_cast<size_t>(r)];
  for (SparseJacobian::InnerIterator it(context_.J, r); it; ++it) {
    const ColumnOwner& owner = owners[static_cast<size_t>(it.col())];
    const int l = owner.link;
    size_t slot = 0;
    while (slot < parts.used && parts.perLink[slot].first != l)
      ++slot;
    if (slot == parts.used) {
      if (parts.used == kLinksPerRow) {  // a row on more than four links: no bound for the links it touches
        parts.overflow = true;
        linkFrobenius_[static_cast<size_t>(l)] = std::numeric_limits<double>::infinity();
        continue;
      }
      parts.perLink[parts.used++] = {l, TwistRow::Zero()};
    }
    const int e = owner.element;
    const int k = static_cast<int>(it.col()) - context_.model.elements[e].offset;
    parts.perLink[slot].second += (it.value() / norm) * context_.twistRow(e, k, context_.twistOrigin(l));
  }
}

void EndConnectionBound::addRow(Eigen::Index r, const RowParts& parts) {
  if (context_.planar)
    addRowOf<3>(r, parts);
  else
    addRowOf<6>(r, parts);
}

template <int L>
void EndConnectionBound::addRowOf(Eigen::Index r, const RowParts& parts) {
  constexpr int lambda = L;
  const int connection = context_.jointOfRow[static_cast<size_t>(r)];
  const std::pair<int, int>* joint =
      connection >= 0 ? &context_.jointEnds[static_cast<size_t>(connection)] : nullptr;
  bool twoLinks = joint != nullptr && !parts.overflow;
  for (size_t s = 0; s < parts.used; ++s)
    twoLinks =
        twoLinks && (parts.perLink[s].first == joint->first || parts.perLink[s].first == joint->second);
  for (size_t s = 0; s < parts.used; ++s) {
    const int l = parts.perLink[s].first;
    linkFrobenius_[static_cast<size_t>(l)] +=
        parts.overflow ? std::numeric_limits<double>::infinity() : parts.perLink[s].second.squaredNorm();
    if (joint == nullptr)
      continue;
    const int end = slotOf(l, connection);
    if (end < 0)
      continue;
    const size_t at = static_cast<size_t>(l) * 2 + static_cast<size_t>(end);
    double* gram = &endGram_[at * gramSize_];
    const TwistRow& a = parts.perLink[s].second;
    for (int r1 = 0; r1 < lambda; ++r1) {
      for (int c1 = 0; c1 <= r1; ++c1)
        *gram++ += a(r1) * a(c1);
    }
  }
  if (joint != nullptr && !twoLinks) {  // this connection's rows are not all rows of A on the end link
    for (int l : {joint->first, joint->second}) {
      const int end = slotOf(l, connection);
      if (end >= 0)
        endValid_[static_cast<size_t>(l) * 2 + static_cast<size_t>(end)] = 0;
    }
  }
}

int EndConnectionBound::slotOf(int link, int joint) const {
  const core_detail::BucketRange at = context_.connectionsAt(link);
  return at.size() != 2 ? -1 : at[0] == joint ? 0 : at[1] == joint ? 1 : -1;
}

bool EndConnectionBound::rigidByEnds(const std::vector<int>& path) const {
  return context_.planar ? rigidByEndsOf<3>(path) : rigidByEndsOf<6>(path);
}

/// S with t_from = S t_to for one motion written as the twist t_to about a point and as t_from about a point
/// @p delta away from it: omega the same, v_from = v_to + omega x delta.
template <int L>
Eigen::Matrix<double, L, L> twistShift(const Eigen::Vector3d& delta) {
  Eigen::Matrix<double, L, L> S = Eigen::Matrix<double, L, L>::Identity();
  if constexpr (L == 3) {  // omega_z, v_x, v_y
    S(1, 0) = -delta.y();
    S(2, 0) = delta.x();
  } else {
    S.template block<3, 3>(3, 0) << 0.0, delta.z(), -delta.y(), -delta.z(), 0.0, delta.x(), delta.y(),
        -delta.x(), 0.0;
  }
  return S;
}

template <int L>
bool EndConnectionBound::rigidByEndsOf(const std::vector<int>& path) const {
  constexpr int lambda = L;
  // Each link's sums are about its own twist origin; the group's are about its lowest link's, where the
  // search takes its twists (GroupSearch): an end's Gram moves there exactly (S^T G S), and F_l at most by
  // |S|_2^2 <= (1 + |delta|)^2, which can only make the bound more cautious.
  const Eigen::Vector3d& about = context_.twistOrigin(*std::min_element(path.begin(), path.end()));
  Eigen::Matrix<double, L, L> gram = Eigen::Matrix<double, L, L>::Zero();
  double frobenius2 = 0.0;
  int ends = 0;
  auto inPath = [&path](int link) {  // at most kMaxGroup links
    for (const int l : path) {
      if (l == link)
        return true;
    }
    return false;
  };
  for (int l : path) {
    const Eigen::Vector3d delta = context_.twistOrigin(l) - about;
    const double stretch = 1.0 + delta.norm();
    frobenius2 += linkFrobenius_[static_cast<size_t>(l)] * stretch * stretch;
    for (size_t s = 0; s < 2; ++s) {
      if (inPath(context_.otherLink(context_.connectionsAt(l)[s], l)))
        continue;
      const size_t at = static_cast<size_t>(l) * 2 + s;
      if (!endValid_[at])
        return false;
      ++ends;
      const double* packed = &endGram_[at * gramSize_];
      Eigen::Matrix<double, L, L> end;
      for (int r1 = 0; r1 < lambda; ++r1) {
        for (int c1 = 0; c1 <= r1; ++c1)
          end(r1, c1) = end(c1, r1) = *packed++;
      }
      if (delta.isZero(0.0)) {
        gram += end;
      } else {
        const Eigen::Matrix<double, L, L> S = twistShift<L>(delta);
        gram.noalias() += S.transpose() * end * S;
      }
    }
  }
  frobenius2 *= static_cast<double>(path.size());
  if (ends != 2 || !std::isfinite(frobenius2))
    return false;
  const double limit = 100.0 * kTwistNullity * std::max(std::sqrt(frobenius2), 1.0);
  return clearlyFullRank<L>(gram, limit);
}

/// A candidate group's links, sorted and padded with -1, so that the groups sort (and are taken) as sorted
/// vectors would.
using Group = std::array<int, kMaxGroupLinks>;

struct CandidateGroups {
  std::vector<Group> groups;  ///< Sorted, each once.
  int rigidByEnds = 0;        ///< Groups the end-connection bound settled (not in groups).
};

/// Adds the chain @p path as a group, unless it is the reverse of a chain met already or @p bound (when
/// given) settles it.
void addGroup(const std::vector<int>& path, const EndConnectionBound* bound, CandidateGroups& candidates) {
  if (path.front() > path.back())
    return;  // the same links are met from the other end, as the reversed path
  if (bound != nullptr && bound->rigidByEnds(path)) {
    ++candidates.rigidByEnds;
    return;
  }
  Group group;
  group.fill(-1);
  for (size_t i = 0; i < path.size(); ++i) {  // insertion sort of at most kMaxGroupLinks links
    size_t k = i;
    for (; k > 0 && group[k - 1] > path[i]; --k)
      group[k] = group[k - 1];
    group[k] = path[i];
  }
  candidates.groups.push_back(group);
}

/// Adds every chain that continues @p path (of @p bodies rigid bodies) by links with two connections, up to
/// kMaxGroup bodies.
void extendChain(const SearchContext& context, std::vector<int>& path, size_t bodies,
                 const EndConnectionBound* bound, CandidateGroups& candidates) {
  if (path.size() >= kMaxGroupLinks)
    return;
  const int last = path.back();
  if (context.connectionsAt(last).size() != 2)
    return;
  for (int j : context.connectionsAt(last)) {
    const int next = context.otherLink(j, last);
    const size_t more = bodies + (context.weld[static_cast<size_t>(j)] ? 0 : 1);
    if (more > kMaxGroup || next == context.mechanism.rootLink || context.connectionsAt(next).size() != 2 ||
        std::find(path.begin(), path.end(), next) != path.end())
      continue;
    path.push_back(next);
    addGroup(path, bound, candidates);
    extendChain(context, path, more, bound, candidates);
    path.pop_back();
  }
}

/// Candidate groups: every link with two connections but the ground, and chains of such links. A group the
/// end-connection bound settles has no motion and is not kept (the order of the others is unchanged).
CandidateGroups findCandidateGroups(const SearchContext& context, const EndConnectionBound* bound) {
  CandidateGroups candidates;
  std::vector<int> chain;
  for (int l = 0; l < context.numLinks; ++l) {
    if (l == context.mechanism.rootLink || context.connectionsAt(l).size() != 2)
      continue;
    chain.assign(1, l);
    addGroup(chain, bound, candidates);
    extendChain(context, chain, 1, bound, candidates);
  }
  std::vector<Group>& groups = candidates.groups;
  std::sort(groups.begin(), groups.end());
  groups.erase(std::unique(groups.begin(), groups.end()), groups.end());
  return candidates;
}

/// Each link's position along the chains of links with two connections (the ground excepted), the links
/// idle groups are made of: a group's links lie at consecutive positions (or wrap around a ring of such
/// links, which is reduced last); -1 for every other link.
std::vector<int> chainPositions(const SearchContext& context) {
  const int root = context.mechanism.rootLink;
  auto inChain = [&](int l) { return l != root && context.connectionsAt(l).size() == 2; };
  std::vector<int> position(static_cast<size_t>(context.numLinks), -1);
  int next = 0;
  for (int l = 0; l < context.numLinks; ++l) {
    if (!inChain(l) || position[static_cast<size_t>(l)] >= 0)
      continue;
    // Back to one end of l's chain (on a ring: round to the link before l).
    int end = l, previous = -1;
    for (int steps = 0; steps < context.numLinks; ++steps) {
      const core_detail::BucketRange connections = context.connectionsAt(end);
      const int a = context.otherLink(connections[0], end), b = context.otherLink(connections[1], end);
      const int towards = a != previous ? a : b;
      if (towards == previous || towards == l || !inChain(towards))
        break;
      previous = end;
      end = towards;
    }
    // Then along the chain from that end, numbering.
    for (int at = end; at >= 0;) {
      position[static_cast<size_t>(at)] = next++;
      int following = -1;
      for (int j : context.connectionsAt(at)) {
        const int other = context.otherLink(j, at);
        if (inChain(other) && position[static_cast<size_t>(other)] < 0) {
          following = other;
          break;
        }
      }
      at = following;
    }
  }
  return position;
}

/// Where MotionSpan reads each coordinate: its position along the chains, and the factor its entries are
/// taken at.
struct CoordinateLayout {
  std::vector<int> position;  ///< The least position of the links whose elements hold it (-1: none).
  /// A point's coordinates are divided by the length of the link at that position (the largest distance of
  /// its points from its first), a unit vector's taken as they are: a motion is compared in the units of its
  /// own links, rad for a turn. In the model's units (lengths in Lc) the ball-jointed rods of a ring 64 m
  /// across, 0.1 m long each, move their points 600 times less than their directions: two rods nearly in
  /// line, turned as a pair about their end balls, differed from their two spins by 1e-6, the tolerance.
  std::vector<double> scale;
};

CoordinateLayout coordinateLayout(const SearchContext& context, const std::vector<int>& linkPosition) {
  const CoordinateModel& model = context.model;
  const size_t numCoordinates = static_cast<size_t>(model.numCoordinates());
  CoordinateLayout layout{std::vector<int>(numCoordinates, -1), std::vector<double>(numCoordinates, 1.0)};
  for (size_t l = 0; l < linkPosition.size() && l < model.bodyElements.size(); ++l) {
    const int at = linkPosition[l];
    if (at < 0)
      continue;
    double length = 0.0;
    for (int e : model.bodyElements[l]) {
      if (model.elements[e].isPoint)
        length = std::max(length, (context.element3(e) - context.twistOrigin(static_cast<int>(l))).norm());
    }
    for (int e : model.bodyElements[l]) {
      for (int k = 0; k < context.dim; ++k) {
        const size_t c = static_cast<size_t>(model.elements[e].offset + k);
        if (layout.position[c] >= 0 && layout.position[c] < at)
          continue;  // held by a link before this one: read at its position, in its length
        layout.position[c] = at;
        layout.scale[c] = model.elements[e].isPoint && length > 0.0 ? 1.0 / length : 1.0;
      }
    }
  }
  return layout;
}

/// The order the groups are searched in: by the last position of their links, then the shorter first (a
/// group after every group it contains, and MotionSpan's rows end by the position of the motion it reduces).
std::vector<size_t> searchOrder(const std::vector<Group>& groups, const std::vector<int>& linkPosition) {
  struct Key {
    int last, first;
    size_t index;
  };
  std::vector<Key> keys;
  keys.reserve(groups.size());
  for (size_t g = 0; g < groups.size(); ++g) {
    Key key{-1, std::numeric_limits<int>::max(), g};
    for (int l : groups[g]) {
      if (l < 0)
        break;
      key.last = std::max(key.last, linkPosition[static_cast<size_t>(l)]);
      key.first = std::min(key.first, linkPosition[static_cast<size_t>(l)]);
    }
    keys.push_back(key);
  }
  std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
    return a.last != b.last ? a.last < b.last : a.first != b.first ? a.first > b.first : a.index < b.index;
  });
  std::vector<size_t> order;
  order.reserve(keys.size());
  for (const Key& key : keys)
    order.push_back(key.index);
  return order;
}

/// "(0, 0.707, -0.707)": a unit direction, three digits, rounding noise shown as 0.
std::string directionText(const Eigen::Vector3d& direction) {
  std::string text = "(";
  for (int k = 0; k < 3; ++k) {
    char buffer[32];
    const double x = std::abs(direction(k)) < 1e-9 ? 0.0 : direction(k);
    std::snprintf(buffer, sizeof(buffer), "%.3g", x);
    text += (k == 0 ? "" : ", ") + std::string(buffer);
  }
  return text + ")";
}

/// The search of the candidate groups: a group's null twists, the finite check of each, and whether it adds
/// a dimension to the span of the motions kept so far.
class GroupSearch {
 public:
  GroupSearch(const SearchContext& context, CoordinateLayout layout);

  /// Searches the group @p padded: counts it in @p result if it qualifies and appends its new motions.
  void search(const Group& padded, PassiveFreedoms& result);

 private:
  /// A motion as (coordinate, value) over its group's coordinates.
  using Motion = core_detail::SparseMotion;

  void searchMarked(PassiveFreedoms& result);
  bool hasTwoEndsToTwoLinks();
  void collectColumnsAndRows();
  bool boundsClearNullity() const;
  Eigen::MatrixXd buildT() const;
  Eigen::MatrixXd buildA(const Eigen::MatrixXd& T) const;
  void clearLocalColumns();
  void searchNullTwists(const Eigen::MatrixXd& T, const Eigen::MatrixXd& A, PassiveFreedoms& result);
  bool movesFinitely(const Eigen::Vector3d& omega, const Eigen::Vector3d& v);
  PassiveMotion describe(const Eigen::Vector3d& omega, const Eigen::Vector3d& v) const;
  bool endsOnLine(const Eigen::Vector3d& point, const Eigen::Vector3d& direction) const;
  bool alongEnds(const Eigen::Vector3d& direction) const;
  bool isEnd(int j) const;
  std::string endsPhrase() const;

  const SearchContext& context_;
  // Column access, made when a group first needs it (none does on a serial chain).
  Eigen::SparseMatrix<double> Jc_;
  bool haveColumns_ = false;
  std::vector<char> inGroup_;
  // The span of the motions kept (a chain of 10^5 links has 3 10^5 candidate groups: a new motion is
  // reduced within its own chain only).
  std::vector<double> scale_;  // CoordinateLayout::scale
  core_detail::MotionSpan span_;
  std::vector<int> localColumn_;
  Eigen::VectorXd moved_;  // q, copied when a first twist is stepped
  // Work space of one group, reused (a chain of 10^5 links has 3 10^5 groups: no allocation per group).
  std::vector<int> group_, outside_, elements_, columns_, rows_;
  std::vector<TwistRow> twistRows_;  // the rows of T (lambda entries, zero beyond)
  Motion motion_;                    // a null twist's motion (T xi, scaled)
  Eigen::VectorXd local_;
  Eigen::Vector3d about_ = Eigen::Vector3d::Zero();  // the point the group's twists are about
};

GroupSearch::GroupSearch(const SearchContext& context, CoordinateLayout layout)
    : context_(context),
      inGroup_(context.numLinks, 0),
      scale_(std::move(layout.scale)),
      span_(std::move(layout.position), kMotionIndependence),
      localColumn_(context.model.numCoordinates(), -1) {}

void GroupSearch::search(const Group& padded, PassiveFreedoms& result) {
  group_.assign(padded.begin(), std::find(padded.begin(), padded.end(), -1));
  for (int l : group_)
    inGroup_[l] = 1;
  searchMarked(result);
  for (int l : group_)  // inGroup_ back to all zero
    inGroup_[l] = 0;
}

void GroupSearch::searchMarked(PassiveFreedoms& result) {
  if (!hasTwoEndsToTwoLinks())
    return;
  ++result.groupsSearched;
  collectColumnsAndRows();
  if (static_cast<int>(rows_.size()) >= context_.lambda && boundsClearNullity()) {
    clearLocalColumns();
    return;
  }
  const Eigen::MatrixXd T = buildT();
  const Eigen::MatrixXd A = buildA(T);
  clearLocalColumns();
  searchNullTwists(T, A, result);
}

/// The group's end connections must reach at least two other links: a link turning on connections to one
/// link only (a door on its hinges, a robot's last link) is that link's output, not an idle motion.
bool GroupSearch::hasTwoEndsToTwoLinks() {
  const Mechanism& mechanism = context_.mechanism;
  outside_.clear();
  for (int l : group_) {
    for (int j : context_.connectionsAt(l)) {
      const Joint& joint = mechanism.joints[j];
      if (!inGroup_[joint.link1])
        outside_.push_back(joint.link1);
      if (!inGroup_[joint.link2])
        outside_.push_back(joint.link2);
    }
  }
  std::sort(outside_.begin(), outside_.end());
  outside_.erase(std::unique(outside_.begin(), outside_.end()), outside_.end());
  int ends = 0;
  for (int l : group_) {
    for (int j : context_.connectionsAt(l))
      ends += isEnd(j) ? 1 : 0;
  }
  return outside_.size() >= 2 && ends == 2;
}

/// T: coordinates of the group's elements per twist component (space: omega, v; plane: omega_z, v_x, v_y),
/// the rows of J that touch them, and localColumn_ set to each group coordinate's row of T.
void GroupSearch::collectColumnsAndRows() {
  const CoordinateModel& model = context_.model;
  elements_.clear();
  for (int l : group_)
    elements_.insert(elements_.end(), model.bodyElements[l].begin(), model.bodyElements[l].end());
  columns_.clear();
  twistRows_.clear();
  about_ = context_.twistOrigin(group_.front());  // group_ is sorted: its lowest link
  for (int e : elements_) {
    for (int k = 0; k < context_.dim; ++k) {
      columns_.push_back(model.elements[e].offset + k);
      twistRows_.push_back(context_.twistRow(e, k, about_));
    }
  }
  rows_.clear();
  if (!haveColumns_) {
    Jc_ = context_.J;
    haveColumns_ = true;
  }
  for (int c : columns_) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(Jc_, c); it; ++it)
      rows_.push_back(static_cast<int>(it.row()));
  }
  std::sort(rows_.begin(), rows_.end());
  rows_.erase(std::unique(rows_.begin(), rows_.end()), rows_.end());
  for (size_t c = 0; c < columns_.size(); ++c)
    localColumn_[columns_[c]] = static_cast<int>(c);
}

/// Most groups (every link of a serial chain) have no null twist at all. sigma_min(A)^2 is at least
/// 1 / |(A^T A)^-1|_F and sigma_max(A) at most |A|_F: when these bounds clear the nullity test a
/// hundredfold (far beyond what rounding in A^T A can move them), no twist can pass it and the SVD is
/// skipped; otherwise it decides exactly as before. A^T A is summed row by row in fixed-size storage (at
/// most 6 x 6), A itself is built only for the SVD.
bool GroupSearch::boundsClearNullity() const {
  Eigen::Matrix<double, 6, 6> gram = Eigen::Matrix<double, 6, 6>::Zero();
  double frobenius2 = 0.0;
  TwistRow a;
  for (int r : rows_) {
    a.setZero();
    const double norm = context_.rowNorm[static_cast<size_t>(r)];
    for (SparseJacobian::InnerIterator it(context_.J, r); it; ++it) {
      const int c = localColumn_[it.col()];
      if (c >= 0)
        a += (it.value() / norm) * twistRows_[static_cast<size_t>(c)];
    }
    gram.noalias() += a.transpose() * a;
    frobenius2 += a.squaredNorm();
  }
  const double bound = 100.0 * kTwistNullity * std::max(std::sqrt(frobenius2), 1.0);
  return context_.planar ? clearlyFullRank<3>(gram.topLeftCorner<3, 3>().eval(), bound)
                         : clearlyFullRank<6>(gram, bound);
}

Eigen::MatrixXd GroupSearch::buildT() const {
  Eigen::MatrixXd T(static_cast<Eigen::Index>(twistRows_.size()), context_.lambda);
  for (size_t c = 0; c < twistRows_.size(); ++c)
    T.row(static_cast<Eigen::Index>(c)) = twistRows_[c].head(context_.lambda);
  return T;
}

/// A = J(rows touching the group, group columns) T, rows scaled to unit norm.
Eigen::MatrixXd GroupSearch::buildA(const Eigen::MatrixXd& T) const {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rows_.size()), context_.lambda);
  for (size_t r = 0; r < rows_.size(); ++r) {
    const double norm = context_.rowNorm[static_cast<size_t>(rows_[r])];
    for (SparseJacobian::InnerIterator it(context_.J, rows_[r]); it; ++it) {
      const int c = localColumn_[it.col()];
      if (c >= 0)
        A.row(static_cast<Eigen::Index>(r)) += (it.value() / norm) * T.row(c);
    }
  }
  return A;
}

void GroupSearch::clearLocalColumns() {
  for (int c : columns_)
    localColumn_[c] = -1;
}

/// Each twist xi that A (nearly) annihilates is a motion when it is also finite and independent of the
/// motions kept so far.
void GroupSearch::searchNullTwists(const Eigen::MatrixXd& T, const Eigen::MatrixXd& A,
                                   PassiveFreedoms& result) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::VectorXd sigma = svd.singularValues();
  const double largest = sigma.size() > 0 ? sigma(0) : 0.0;
  for (int k = 0; k < context_.lambda; ++k) {
    if (k < sigma.size() && sigma(k) > kTwistNullity * std::max(largest, 1.0))
      continue;
    const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1> xi = svd.matrixV().col(k);
    Eigen::Vector3d omega, v;
    if (context_.planar) {
      omega = Eigen::Vector3d(0.0, 0.0, xi(0));
      v = Eigen::Vector3d(xi(1), xi(2), 0.0);
    } else {
      omega = xi.head<3>();
      v = xi.tail<3>();
    }
    // A motion in the span of those kept adds nothing whether or not it is finite: that is decided first,
    // the finite step (the costlier check) only for a motion that would add a dimension.
    local_.noalias() = T * xi;
    motion_.clear();
    for (size_t c = 0; c < columns_.size(); ++c)
      motion_.emplace_back(columns_[c],
                           scale_[static_cast<size_t>(columns_[c])] * local_(static_cast<Eigen::Index>(c)));
    if (!span_.isIndependent(motion_) || !movesFinitely(omega, v))
      continue;
    span_.keep();
    result.motions.push_back(describe(omega, v));
  }
}

/// Finite: the group moved by exp(step xi) keeps every constraint.
bool GroupSearch::movesFinitely(const Eigen::Vector3d& omega, const Eigen::Vector3d& v) {
  const CoordinateModel& model = context_.model;
  const int dim = context_.dim;
  const double scale = kFiniteStep / std::max(omega.norm(), v.norm());
  const Eigen::Isometry3d g = exponential(scale * omega, scale * v);
  // (moved_ is q outside the group: one copy for all groups, put back after each.)
  if (moved_.size() == 0)
    moved_ = context_.q;
  for (int e : elements_) {
    const Eigen::Vector3d x = context_.element3(e);
    // The twist is about about_: a point moves as about_ + g (x - about_).
    const Eigen::Vector3d y =
        model.elements[e].isPoint ? (about_ + g * (x - about_)).eval() : (g.linear() * x).eval();
    moved_.segment(model.elements[e].offset, dim) = y.head(dim);
  }
  // Only the rows touching the group can change.
  const ElementView before(model, context_.q), after(model, moved_);
  double change = 0.0;
  for (int r : rows_) {
    const ConstraintEquation& eq = model.equations[r];
    change = std::max(change, std::abs(visitForm(eq.form, [&](auto form) {
                        return form.value(after, eq) - form.value(before, eq);
                      })));
  }
  for (int e : elements_)
    moved_.segment(model.elements[e].offset, dim) = context_.q.segment(model.elements[e].offset, dim);
  return !(change > kFiniteResidual);
}

/// The phrase: the group, what it does, and the connections it turns or slides between.
PassiveMotion GroupSearch::describe(const Eigen::Vector3d& omega, const Eigen::Vector3d& v) const {
  PassiveMotion passive;
  std::string names;
  for (int l : group_) {
    passive.links.push_back(context_.mechanism.links[l].name);
    names += (names.empty() ? "" : "-") + context_.mechanism.links[l].name;
  }
  const std::string ends = endsPhrase();
  const std::string subject = (group_.size() == 1 ? "link " : "chain ") + names;
  if (omega.norm() < 1e-9 * v.norm()) {
    const Eigen::Vector3d direction = v.normalized();
    passive.description =
        alongEnds(direction) ? subject + " slides along the line of its " + ends
                             : subject + " slides along " + directionText(direction) + " between its " + ends;
    return passive;
  }
  // The twist's axis: the points moving along it, about_ + omega x v / |omega|^2 (Murray, Li & Sastry §2.2).
  const Eigen::Vector3d axis = omega.normalized(), through = about_ + omega.cross(v) / omega.squaredNorm();
  const bool screws = std::abs(axis.dot(v)) > 1e-6 * v.norm() + 1e-12;
  if (endsOnLine(through, axis))
    passive.description =
        subject + (screws ? " screws about the line of its " : " spins about the line through its ") + ends;
  else
    passive.description = subject + (screws ? " screws" : " turns") + " about an axis along " +
                          directionText(axis) + " between its " + ends;
  return passive;
}

/// Whether the group's end connections, at their points on the group, lie on the line through @p point
/// along the unit @p direction (lengths in Lc; a connection with no point there, such as a planar joint's,
/// does not).
bool GroupSearch::endsOnLine(const Eigen::Vector3d& point, const Eigen::Vector3d& direction) const {
  int found = 0;
  for (int e : elements_) {
    const Element& element = context_.model.elements[e];
    if (element.role != ElementRole::JointPoint || !isEnd(element.joint))
      continue;
    if ((context_.element3(e) - point).cross(direction).norm() > kLineTolerance)
      return false;
    ++found;
  }
  return found >= 2;
}

/// Whether @p direction (a unit slide) is the line of the group's ends: parallel to the axes the end
/// connections have on the group (two parallel prismatic joints), or to the line through their points.
bool GroupSearch::alongEnds(const Eigen::Vector3d& direction) const {
  std::vector<Eigen::Vector3d> points;
  bool axes = false, parallel = true;
  for (int e : elements_) {
    const Element& element = context_.model.elements[e];
    if (!isEnd(element.joint))
      continue;
    if (element.role == ElementRole::JointPoint) {
      points.push_back(context_.element3(e));
    } else if (element.role == ElementRole::JointAxis) {
      axes = true;
      parallel = parallel && context_.element3(e).cross(direction).norm() <= kLineTolerance;
    }
  }
  if (axes && parallel)
    return true;
  return points.size() == 2 && (points[1] - points[0]).norm() > kLineTolerance &&
         (points[1] - points[0]).normalized().cross(direction).norm() <= kLineTolerance;
}

/// Whether connection @p j (an element's joint, -1 for none) is one of the group's end connections.
bool GroupSearch::isEnd(int j) const {
  if (j < 0)
    return false;
  const std::pair<int, int>& ends = context_.jointEnds[static_cast<size_t>(j)];
  return inGroup_[ends.first] != inGroup_[ends.second];
}

/// The group's end connections, "revolute joints j1 and j2" (their kind named when they share one).
std::string GroupSearch::endsPhrase() const {
  const Mechanism& mechanism = context_.mechanism;
  std::vector<int> ends;
  std::set<std::string> types;
  for (int l : group_) {
    for (int j : context_.connectionsAt(l)) {
      if (!isEnd(j))
        continue;
      const Joint& joint = mechanism.joints[j];
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
  return jointWord + " " + endText;
}

}  // namespace

PassiveFreedoms findPassiveFreedoms(const Mechanism& mechanism, const CoordinateModel& model,
                                    const Eigen::Ref<const Eigen::VectorXd>& q, const SparseJacobian& J,
                                    const PassiveFreedomsOptions& options) {
  PassiveFreedoms result;
  const SearchContext context(mechanism, model, q, J);
  std::optional<EndConnectionBound> bound;
  if (options.endConnectionBound)
    bound.emplace(context);
  const CandidateGroups candidates = findCandidateGroups(context, bound ? &*bound : nullptr);
  result.groupsRigidByEnds = candidates.rigidByEnds;
  if (candidates.groups.empty())
    return result;
  const std::vector<int> linkPosition = chainPositions(context);
  GroupSearch search(context, coordinateLayout(context, linkPosition));
  // Searched in chain order (MotionSpan), listed in the groups' sorted order, each group's motions together.
  std::vector<size_t> groupOfMotion;
  for (size_t g : searchOrder(candidates.groups, linkPosition)) {
    search.search(candidates.groups[g], result);
    groupOfMotion.resize(result.motions.size(), g);
  }
  std::vector<size_t> listed(result.motions.size());
  for (size_t m = 0; m < listed.size(); ++m)
    listed[m] = m;
  std::stable_sort(listed.begin(), listed.end(),
                   [&](size_t a, size_t b) { return groupOfMotion[a] < groupOfMotion[b]; });
  std::vector<PassiveMotion> motions;
  motions.reserve(listed.size());
  for (size_t m : listed)
    motions.push_back(std::move(result.motions[m]));
  result.motions = std::move(motions);
  result.dof = static_cast<int>(result.motions.size());
  return result;
}

}  // namespace mobility_analysis
