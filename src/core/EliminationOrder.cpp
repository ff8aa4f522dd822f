#include "mobility_analysis/EliminationOrder.hpp"

#include <algorithm>
#include <numeric>
#include <queue>
#include <tuple>

#include <amd.h>

#include "Buckets.hpp"

namespace mobility_analysis {

namespace {

using core_detail::BucketRange;
using core_detail::Buckets;

/// Connections of one link sorted by insertion, at most.
constexpr size_t kInsertionSortMax = 16;

/// The equations grouped by what releases them and the links each connection couples, read once from the
/// model: what a sweep over the links needs, whatever the order of the links.
struct SweepGraph {
  SweepGraph(const Mechanism& mechanism, const CoordinateModel& model);
  int numLinks;
  Buckets rowsOf;  ///< Link rows by link, then boundary rows by link, then joint rows by joint.
  std::vector<std::pair<int, int>> ends;
  Buckets incidentOf;
  std::vector<char> expressed;
  BucketRange linkRows(int l) const { return rowsOf[l]; }
  BucketRange boundaryRows(int l) const { return rowsOf[numLinks + l]; }
  BucketRange jointRows(int j) const { return rowsOf[2 * numLinks + j]; }
  BucketRange incident(int l) const { return incidentOf[l]; }
  int otherEnd(int joint, int link) const {
    const std::pair<int, int>& e = ends[static_cast<size_t>(joint)];
    return e.first == link ? e.second : e.first;
  }
};

SweepGraph::SweepGraph(const Mechanism& mechanism, const CoordinateModel& model)
    : numLinks(static_cast<int>(mechanism.links.size())),
      rowsOf(2 * static_cast<int>(mechanism.links.size()) + static_cast<int>(mechanism.joints.size())),
      incidentOf(static_cast<int>(mechanism.links.size())) {
  const int numJoints = static_cast<int>(mechanism.joints.size());

  // One read of the equations (about 110 bytes each, 55 MB for 5 10^5 of them): each row's group, numbered
  // link rows, then boundary rows by link, then joint rows by joint, and the elements that rigid-link
  // equations express (below); the rows are then filed from those compact keys.
  const int numRows = model.numConstraints();
  std::vector<int> groupOfRow(static_cast<size_t>(numRows));
  expressed.assign(model.elements.size(), 0);
  for (int r = 0; r < numRows; ++r) {
    const ConstraintEquation& eq = model.equations[r];
    const int group = eq.source == EquationSource::Link       ? eq.element
                      : eq.source == EquationSource::Boundary ? numLinks + eq.element
                                                              : 2 * numLinks + eq.element;
    groupOfRow[static_cast<size_t>(r)] = group;
    rowsOf.count(group);
    if (eq.form == EquationForm::Combination)
      expressed[eq.target()] = 1;
  }
  rowsOf.allocate();
  for (int r = 0; r < numRows; ++r)
    rowsOf.add(groupOfRow[static_cast<size_t>(r)], r);
  // Each connection's two links, read once (a Joint holds its frames and name: hundreds of bytes).
  ends.resize(static_cast<size_t>(numJoints));
  for (int j = 0; j < numJoints; ++j)
    ends[static_cast<size_t>(j)] = {mechanism.joints[j].link1, mechanism.joints[j].link2};
  // Only connections with equations couple their links: a floating joint (a link held by loop joints alone)
  // or a slack cable would let the sweep jump from the ground straight into the middle of the mechanism.
  auto couples = [&](int j) {
    return !rowsOf[2 * numLinks + j].empty() &&
           ends[static_cast<size_t>(j)].first != ends[static_cast<size_t>(j)].second;
  };
  for (int j = 0; j < numJoints; ++j) {
    if (couples(j)) {
      incidentOf.count(ends[static_cast<size_t>(j)].first);
      incidentOf.count(ends[static_cast<size_t>(j)].second);
    }
  }
  incidentOf.allocate();
  for (int j = 0; j < numJoints; ++j) {
    if (couples(j)) {
      incidentOf.add(ends[static_cast<size_t>(j)].first, j);
      incidentOf.add(ends[static_cast<size_t>(j)].second, j);
    }
  }
}

/// The links in the order of a maximum cardinality search from the ground (computeSweepOrder).
std::vector<int> maximumCardinalitySweep(const Mechanism& mechanism, const SweepGraph& graph) {
  const int numLinks = graph.numLinks;
  // Maximum cardinality search from the ground: the next link is the one with the most links already swept
  // among its neighbours (ties: the one touched first, so the sweep advances like a front). A link reached
  // this way closes every loop it can right away, which keeps the front narrow and, with the attachment rule
  // below, puts each loop's closing connection where no later loop passes.
  std::vector<int> discovered(numLinks, -1), sweptNeighbours(numLinks, 0), touched(numLinks, -1), sweep;
  sweep.reserve(numLinks);
  using Candidate = std::tuple<int, int, int>;  // (swept neighbours, -touch time, link)
  std::priority_queue<Candidate> candidates;
  int touchClock = 0;
  auto sweepLink = [&](int link) {
    discovered[link] = static_cast<int>(sweep.size());
    sweep.push_back(link);
    for (int j : graph.incident(link)) {
      const int other = graph.otherEnd(j, link);
      if (discovered[other] >= 0)
        continue;
      if (touched[other] < 0)
        touched[other] = touchClock++;
      candidates.emplace(++sweptNeighbours[other], -touched[other], other);
    }
  };
  std::vector<int> starts = {mechanism.rootLink};
  for (int l = 0; l < numLinks; ++l)
    starts.push_back(l);
  for (int start : starts) {
    if (discovered[start] >= 0)
      continue;
    sweepLink(start);
    while (!candidates.empty()) {
      const auto [count, touch, link] = candidates.top();
      candidates.pop();
      if (discovered[link] >= 0 || count != sweptNeighbours[link])
        continue;  // stale entry
      sweepLink(link);
    }
  }
  return sweep;
}

/// The links in SuiteSparse AMD's approximate minimum degree order of the graph whose edges are the
/// connections with equations (computeMinimumDegreeOrder); in index order should AMD refuse the graph.
std::vector<int> minimumDegreeLinks(const SweepGraph& graph) {
  const int numLinks = graph.numLinks;
  // AMD reads the graph as a symmetric pattern in compressed columns: each link's neighbours, each once.
  std::vector<int> columnStart(static_cast<size_t>(numLinks) + 1, 0), neighbours;
  for (int l = 0; l < numLinks; ++l) {
    const size_t first = neighbours.size();
    for (int j : graph.incident(l))
      neighbours.push_back(graph.otherEnd(j, l));
    std::sort(neighbours.begin() + static_cast<std::ptrdiff_t>(first), neighbours.end());
    neighbours.erase(std::unique(neighbours.begin() + static_cast<std::ptrdiff_t>(first), neighbours.end()),
                     neighbours.end());
    columnStart[static_cast<size_t>(l) + 1] = static_cast<int>(neighbours.size());
  }
  std::vector<int> order(static_cast<size_t>(numLinks));
  double control[AMD_CONTROL], info[AMD_INFO];
  amd_defaults(control);
  if (amd_order(numLinks, columnStart.data(), neighbours.data(), order.data(), control, info) < AMD_OK)
    std::iota(order.begin(), order.end(), 0);
  return order;
}

/// The rows and column priorities of a sweep over the links in the order @p sweep (computeSweepOrder).
EliminationOrder orderFromSweep(const CoordinateModel& model, const SweepGraph& graph,
                                const std::vector<int>& sweep) {
  std::vector<int> discovered(static_cast<size_t>(graph.numLinks), -1);
  for (size_t i = 0; i < sweep.size(); ++i)
    discovered[sweep[i]] = static_cast<int>(i);
  const std::vector<char>& expressed = graph.expressed;
  auto otherEnd = [&](int joint, int link) { return graph.otherEnd(joint, link); };
  // Each link attaches to the most recently discovered of its earlier neighbours, and its other connections
  // to earlier links close loops. Why the most recent: the redundant equations an elimination reveals are
  // those of the connection that closes a loop, and its self-stress is the unique one over that connection
  // and independent equations before it. When each closing connection closes a short loop of the attaching
  // ones (a ladder's rungs and one rail attach, the other rail closes squares; breadth-first parents alone
  // would run both rails down to the ground), no closing connection lies in another's loop and every stress
  // stays as local as the mechanism's own loops.
  EliminationOrder order;
  order.rows.reserve(model.numConstraints());
  order.columnPriority.assign(model.numCoordinates(), 0);
  order.closing.assign(model.numConstraints(), 0);
  int nextColumn = 0;
  std::vector<int> closing;
  // Within a link, the elements its rigid-link equations express (p = p0 + a d1 + b d2 + c d1 x d2) come
  // before its basis: each such equation then pivots on its own element, and the link's other equations and
  // its joints reduce onto the basis alone. With the basis first, the equations would pivot on it one after
  // the other and couple every element of the link (quadratic for a door on many hinges or a bar through many
  // pins).
  // (expressed: marked when SweepGraph read the equations.)
  for (int link : sweep) {
    for (const char wanted : {1, 0}) {
      for (int e : model.bodyElements[link]) {
        if (expressed[e] != wanted)
          continue;
        for (int i = 0; i < model.dim; ++i)
          order.columnPriority[model.elements[e].offset + i] = nextColumn++;
      }
    }
    order.rows.insert(order.rows.end(), graph.linkRows(link).begin(), graph.linkRows(link).end());
    order.rows.insert(order.rows.end(), graph.boundaryRows(link).begin(), graph.boundaryRows(link).end());
    closing.clear();
    int attaching = -1;
    for (int j : graph.incident(link)) {
      const int other = otherEnd(j, link);
      if (discovered[other] >= discovered[link])
        continue;
      closing.push_back(j);
      if (attaching < 0 || discovered[other] > discovered[otherEnd(attaching, link)])
        attaching = j;
    }
    auto before = [&](int a, int b) {
      if ((a == attaching) != (b == attaching))
        return a == attaching;
      return discovered[otherEnd(a, link)] > discovered[otherEnd(b, link)];
    };
    // Stable either way: a link has mostly a few connections, and std::stable_sort allocates a buffer per
    // call (10^5 links), so few are sorted by insertion.
    if (closing.size() > kInsertionSortMax)
      std::stable_sort(closing.begin(), closing.end(), before);
    for (size_t i = 1; i < closing.size() && closing.size() <= kInsertionSortMax; ++i) {
      const int j = closing[i];
      size_t k = i;
      for (; k > 0 && before(j, closing[k - 1]); --k)
        closing[k] = closing[k - 1];
      closing[k] = j;
    }
    for (int j : closing) {
      order.rows.insert(order.rows.end(), graph.jointRows(j).begin(), graph.jointRows(j).end());
      if (j != attaching) {
        for (int r : graph.jointRows(j))
          order.closing[r] = 1;
      }
    }
  }
  return order;
}

}  // namespace

EliminationOrder computeSweepOrder(const Mechanism& mechanism, const CoordinateModel& model) {
  const SweepGraph graph(mechanism, model);
  return orderFromSweep(model, graph, maximumCardinalitySweep(mechanism, graph));
}

EliminationOrder computeMinimumDegreeOrder(const Mechanism& mechanism, const CoordinateModel& model) {
  const SweepGraph graph(mechanism, model);
  return orderFromSweep(model, graph, minimumDegreeLinks(graph));
}

EliminationOrder computeOrderOfLinks(const Mechanism& mechanism, const CoordinateModel& model,
                                     const std::vector<int>& links) {
  return orderFromSweep(model, SweepGraph(mechanism, model), links);
}

}  // namespace mobility_analysis
