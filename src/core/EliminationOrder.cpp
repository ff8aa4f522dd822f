#include "mobility_analysis/EliminationOrder.hpp"

#include <algorithm>
#include <queue>
#include <tuple>

namespace mobility_analysis {

namespace {

/// Equations grouped by what releases them, and the connections that couple links.
struct ConnectionGraph {
  std::vector<std::vector<int>> linkRows, boundaryRows, jointRows;
  std::vector<std::vector<int>> incident;  ///< Per link, its connections with equations to another link.
};

ConnectionGraph connectionGraphOf(const Mechanism& mechanism, const CoordinateModel& model) {
  const int numLinks = static_cast<int>(mechanism.links.size());
  const int numJoints = static_cast<int>(mechanism.joints.size());
  ConnectionGraph graph;
  graph.linkRows.resize(numLinks);
  graph.boundaryRows.resize(numLinks);
  graph.jointRows.resize(numJoints);
  graph.incident.resize(numLinks);

  // Rigid-link and boundary rows by their link, joint rows by their joint.
  for (int r = 0; r < model.numConstraints(); ++r) {
    const ConstraintEquation& eq = model.equations[r];
    switch (eq.source) {
      case EquationSource::Link:
        graph.linkRows[eq.element].push_back(r);
        break;
      case EquationSource::Boundary:
        graph.boundaryRows[eq.element].push_back(r);
        break;
      case EquationSource::Joint:
        graph.jointRows[eq.element].push_back(r);
        break;
    }
  }
  // Only connections with equations couple their links: a floating joint (a link held by loop joints alone)
  // or a slack cable would let the sweep jump from the ground straight into the middle of the mechanism.
  for (int j = 0; j < numJoints; ++j) {
    const Joint& joint = mechanism.joints[j];
    if (graph.jointRows[j].empty() || joint.link1 == joint.link2)
      continue;
    graph.incident[joint.link1].push_back(j);
    graph.incident[joint.link2].push_back(j);
  }
  return graph;
}

int otherEnd(const Mechanism& mechanism, int joint, int link) {
  return mechanism.joints[joint].link1 == link ? mechanism.joints[joint].link2
                                               : mechanism.joints[joint].link1;
}

/// The links in the order of a maximum cardinality search from the ground (computeSweepOrder).
std::vector<int> maximumCardinalitySweep(const Mechanism& mechanism, const ConnectionGraph& graph) {
  const int numLinks = static_cast<int>(mechanism.links.size());
  const std::vector<std::vector<int>>& incident = graph.incident;
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
    for (int j : incident[link]) {
      const int other = otherEnd(mechanism, j, link);
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

/// The rows and column priorities of a sweep over the links in @p sweep (computeSweepOrder).
EliminationOrder orderFromSweep(const Mechanism& mechanism, const CoordinateModel& model,
                                const ConnectionGraph& graph, const std::vector<int>& sweep) {
  const std::vector<std::vector<int>>& incident = graph.incident;
  const std::vector<std::vector<int>>& jointRows = graph.jointRows;
  std::vector<int> discovered(mechanism.links.size(), -1);
  for (size_t i = 0; i < sweep.size(); ++i)
    discovered[sweep[i]] = static_cast<int>(i);

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
  std::vector<char> expressed(model.elements.size(), 0);
  for (const ConstraintEquation& eq : model.equations) {
    if (eq.form == EquationForm::Combination)
      expressed[eq.target] = 1;
  }
  for (int link : sweep) {
    for (const char wanted : {1, 0}) {
      for (int e : model.bodyElements[link]) {
        if (expressed[e] != wanted)
          continue;
        for (int i = 0; i < model.dim; ++i)
          order.columnPriority[model.elements[e].offset + i] = nextColumn++;
      }
    }
    order.rows.insert(order.rows.end(), graph.linkRows[link].begin(), graph.linkRows[link].end());
    order.rows.insert(order.rows.end(), graph.boundaryRows[link].begin(), graph.boundaryRows[link].end());
    closing.clear();
    int attaching = -1;
    for (int j : incident[link]) {
      const int other = otherEnd(mechanism, j, link);
      if (discovered[other] >= discovered[link])
        continue;
      closing.push_back(j);
      if (attaching < 0 || discovered[other] > discovered[otherEnd(mechanism, attaching, link)])
        attaching = j;
    }
    std::stable_sort(closing.begin(), closing.end(), [&](int a, int b) {
      if ((a == attaching) != (b == attaching))
        return a == attaching;
      return discovered[otherEnd(mechanism, a, link)] > discovered[otherEnd(mechanism, b, link)];
    });
    for (int j : closing) {
      order.rows.insert(order.rows.end(), jointRows[j].begin(), jointRows[j].end());
      if (j != attaching) {
        for (int r : jointRows[j])
          order.closing[r] = 1;
      }
    }
  }
  return order;
}

}  // namespace

EliminationOrder computeSweepOrder(const Mechanism& mechanism, const CoordinateModel& model) {
  const ConnectionGraph graph = connectionGraphOf(mechanism, model);
  return orderFromSweep(mechanism, model, graph, maximumCardinalitySweep(mechanism, graph));
}

EliminationOrder computeOrderOfLinks(const Mechanism& mechanism, const CoordinateModel& model,
                                     const std::vector<int>& links) {
  return orderFromSweep(mechanism, model, connectionGraphOf(mechanism, model), links);
}

}  // namespace mobility_analysis
