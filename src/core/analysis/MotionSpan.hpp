#pragma once

// Private to src/core: the span of the idle motions kept so far (analysis/PassiveFreedoms.cpp), so that
// passive_dof is the dimension of the span of all idle motions, as PassiveFreedoms documents.

#include <cstddef>
#include <utility>
#include <vector>

namespace mobility_analysis {
namespace core_detail {

/// A motion as (coordinate, value) pairs over the coordinates it moves.
using SparseMotion = std::vector<std::pair<int, double>>;

/**
 * @brief The span of sparse vectors added one by one, in block echelon form over ordered positions; tells
 *        whether a new vector adds a dimension.
 *
 * Every coordinate has a position (an idle group's links lie at consecutive positions along their chain:
 * chainPositions in PassiveFreedoms.cpp). A kept row leads at the first position where it is not zero; the rows
 * leading at one position have orthonormal parts there (Gram–Schmidt, taken twice), so a new vector is reduced
 * position after position by orthogonal projections whose coefficients never exceed the norm of its part
 * there. It is in the span
 * exactly when every position's remainder vanishes: a remainder of norm above @p tolerance (the vector scaled
 * to unit norm) at some position makes it a new row leading there.
 *
 * Why not compare a new motion with the kept motions that share one of its links only (as before): a
 * dependency may run through motions that share no link with it. On a straight rope of ball-jointed rods,
 * rod b's spin is the turn of the pair a–b less rod a's spin; the pair shares a link with b, rod a does not,
 * and the turns of pairs and triples were counted beside the rods' spins (10 for 6 rods, 495 for 200,
 * instead of n − 1).
 *
 * Cost: a vector reduced at positions [s, e] meets only rows leading there, and those rows end by e when the
 * vectors arrive in the order of their last position (a sub-chain before the chains that contain it):
 * nothing spreads beyond the vector's own chain, so a chain of n links costs O(n).
 */
class MotionSpan {
 public:
  /// @param positionOf each coordinate's position (-1: never moved).
  /// @param tolerance a remainder (the vector at unit norm) at most this is zero.
  MotionSpan(std::vector<int> positionOf, double tolerance);

  /// Reduces @p motion against the rows kept; @return whether it is independent of them. Its reduced form is
  /// held until keep() adds it or the next call drops it.
  bool isIndependent(const SparseMotion& motion);
  /// Adds the motion the last isIndependent found independent.
  void keep();

  int dimension() const { return static_cast<int>(rowStart_.size()) - 1; }

 private:
  /// Subtracts from the work vector its projection on the rows leading at @p position (their parts there).
  void project(int position);
  void touch(int coordinate);
  double normAt(int position) const;
  void keepRow(int position);
  void clearWork();

  std::vector<int> positionOf_;
  double tolerance_;
  // Kept rows, compressed: row k is entries_[rowStart_[k], rowStart_[k + 1]); leadingAt_ per position.
  std::vector<std::pair<int, double>> entries_;
  std::vector<size_t> rowStart_{0};
  std::vector<std::vector<int>> leadingAt_;
  // The vector being reduced: dense values over every coordinate, the coordinates it touches, and the
  // positions still to reduce (a heap, each position once).
  std::vector<double> work_;
  std::vector<char> touched_;
  std::vector<int> support_;
  std::vector<int> pending_;
  std::vector<char> queued_;  // per position, whether it is in pending_
  int current_ = -1;          // the position being reduced
  int heldPosition_ = -1;     // where the held independent motion leads (-1: none held)
};

}  // namespace core_detail
}  // namespace mobility_analysis
