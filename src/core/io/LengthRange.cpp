#include "mobility_analysis/io/LengthRange.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

/**
 * @brief Calls @p visit(value, joint, what) for each length of @p mechanism in the order of its connections
 *        (value >= 0 [m], joint: the connection it belongs to, what: which of its lengths), until @p visit
 *        returns true.
 *
 * Walked where it is needed instead of gathered into a list of lengths first: the list was 24 bytes a length
 * (4.8 MB of fresh pages on a 10^5-joint chain) for the median and the check to read once each.
 */
template <class Visit>
void forEachLength(const Mechanism& mechanism, const Visit& visit) {
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const Joint& joint = mechanism.joints[j];
    const int index = static_cast<int>(j);
    if (joint.kind == ConnectionKind::Coupling) {
      const bool slides = joint.follower >= 0 && joint.follower < static_cast<int>(mechanism.joints.size()) &&
                          mechanism.joints[joint.follower].type == JointType::Prismatic;
      if (slides && visit(std::abs(joint.offset), index, "offset"))
        return;
      continue;
    }
    const bool tree = joint.kind == ConnectionKind::TreeJoint;
    if (visit(joint.frame1.translation().norm(), index, tree ? "origin" : "anchor on link1"))
      return;
    if (visit(joint.frame2.translation().norm(), index, "anchor on link2"))
      return;
    if (joint.kind == ConnectionKind::Cable && visit(std::abs(joint.length), index, "length"))
      return;
  }
}

/// The lower median of the nonzero lengths of @p mechanism (0 when there is none); @p longest (if given): the
/// longest of all its lengths (0 when there is none).
double medianOfNonzero(const Mechanism& mechanism, double* longest = nullptr) {
  std::vector<double> values;
  values.reserve(3 * mechanism.joints.size());  // at most three lengths a connection (a cable)
  double maximum = 0.0;
  forEachLength(mechanism, [&](double value, int, const char*) {
    if (value > tolerances::kZeroVector && std::isfinite(value))  // CAD round-off (1e-17) is zero
      values.push_back(value);
    maximum = std::max(maximum, value);
    return false;
  });
  if (longest != nullptr)
    *longest = maximum;
  if (values.empty())
    return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>((values.size() - 1) / 2);  // lower median
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

double typicalLength(const Mechanism& mechanism) {
  return medianOfNonzero(mechanism);
}

std::optional<Diagnostic> checkLengthRange(const Mechanism& mechanism) {
  // The median of the nonzero lengths is one of them, so at least the shortest: a model whose longest length
  // is within range of its shortest is within range of its median, found without the list of lengths and
  // its selection (on a 10^5-joint chain 2.4 MB of fresh pages and a partial sort of 2 10^5 values).
  double shortest = std::numeric_limits<double>::infinity(), longestOfAll = 0.0;
  forEachLength(mechanism, [&](double value, int, const char*) {
    if (value > tolerances::kZeroVector && std::isfinite(value))  // the median's lengths (medianOfNonzero)
      shortest = std::min(shortest, value);
    longestOfAll = std::max(longestOfAll, value);
    return false;
  });
  if (shortest == std::numeric_limits<double>::infinity() ||
      longestOfAll <= tolerances::kMaxRelativeLength * shortest)
    return std::nullopt;  // no nonzero length (no typical length), or all within range of the shortest
  double longest = 0.0;
  const double typical = medianOfNonzero(mechanism, &longest);
  if (typical <= 0.0)
    return std::nullopt;
  const double limit = tolerances::kMaxRelativeLength * typical;
  if (longest <= limit)
    return std::nullopt;  // every length within range: no second walk to find the first that is not
  std::optional<Diagnostic> outOfRange;
  forEachLength(mechanism, [&](double value, int index, const char* what) {
    if (value <= limit)
      return false;
    const Joint& joint = mechanism.joints[index];
    char text[320];
    std::snprintf(text, sizeof(text),
                  "%s of %.6g m is %.3g times the model's typical length %.6g m (the median of its offsets); "
                  "accepted up to %.0g times: the rest of the model would be lost in rounding",
                  what, value, value / typical, typical, tolerances::kMaxRelativeLength);
    outOfRange = makeDiagnostic(mechanism.file, toString(joint.kind), joint.name, text);
    return true;
  });
  return outOfRange;
}

}  // namespace mobility_analysis
