#include "mobility_analysis/Diagnostic.hpp"

namespace mobility_analysis {

std::string Diagnostic::toString() const {
  std::string line;
  if (!file.empty()) {
    line += file + ": ";
  }
  if (!elementKind.empty()) {
    line += elementKind;
    if (!elementName.empty()) {
      line += " '" + elementName + "'";
    }
    line += ": ";
  }
  return line + what;
}

Diagnostic makeDiagnostic(std::string file, std::string elementKind, std::string elementName, std::string what) {
  return Diagnostic{std::move(file), std::move(elementKind), std::move(elementName), std::move(what)};
}

}  // namespace mobility_analysis
