/// libFuzzer target: any bytes as a closed-loop URDF through the whole CLI path (load, analyse, writeJson).
///
/// What counts as a finding (besides a crash or a sanitizer report): a diagnostic that is not one line of
/// text (a control character or bytes that are not UTF-8); a report that writeJson refuses (its own
/// invariants broken: a bug of the analysis, not bad input); a written report that is not valid JSON (inf,
/// nan, a raw control character or invalid UTF-8 in a string), checked by the tests' strict validator.
/// Models above kMaxLinks are only loaded, so each input stays fast.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "../core/JsonCheck.hpp"
#include "mobility_analysis/mobility_analysis.hpp"

namespace {

constexpr size_t kMaxLinks = 64;

/// Aborts (a finding) unless @p line is one line of printable UTF-8 text.
void requireOneLine(const std::string& line) {
  std::string asJson = "\"";
  for (const char c : line) {
    if (static_cast<unsigned char>(c) < 0x20 || c == '\x7f')
      std::abort();
    asJson += c == '"' || c == '\\' ? ' ' : c;
  }
  if (!mobility_analysis::JsonCheck::check(asJson + "\"").empty())
    std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace mobility_analysis;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const Result<Mechanism> mechanism = loadMechanismFromString(text, "fuzz.urdf");
  if (!isOk(mechanism)) {
    requireOneLine(diagnosticOf(mechanism).toString());
    return 0;
  }
  for (const Diagnostic& warning : valueOf(mechanism).warnings)
    requireOneLine(warning.toString());
  if (valueOf(mechanism).links.size() > kMaxLinks) {
    return 0;
  }
  AnalysisOptions options;
  const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), options);
  if (!isOk(analysis)) {
    requireOneLine(diagnosticOf(analysis).toString());
    return 0;
  }
  const Result<std::string> json = writeJson(valueOf(analysis).report);
  // A refused report (inf/nan, counts that contradict each other) is the analysis' bug, not bad input.
  if (!isOk(json) || !JsonCheck::check(valueOf(json)).empty()) {
    std::abort();
  }
  return 0;
}
