#pragma once

// Private to src/core: the local stress finder's balls in space (LocalStressFinder.hpp).

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"

namespace mobility_analysis {
namespace core_detail {

/**
 * Where each equation acts, at the pose the model was built at: a joint's equations at the points they
 * join, a point's rigid-link combination at the point. The rest of a link's equations (those between its
 * basis elements, its boundary) act on the link as a whole and are attached to it.
 *
 * Why in space: on a link through many joints (a continuous bar pinned at every crossing of a grid) every
 * joint's equations reach every other's through the link's basis, so a ball of links is the whole mechanism
 * after one step, while the self-stresses stay among a few neighbouring joints; their neighbourhood along the
 * link is only visible in where they are.
 */
class EquationPlaces {
 public:
  EquationPlaces(const Mechanism& mechanism, const CoordinateModel& model, const SparseJacobian& J)
      : place_(J.rows(), Eigen::Vector3d::Zero()), located_(J.rows(), 0), attached_(mechanism.links.size()) {
    std::vector<int> elementOf(J.cols(), -1);
    for (size_t e = 0; e < model.elements.size(); ++e) {
      for (int i = 0; i < model.dim; ++i)
        elementOf[model.elements[e].offset + i] = static_cast<int>(e);
    }
    auto position = [&](int e) {
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      x.head(model.dim) = model.q0.segment(model.elements[e].offset, model.dim);
      return x;
    };
    std::vector<int> seen;
    std::vector<int> placedRow(mechanism.joints.size(), -1);  // per joint, its first located row
    for (int r = 0; r < J.rows(); ++r) {
      const ConstraintEquation& eq = model.equations[r];
      if (eq.source == EquationSource::Joint) {
        // The mean of the points it touches (each point once).
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        int count = 0;
        seen.clear();
        for (SparseJacobian::InnerIterator it(J, r); it; ++it) {
          const int e = elementOf[it.col()];
          if (e < 0 || !model.elements[e].isPoint || std::find(seen.begin(), seen.end(), e) != seen.end())
            continue;
          seen.push_back(e);
          sum += position(e);
          ++count;
        }
        if (count > 0) {
          place_[r] = sum / count;
          located_[r] = 1;
          if (placedRow[eq.element] < 0)
            placedRow[eq.element] = r;
        }
      } else if (eq.source == EquationSource::Link && eq.form == EquationForm::Combination &&
                 model.elements[eq.target()].isPoint) {
        place_[r] = position(eq.target());
        located_[r] = 1;
      } else if (!atJointWithoutPoint(model, eq)) {
        attached_[eq.element].push_back(r);
      }
    }
    // The typical spacing: on each link with located equations, its extent over the places it has less one.
    std::vector<std::vector<int>> linkPlaces(mechanism.links.size());
    for (int r = 0; r < J.rows(); ++r) {
      if (located_[r] != 0 && model.equations[r].source == EquationSource::Link)
        linkPlaces[model.equations[r].element].push_back(r);
    }
    std::vector<double> spacings;
    for (const std::vector<int>& rows : linkPlaces) {
      if (rows.size() < 2)
        continue;
      Eigen::Vector3d low = place_[rows[0]], high = low;
      for (int r : rows) {
        low = low.cwiseMin(place_[r]);
        high = high.cwiseMax(place_[r]);
      }
      const double extent = (high - low).norm();
      if (extent > 0.0)
        spacings.push_back(extent / static_cast<double>(rows.size() - 1));
    }
    if (!spacings.empty()) {
      std::nth_element(spacings.begin(), spacings.begin() + spacings.size() / 2, spacings.end());
      spacing_ = spacings[spacings.size() / 2];
    } else {
      spacing_ = model.characteristicLength > 0.0 ? model.characteristicLength : 1.0;
    }
    locateAtJoints(model, placedRow);
    // Located rows bucketed in cubes of the spacing.
    for (int r = 0; r < J.rows(); ++r) {
      if (located_[r] == 0)
        continue;
      const Eigen::Vector3i cell = cellOf(place_[r]);
      lowest_ = numLocated_ == 0 ? cell : lowest_.cwiseMin(cell);
      highest_ = numLocated_ == 0 ? cell : highest_.cwiseMax(cell);
      cells_[key(cell)].push_back(r);
      ++numLocated_;
    }
  }

  bool located(int row) const { return located_[row] != 0; }
  size_t numLocated() const { return numLocated_; }
  const Eigen::Vector3d& place(int row) const { return place_[row]; }
  double spacing() const { return spacing_; }
  /// Rows without a place, acting on @p link as a whole.
  const std::vector<int>& attached(int link) const { return attached_[link]; }

  /// Calls @p visit for every located row within @p radius of @p center.
  template <class Visit>
  void forEachWithin(const Eigen::Vector3d& center, double radius, Visit&& visit) const {
    // Only the cells within the places' bounds (a planar model is one cell thick).
    const Eigen::Vector3i low = cellOf(center - Eigen::Vector3d::Constant(radius)).cwiseMax(lowest_);
    const Eigen::Vector3i high = cellOf(center + Eigen::Vector3d::Constant(radius)).cwiseMin(highest_);
    // A box with more cells than there are occupied ones (a wide ball over a ring, whose box is mostly empty:
    // (ring radius / spacing)^2 cells, quadratic in the ring's length) is read by its occupied cells instead.
    const Eigen::Vector3d extent = (high - low + Eigen::Vector3i::Ones()).cast<double>();
    if (extent.x() * extent.y() * extent.z() > static_cast<double>(cells_.size())) {
      for (const auto& cell : cells_) {
        for (int r : cell.second) {
          if ((place_[r] - center).squaredNorm() <= radius * radius)
            visit(r);
        }
      }
      return;
    }
    for (int x = low.x(); x <= high.x(); ++x) {
      for (int y = low.y(); y <= high.y(); ++y) {
        for (int z = low.z(); z <= high.z(); ++z) {
          const auto cell = cells_.find(key(Eigen::Vector3i(x, y, z)));
          if (cell == cells_.end())
            continue;
          for (int r : cell->second) {
            if ((place_[r] - center).squaredNorm() <= radius * radius)
              visit(r);
          }
        }
      }
    }
  }

 private:
  /// A row that touches no point but belongs to one joint: the joint's own rows between axes (a revolute's
  /// parallel-axis rows), and a link's combination for an axis that sits at a joint.
  static bool atJointWithoutPoint(const CoordinateModel& model, const ConstraintEquation& eq) {
    if (eq.source == EquationSource::Joint)
      return true;
    return eq.source == EquationSource::Link && eq.form == EquationForm::Combination &&
           model.elements[eq.target()].joint >= 0;
  }

  /**
   * Rows at a joint that touch no point act where the joint's point rows do. Unplaced, the joint's own were
   * in no ball in space and the links' axis combinations were attached to their links as a whole, so on a
   * grid of continuous bars pinned at every crossing, in spatial mode, a cell's stress between its four pins'
   * axes was traced along whole bars (a 50 x 50 grid: 12 387 of 12 400 stresses, up to 997 entries each)
   * or found in a ball holding every axis of its four bars (quadratic). Placed after the spacing is taken,
   * which reads the links' point combinations only. A joint without a located row (@p placedRow, per joint:
   * its first located row, else -1) leaves them as they were: its own unplaced, a link's attached to the
   * link.
   */
  void locateAtJoints(const CoordinateModel& model, const std::vector<int>& placedRow) {
    for (size_t r = 0; r < located_.size(); ++r) {
      const ConstraintEquation& eq = model.equations[r];
      if (located_[r] != 0 || !atJointWithoutPoint(model, eq))
        continue;
      const int joint = eq.source == EquationSource::Joint ? eq.element : model.elements[eq.target()].joint;
      const int placed = placedRow[static_cast<size_t>(joint)];
      if (placed >= 0) {
        place_[r] = place_[static_cast<size_t>(placed)];
        located_[r] = 1;
      } else if (eq.source == EquationSource::Link) {
        attached_[eq.element].push_back(static_cast<int>(r));
      }
    }
  }

  Eigen::Vector3i cellOf(const Eigen::Vector3d& x) const {
    return (x / spacing_).array().floor().cast<int>();
  }
  static uint64_t key(const Eigen::Vector3i& cell) {
    auto part = [](int v) { return static_cast<uint64_t>(static_cast<uint32_t>(v) & 0x1fffffu); };
    return part(cell.x()) | part(cell.y()) << 21 | part(cell.z()) << 42;
  }

  std::vector<Eigen::Vector3d> place_;
  std::vector<char> located_;
  std::vector<std::vector<int>> attached_;
  double spacing_ = 1.0;
  size_t numLocated_ = 0;
  Eigen::Vector3i lowest_ = Eigen::Vector3i::Zero(), highest_ = Eigen::Vector3i::Zero();
  std::unordered_map<uint64_t, std::vector<int>> cells_;
};

}  // namespace core_detail
}  // namespace mobility_analysis
