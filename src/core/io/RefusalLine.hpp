#pragma once

#include <string>
#include <vector>

#include "mobility_analysis/Diagnostic.hpp"

namespace mobility_analysis {
namespace io_detail {

/**
 * @brief A reader's refusal with the first warning it gave before it, in the same line.
 *
 * A refusal is one line and the warnings before it are not printed, yet the first may be its cause (a
 * <jiont> not read leaves its child a second root; an SDFormat element not read leaves a link unreached).
 * @return @p refusal, its `what` followed by " (after the warning <kind 'name': what>[, and N more])".
 */
inline Diagnostic refusalAfter(Diagnostic refusal, const std::vector<Diagnostic>& warnings) {
  if (warnings.empty())
    return refusal;
  const Diagnostic& first = warnings.front();
  std::string what = first.elementKind;
  if (!first.elementName.empty())
    what += " '" + first.elementName + "'";
  what += (what.empty() ? "" : ": ") + first.what;
  refusal.what += " (after the warning " + what +
                  (warnings.size() > 1 ? ", and " + std::to_string(warnings.size() - 1) + " more" : "") + ")";
  return refusal;
}

}  // namespace io_detail
}  // namespace mobility_analysis
