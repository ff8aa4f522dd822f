#pragma once

#include <string>
#include <utility>
#include <variant>

namespace mobility_analysis {

/**
 * @brief A problem with the caller's input, as a value the caller can show.
 *
 * Every failure of the core (a malformed URDF, an unknown link, a loop that cannot be closed) is
 * returned as a Diagnostic inside a Result; no exception crosses the public API.
 */
struct Diagnostic {
  std::string file;         ///< File (or source name) the input came from; may be empty.
  std::string elementKind;  ///< "loop_joint", "joint", "link", "positions", … ; may be empty.
  std::string elementName;  ///< Name of the offending element; may be empty.
  std::string what;         ///< What is wrong, with expected vs got where sizes differ.

  /// @return One line: "bennett.urdf: loop_joint 'j4': link2 'rockr' is not a link". Every field goes through
  ///         escapeForLine, so a name or a third-party message with a newline still gives one line.
  std::string toString() const;
};

/// Either a value or the Diagnostic that explains why there is none.
template <class T>
using Result = std::variant<T, Diagnostic>;

/// @return True when @p result holds a value.
template <class T>
bool isOk(const Result<T>& result) {
  return std::holds_alternative<T>(result);
}

/// @note Precondition: isOk(result).
template <class T>
const T& valueOf(const Result<T>& result) {
  return std::get<T>(result);
}

/// @note Precondition: isOk(result).
template <class T>
T&& valueOf(Result<T>&& result) {
  return std::get<T>(std::move(result));
}

/// @note Precondition: !isOk(result).
template <class T>
const Diagnostic& diagnosticOf(const Result<T>& result) {
  return std::get<Diagnostic>(result);
}

/**
 * @brief Escapes what would break a one-line message: newline, carriage return and tab as \\n, \\r, \\t,
 *        every other control character (and DEL) as \\xNN, and so is every byte that is not part of a valid
 *        UTF-8 sequence (the line stays valid UTF-8 text, as ROS strings and JSON need). Valid UTF-8 passes
 *        unchanged.
 */
std::string escapeForLine(const std::string& text);

/// @return The length (1 to 4) of the valid UTF-8 sequence starting at byte @p at of @p text, 0 when the bytes
///         there are not one (a stray continuation byte, an overlong form, a surrogate, beyond U+10FFFF, cut).
int utf8SequenceLength(const std::string& text, size_t at);

/// Builds a Diagnostic in one expression.
Diagnostic makeDiagnostic(std::string file, std::string elementKind, std::string elementName, std::string what);

}  // namespace mobility_analysis
