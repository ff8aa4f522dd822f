#pragma once

// Private to src/core: readUrdfFile's reading in two halves (io_detail::parseInHalves) and its test.

#include <cstddef>
#include <string>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis {
namespace core_detail {

/// readUrdfFile on two threads, its file parsed in two halves cut at the first top-level element from byte
/// @p cutFrom on, whatever the file's size, where that can be done (else read whole); @p cut is
/// set to the byte the second half starts at, 0 when it was read whole. The answer is readUrdfFile's.
Result<Mechanism> readUrdfFileCutFrom(const std::string& path, size_t cutFrom, size_t* cut);

}  // namespace core_detail
}  // namespace mobility_analysis
