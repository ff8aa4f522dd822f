#include "mobility_analysis/io/LengthRange.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "mobility_analysis/Tolerances.hpp"

namespace mobility_analysis {

namespace {

/// One length of the model and where it comes from.
struct Length {
  double value = 0.0;  ///< [m], >= 0
  int joint = -1;      ///< The connection it belongs to.
  const char* what = "";
};

std::vector<Length> lengthsOf(const Mechanism& mechanism) {
  std::vector<Length> lengths;
  lengths.reserve(2 * mechanism.joints.size());
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const Joint& joint = mechanism.joints[j];
    const int index = static_cast<int>(j);
    if (joint.kind == ConnectionKind::Coupling) {
      const bool slides = joint.follower >= 0 && joint.follower < static_cast<int>(mechanism.joints.size()) &&
                          mechanism.joints[joint.follower].type == JointType::Prismatic;
      if (slides)
        lengths.push_back({std::abs(joint.offset), index, "offset"});
      continue;
    }
    const bool tree = joint.kind == ConnectionKind::TreeJoint;
    lengths.push_back({joint.frame1.translation().norm(), index, tree ? "origin" : "anchor on link1"});
    lengths.push_back({joint.frame2.translation().norm(), index, "anchor on link2"});
    if (joint.kind == ConnectionKind::Cable)
      lengths.push_back({std::abs(joint.length), index, "length"});
  }
  return lengths;
}

double medianOfNonzero(const std::vector<Length>& lengths) {
  std::vector<double> values;
  values.reserve(lengths.size());
  for (const Length& l : lengths) {
    if (l.value > tolerances::kZeroVector && std::isfinite(l.value))  // CAD round-off (1e-17) is zero
      values.push_back(l.value);
  }
  if (values.empty())
    return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>((values.size() - 1) / 2);  // lower median
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

double typicalLength(const Mechanism& mechanism) {
  return medianOfNonzero(lengthsOf(mechanism));
}

std::optional<Diagnostic> checkLengthRange(const Mechanism& mechanism) {
  const std::vector<Length> lengths = lengthsOf(mechanism);
  const double typical = medianOfNonzero(lengths);
  if (typical <= 0.0)
    return std::nullopt;
  const double limit = tolerances::kMaxRelativeLength * typical;
  for (const Length& l : lengths) {
    if (l.value <= limit)
      continue;
    const Joint& joint = mechanism.joints[l.joint];
    char what[320];
    std::snprintf(what, sizeof(what),
                  "%s of %.6g m is %.3g times the model's typical length %.6g m (the median of its offsets); "
                  "accepted up to %.0g times: the rest of the model would be lost in rounding",
                  l.what, l.value, l.value / typical, typical, tolerances::kMaxRelativeLength);
    return makeDiagnostic(mechanism.file, toString(joint.kind), joint.name, what);
  }
  return std::nullopt;
}

}  // namespace mobility_analysis
