#include "mobility_analysis/Diagnostic.hpp"

#include <cstdio>

namespace mobility_analysis {

std::string escapeForLine(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (byte < 0x20 || byte == 0x7f) {
      char escaped[8];
      std::snprintf(escaped, sizeof(escaped), "\\x%02x", byte);
      out += escaped;
    } else {
      out += c;
    }
  }
  return out;
}

std::string Diagnostic::toString() const {
  std::string line;
  if (!file.empty()) {
    line += escapeForLine(file) + ": ";
  }
  if (!elementKind.empty()) {
    line += escapeForLine(elementKind);
    if (!elementName.empty()) {
      line += " '" + escapeForLine(elementName) + "'";
    }
    line += ": ";
  }
  return line + escapeForLine(what);
}

Diagnostic makeDiagnostic(std::string file, std::string elementKind, std::string elementName,
                          std::string what) {
  return Diagnostic{std::move(file), std::move(elementKind), std::move(elementName), std::move(what)};
}

}  // namespace mobility_analysis
