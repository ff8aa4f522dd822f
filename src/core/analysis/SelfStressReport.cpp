#include "mobility_analysis/analysis/SelfStressReport.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>

#include "../SignificantBits.hpp"
#include "mobility_analysis/analysis/Prestress.hpp"

namespace mobility_analysis {

namespace {

/// An element's share below this fraction of the state's largest is rounding, not support.
constexpr double kSupportFloor = 1e-9;
/// An eigenvalue of N^T Omega N above this fraction of |Omega| counts as positive.
constexpr double kStiffnessFloor = 1e-9;

bool isDistanceLike(const Joint& joint) {
  return joint.kind == ConnectionKind::Cable || joint.kind == ConnectionKind::DistanceConstraint;
}

/// One equation's share of an element's force: key (source, element), and its contribution.
struct Share {
  std::pair<int, int> key;
  double value;
};

/// Sums the shares of each key, in key order; shares of one key are added in the order given (a stable sort),
/// so the sums are the same to the last bit whatever the container.
std::vector<Share> sumByKey(std::vector<Share>& shares) {
  auto byKey = [](const Share& a, const Share& b) { return a.key < b.key; };
  // Shares come in equation order, in which an element's equations are mostly together and the elements in
  // order (a braced lattice's prestress: 0.63 10^6 shares of 200 x 200 cells, already sorted, 0.02 s of
  // stable sort): then the sort would keep them.
  if (!std::is_sorted(shares.begin(), shares.end(), byKey))
    std::stable_sort(shares.begin(), shares.end(), byKey);
  std::vector<Share> sums;
  for (const Share& share : shares) {
    if (sums.empty() || sums.back().key != share.key)
      sums.push_back(Share{share.key, 0.0});
    sums.back().value += share.value;
  }
  return sums;
}

/// Low bits of a force's magnitude dropped when forces are ordered or compared: 29 of its 52 mantissa bits
/// stay, about the nine decimal digits the JSON prints.
constexpr int kDroppedBits = 23;

/// |@p value| to the bits that order forces, as an integer that orders as the magnitude
/// (SignificantBits.hpp).
uint64_t quantisedMagnitude(double value) {
  return core_detail::roundedMagnitudeBits(value, kDroppedBits);
}

/// The elements carrying a multiplier vector given as (row, value) pairs, forces relative to the largest.
/// (Sorted vectors, not maps: a large grid's report asks this of tens of thousands of states.)
template <class Entries>
std::vector<ElementForce> elementForces(const Mechanism& mechanism, const CoordinateModel& model,
                                        const Entries& entries) {
  // (source, element) -> signed force (distance-like) or sum of squares.
  std::vector<Share> signedShares, squareShares;
  for (const auto& [row, value] : entries) {
    const ConstraintEquation& eq = model.equations[row];
    const std::pair<int, int> key{static_cast<int>(eq.source), eq.element};
    if (eq.source == EquationSource::Joint && isDistanceLike(mechanism.joints[eq.element]) &&
        eq.kind == EquationKind::Distance) {
      // |p2 - p1|^2 = L^2 with multiplier y: axial force 2 y L, tension positive.
      signedShares.push_back(Share{key, 2.0 * value * std::sqrt(std::max(eq.value, 0.0))});
    } else {
      squareShares.push_back(Share{key, value * value});
    }
  }
  const std::vector<Share> signedForce = sumByKey(signedShares);
  const std::vector<Share> squares = sumByKey(squareShares);
  // Forces as (key, signed?, value), signed first, then the magnitudes; named only once kept and sorted, so
  // the sort moves no strings (a large grid's report asks this of tens of thousands of states).
  struct Force {
    std::pair<int, int> key;
    bool isSigned;  // a cable's or distance constraint's, whichever its equation
    double value;
  };
  auto distanceLike = [&](const std::pair<int, int>& key) {
    return static_cast<EquationSource>(key.first) == EquationSource::Joint &&
           isDistanceLike(mechanism.joints[key.second]);
  };
  std::vector<Force> forces;
  forces.reserve(signedForce.size() + squares.size());
  for (const Share& share : signedForce)
    forces.push_back(Force{share.key, distanceLike(share.key), share.value});
  for (const Share& share : squares)
    forces.push_back(Force{share.key, distanceLike(share.key), std::sqrt(share.value)});
  double largest = 0.0;
  for (const Force& f : forces)
    largest = std::max(largest, std::abs(f.value));
  // Sign of a state is free: make its largest signed (cable / distance) force a tension. Of forces that tie
  // to the digits printed (two cables pulling against each other), the first element's: by the last bits the
  // sign of the whole state came out differently in millimetres and in metres.
  double largestSigned = 0.0;
  uint64_t largestQuantised = 0;
  for (const Share& share : signedForce) {
    const uint64_t quantised = quantisedMagnitude(share.value);
    if (share.value != 0.0 && quantised > largestQuantised) {
      largestQuantised = quantised;
      largestSigned = share.value;
    }
  }
  const double sign = largestSigned < 0.0 ? -1.0 : 1.0;
  std::vector<ElementForce> kept;
  if (largest <= 0.0)
    return kept;
  // Largest first. Forces that agree to about nine digits (as the JSON prints them) tie and keep the order of
  // their elements, which the rounding of a pose cannot change: ordered by their last bits, the same
  // parallelogram grid written in millimetres listed its states' elements in another order than in metres.
  std::vector<std::pair<uint64_t, int>> order;  // (magnitude quantised, force), then sorted
  order.reserve(forces.size());
  for (size_t i = 0; i < forces.size(); ++i) {
    Force& f = forces[i];
    f.value = (f.isSigned ? sign : 1.0) * f.value / largest;
    if (std::abs(f.value) > kSupportFloor)
      order.emplace_back(quantisedMagnitude(f.value), static_cast<int>(i));
  }
  std::stable_sort(order.begin(), order.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  kept.reserve(order.size());
  for (const auto& [magnitude, i] : order) {
    const Force& f = forces[static_cast<size_t>(i)];
    ElementForce force;
    const auto source = static_cast<EquationSource>(f.key.first);
    if (source == EquationSource::Joint) {
      force.kind = toString(mechanism.joints[f.key.second].kind);
      force.name = mechanism.joints[f.key.second].name;
    } else {
      force.kind = source == EquationSource::Link ? "link" : "boundary";
      force.name = mechanism.links[f.key.second].name;
    }
    force.force = f.value;
    kept.push_back(std::move(force));
  }
  return kept;
}

}  // namespace

std::vector<int> findTautCableRows(const Mechanism& mechanism, const CoordinateModel& model) {
  std::vector<int> rows;
  // Most mechanisms have no cable: then the equations, five or more per joint and each with a look at its
  // joint, are not read at all (a 200 x 200 bar lattice: 8 ms).
  if (std::none_of(mechanism.joints.begin(), mechanism.joints.end(),
                   [](const Joint& joint) { return joint.kind == ConnectionKind::Cable; }))
    return rows;
  for (int r = 0; r < model.numConstraints(); ++r) {
    const ConstraintEquation& eq = model.equations[r];
    if (eq.source == EquationSource::Joint && mechanism.joints[eq.element].kind == ConnectionKind::Cable &&
        eq.kind == EquationKind::Distance)
      rows.push_back(r);
  }
  return rows;
}

Mechanism lockActiveCables(const Mechanism& mechanism, const LinkPoses& poses, std::vector<bool>& locked) {
  Mechanism copy = mechanism;
  locked.assign(mechanism.joints.size(), false);
  for (size_t j = 0; j < copy.joints.size(); ++j) {
    Joint& joint = copy.joints[j];
    if (joint.kind != ConnectionKind::Cable || joint.cableType != CableType::Active)
      continue;
    joint.cableType = CableType::Passive;
    joint.length = ((poses[joint.link1] * joint.frame1.translation()) -
                    (poses[joint.link2] * joint.frame2.translation()))
                       .norm();
    locked[j] = true;
  }
  return copy;
}

std::vector<SelfStress> toEquilibriumStresses(const std::vector<SelfStress>& stresses,
                                              const SparseJacobian& J) {
  std::vector<SelfStress> result;
  result.reserve(stresses.size());
  for (const SelfStress& stress : stresses) {
    SelfStress scaled;
    scaled.reserve(stress.size());
    double largest = 0.0;
    for (const auto& [row, value] : stress) {
      const double norm = J.row(row).norm();
      if (norm <= 0.0)
        continue;
      scaled.emplace_back(row, value / norm);
      largest = std::max(largest, std::abs(value / norm));
    }
    for (auto& entry : scaled)
      entry.second /= largest > 0.0 ? largest : 1.0;
    result.push_back(std::move(scaled));
  }
  return result;
}

Eigen::VectorXd toMultipliers(const SelfStress& stress, int numConstraints) {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(numConstraints);
  for (const auto& [row, value] : stress)
    y(row) += value;
  return y;
}

SelfStressInfo computeSelfStressInfo(const Mechanism& mechanism, const CoordinateModel& model,
                                     const Eigen::Ref<const Eigen::VectorXd>& q, const SparseJacobian& J,
                                     const SelfStressBasis& basis) {
  SelfStressInfo info;
  info.count = basis.numConstraints - basis.rank;
  info.mechanismModes = basis.numCoordinates - basis.rank;
  const std::vector<SelfStress> stresses = toEquilibriumStresses(basis.stresses, J);
  info.statesListed = stresses.size() <= kMaxListedStates;
  if (info.statesListed) {
    info.states.reserve(stresses.size());
    for (const SelfStress& stress : stresses)
      info.states.push_back(SelfStressState{elementForces(mechanism, model, stress)});
  }

  const std::vector<int> cableRows = findTautCableRows(mechanism, model);
  info.tautCables = static_cast<int>(cableRows.size());
  if (cableRows.empty()) {
    info.stability = "no taut cables to prestress";
    return info;
  }
  const CablePrestress prestress = findCablePrestress(stresses, model.numConstraints(), cableRows, &J);
  info.prestressable = prestress.feasible;
  if (!prestress.feasible) {
    info.stability = stresses.empty() ? "no state of self-stress: the taut cables cannot be pretensioned"
                                      : "no combination of the states tensions every taut cable";
    return info;
  }
  std::vector<std::pair<int, double>> entries;
  for (int r = 0; r < prestress.multipliers.size(); ++r) {
    if (prestress.multipliers(r) != 0.0)
      entries.emplace_back(r, prestress.multipliers(r));
  }
  info.prestress = elementForces(mechanism, model, entries);

  // Second-order test on the first-order motions.
  const int m = info.mechanismModes;
  if (m == 0) {
    info.prestressStable = true;
    info.stability = "first-order rigid (m = 0): the prestress has no mechanism mode to stiffen";
    return info;
  }
  if (model.numCoordinates() > kMaxStabilityCoordinates) {
    char what[160];
    std::snprintf(what, sizeof(what), "not decided: %d mechanism modes over %d coordinates (limit %d)", m,
                  model.numCoordinates(), kMaxStabilityCoordinates);
    info.stability = what;
    return info;
  }
  const Eigen::MatrixXd dense = Eigen::MatrixXd(J);
  Eigen::FullPivLU<Eigen::MatrixXd> lu(dense);
  lu.setThreshold(basis.smallestKeptPivot > 0.0 ? std::min(1e-8, 0.1 * basis.smallestKeptPivot) : 1e-8);
  const Eigen::MatrixXd kernel = lu.kernel();
  const Eigen::MatrixXd N = Eigen::HouseholderQR<Eigen::MatrixXd>(kernel).householderQ() *
                            Eigen::MatrixXd::Identity(kernel.rows(), kernel.cols());
  const Eigen::MatrixXd omega = Eigen::MatrixXd(computeStressedHessian(model, q, prestress.multipliers));
  const Eigen::MatrixXd reduced = N.transpose() * omega * N;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(0.5 * (reduced + reduced.transpose()));
  const double scale = std::max(1.0, omega.cwiseAbs().maxCoeff());
  const double smallest = eigen.eigenvalues().size() ? eigen.eigenvalues().minCoeff() : 0.0;
  info.prestressStable = kernel.cols() == m && smallest > kStiffnessFloor * scale;
  char what[200];
  std::snprintf(what, sizeof(what), "stress matrix on the %d mechanism modes: smallest eigenvalue %.3g (%s)",
                m, smallest, info.prestressStable ? "positive definite" : "not positive definite");
  info.stability = what;
  return info;
}

}  // namespace mobility_analysis
