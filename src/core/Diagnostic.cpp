#include "mobility_analysis/Diagnostic.hpp"

#include <cstdio>

namespace mobility_analysis {

int utf8SequenceLength(const std::string& text, size_t at) {
  const auto byte = [&](size_t k) {
    return at + k < text.size() ? static_cast<unsigned char>(text[at + k]) : 0;
  };
  const unsigned char lead = byte(0);
  if (lead < 0x80)
    return at < text.size() ? 1 : 0;
  int length = 0;
  unsigned char low = 0x80, high = 0xBF;  // the range of the second byte (RFC 3629, table 3-7 of Unicode)
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    low = lead == 0xE0 ? 0xA0 : 0x80;
    high = lead == 0xED ? 0x9F : 0xBF;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    low = lead == 0xF0 ? 0x90 : 0x80;
    high = lead == 0xF4 ? 0x8F : 0xBF;
  } else {
    return 0;
  }
  if (byte(1) < low || byte(1) > high)
    return 0;
  for (int k = 2; k < length; ++k) {
    if (byte(k) < 0x80 || byte(k) > 0xBF)
      return 0;
  }
  return length;
}

std::string escapeForLine(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x80) {
      const int length = utf8SequenceLength(text, i);
      if (length == 0) {
        char escaped[8];
        std::snprintf(escaped, sizeof(escaped), "\\x%02x", byte);
        out += escaped;
      } else {
        out.append(text, i, static_cast<size_t>(length));
        i += static_cast<size_t>(length) - 1;
      }
    } else if (c == '\n') {
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
