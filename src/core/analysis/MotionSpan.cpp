#include "MotionSpan.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

namespace mobility_analysis {
namespace core_detail {

MotionSpan::MotionSpan(std::vector<int> positionOf, double tolerance)
    : positionOf_(std::move(positionOf)),
      tolerance_(tolerance),
      work_(positionOf_.size(), 0.0),
      touched_(positionOf_.size(), 0) {
  int last = -1;
  for (const int p : positionOf_)
    last = std::max(last, p);
  // A coordinate without a position (none is ever moved) is reduced last, at a position of its own.
  for (int& p : positionOf_) {
    if (p < 0)
      p = last + 1;
  }
  leadingAt_.resize(static_cast<size_t>(last) + 2);
  queued_.assign(leadingAt_.size(), 0);
}

bool MotionSpan::isIndependent(const SparseMotion& motion) {
  clearWork();  // a motion held and not kept
  double norm2 = 0.0;
  for (const auto& entry : motion)
    norm2 += entry.second * entry.second;
  if (!(norm2 > 0.0) || !std::isfinite(norm2))
    return false;  // no motion adds no dimension
  const double scale = 1.0 / std::sqrt(norm2);
  for (const auto& [coordinate, value] : motion) {
    touch(coordinate);
    work_[static_cast<size_t>(coordinate)] += scale * value;
  }
  while (!pending_.empty()) {
    std::pop_heap(pending_.begin(), pending_.end(), std::greater<int>());
    const int position = pending_.back();
    pending_.pop_back();
    current_ = position;  // a projection here touches coordinates here and after only: none is queued again
    // Twice: the second projection removes what rounding left of the first (Giraud et al. 2005, "twice is
    // enough"), so that the rows leading here stay orthonormal to working precision.
    project(position);
    project(position);
    const double remainder = normAt(position);
    if (remainder > tolerance_) {
      heldPosition_ = position;
      return true;
    }
    for (int c : support_) {  // within the tolerance: zero here, and on to the next position
      if (positionOf_[static_cast<size_t>(c)] == position)
        work_[static_cast<size_t>(c)] = 0.0;
    }
  }
  clearWork();
  return false;
}

void MotionSpan::project(int position) {
  for (int k : leadingAt_[static_cast<size_t>(position)]) {
    const size_t begin = rowStart_[static_cast<size_t>(k)], end = rowStart_[static_cast<size_t>(k) + 1];
    double coefficient = 0.0;
    for (size_t i = begin; i < end && positionOf_[static_cast<size_t>(entries_[i].first)] == position; ++i)
      coefficient += work_[static_cast<size_t>(entries_[i].first)] * entries_[i].second;
    if (coefficient == 0.0)
      continue;
    for (size_t i = begin; i < end; ++i) {
      touch(entries_[i].first);
      work_[static_cast<size_t>(entries_[i].first)] -= coefficient * entries_[i].second;
    }
  }
}

void MotionSpan::touch(int coordinate) {
  const size_t c = static_cast<size_t>(coordinate);
  if (touched_[c])
    return;
  touched_[c] = 1;
  support_.push_back(coordinate);
  const int position = positionOf_[c];
  if (position <= current_ || queued_[static_cast<size_t>(position)])
    return;
  queued_[static_cast<size_t>(position)] = 1;
  pending_.push_back(position);
  std::push_heap(pending_.begin(), pending_.end(), std::greater<int>());
}

double MotionSpan::normAt(int position) const {
  double norm2 = 0.0;
  for (int c : support_) {
    if (positionOf_[static_cast<size_t>(c)] == position)
      norm2 += work_[static_cast<size_t>(c)] * work_[static_cast<size_t>(c)];
  }
  return std::sqrt(norm2);
}

/// The work vector (zero before @p position) as a row leading at @p position, scaled to a unit part there;
/// its entries by position, so that a projection reads the leading part first.
void MotionSpan::keepRow(int position) {
  const double scale = 1.0 / normAt(position);
  std::sort(support_.begin(), support_.end(), [this](int a, int b) {
    const int pa = positionOf_[static_cast<size_t>(a)], pb = positionOf_[static_cast<size_t>(b)];
    return pa != pb ? pa < pb : a < b;
  });
  for (int c : support_) {
    const double value = work_[static_cast<size_t>(c)];
    if (value != 0.0 && positionOf_[static_cast<size_t>(c)] >= position)
      entries_.emplace_back(c, scale * value);
  }
  leadingAt_[static_cast<size_t>(position)].push_back(dimension());
  rowStart_.push_back(entries_.size());
}

void MotionSpan::keep() {
  if (heldPosition_ < 0)
    return;
  keepRow(heldPosition_);
  clearWork();
}

void MotionSpan::clearWork() {
  heldPosition_ = -1;
  current_ = -1;
  for (int c : support_) {
    queued_[static_cast<size_t>(positionOf_[static_cast<size_t>(c)])] = 0;
    work_[static_cast<size_t>(c)] = 0.0;
    touched_[static_cast<size_t>(c)] = 0;
  }
  support_.clear();
  pending_.clear();
}

}  // namespace core_detail
}  // namespace mobility_analysis
