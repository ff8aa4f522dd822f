/// libFuzzer target: any bytes as a closed-loop URDF through the whole CLI path (load, analyse, JSON).
///
/// What counts as a finding (besides a crash or a sanitizer report): a diagnostic that is not one line, or a
/// report whose JSON holds `inf` or `nan`. Models above kMaxLinks are only loaded, so each input stays fast.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "mobility_analysis/mobility_analysis.hpp"

namespace {

constexpr size_t kMaxLinks = 64;

void requireOneLine(const mobility_analysis::Diagnostic& diagnostic) {
  const std::string line = diagnostic.toString();
  if (line.find('\n') != std::string::npos || line.find('\r') != std::string::npos) {
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace mobility_analysis;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const Result<Mechanism> mechanism = loadMechanismFromString(text, "fuzz.urdf");
  if (!isOk(mechanism)) {
    requireOneLine(diagnosticOf(mechanism));
    return 0;
  }
  if (valueOf(mechanism).links.size() > kMaxLinks) {
    return 0;
  }
  AnalysisOptions options;
  const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), options);
  if (!isOk(analysis)) {
    requireOneLine(diagnosticOf(analysis));
    return 0;
  }
  const std::string json = toJson(valueOf(analysis).report);
  if (json.find("nan") != std::string::npos || json.find("inf") != std::string::npos) {
    std::abort();
  }
  return 0;
}
