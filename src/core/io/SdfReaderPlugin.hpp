#pragma once

#include <string>

#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/Mechanism.hpp"

namespace mobility_analysis {
namespace io_detail {

/// The SDFormat reader's entry point as the plugin exports it (readSdf's signature).
using SdfReadFunction = Result<Mechanism> (*)(const std::string& sdfText, const std::string& fileName);

/// The plugin's file name, looked for beside the core library.
constexpr const char* kSdfPluginFile = "libmobility_analysis_sdf.so";
/// The symbol the plugin exports (C linkage, so that dlsym finds it by this name).
constexpr const char* kSdfPluginSymbol = "mobility_analysis_sdf_reader";

}  // namespace io_detail
}  // namespace mobility_analysis
