#pragma once

// Private to src/core: toJson (MobilityReport.cpp) and its test.

#include <cstddef>
#include <ostream>
#include <string>

#include "mobility_analysis/MobilityReport.hpp"

namespace mobility_analysis {
namespace core_detail {

/// toJson, written in two halves on two threads once the report's estimated size reaches
/// @p secondThreadFrom bytes (0: always, even an empty report; SIZE_MAX: never). The text is the same either
/// way.
std::string toJson(const MobilityReport& r, size_t secondThreadFrom);
/// The same text written to @p out as it is made (writeJson to a stream).
void writeJson(const MobilityReport& r, std::ostream& out, size_t secondThreadFrom);

}  // namespace core_detail
}  // namespace mobility_analysis
