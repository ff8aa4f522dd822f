#pragma once

#include <cctype>
#include <string>

namespace mobility_analysis {

/**
 * @brief A strict RFC 8259 JSON validator, written independently of the report's writer: the whole text must
 * be one value (blanks around it allowed). `NaN`, `Infinity`, `inf`, `nan`, leading zeros, a bare `.5`,
 *        trailing commas, control characters in strings, bad escapes and invalid UTF-8 are all errors, as in
 * any conforming parser.
 */
class JsonCheck {
 public:
  /// @return Empty when @p text is valid JSON, else what is wrong and where.
  static std::string check(const std::string& text) {
    JsonCheck parser(text);
    parser.blanks();
    if (!parser.value(0))
      return parser.error_;
    parser.blanks();
    if (parser.at_ != text.size()) {
      parser.fail("text after the value");
      return parser.error_;
    }
    return "";
  }

 private:
  explicit JsonCheck(const std::string& text) : text_(text) {}

  static constexpr int kMaxDepth = 256;

  bool fail(const std::string& what) {
    if (error_.empty())
      error_ = what + " at offset " + std::to_string(at_);
    return false;
  }
  char peek() const { return at_ < text_.size() ? text_[at_] : '\0'; }
  void blanks() {
    while (at_ < text_.size() && (peek() == ' ' || peek() == '\t' || peek() == '\n' || peek() == '\r'))
      ++at_;
  }
  bool literal(const char* word) {
    const std::string w(word);
    if (text_.compare(at_, w.size(), w) != 0)
      return fail("bad literal");
    at_ += w.size();
    return true;
  }
  bool digits() {
    if (!std::isdigit(static_cast<unsigned char>(peek())))
      return fail("digit expected");
    while (std::isdigit(static_cast<unsigned char>(peek())))
      ++at_;
    return true;
  }
  bool number() {
    if (peek() == '-')
      ++at_;
    if (peek() == '0') {
      ++at_;
    } else if (!digits()) {
      return false;
    }
    if (peek() == '.') {
      ++at_;
      if (!digits())
        return false;
    }
    if (peek() == 'e' || peek() == 'E') {
      ++at_;
      if (peek() == '+' || peek() == '-')
        ++at_;
      if (!digits())
        return false;
    }
    return true;
  }
  bool string() {
    ++at_;  // opening quote
    while (at_ < text_.size()) {
      const unsigned char c = static_cast<unsigned char>(text_[at_]);
      if (c == '"') {
        ++at_;
        return true;
      }
      if (c < 0x20)
        return fail("control character in a string");
      if (c >= 0x80) {  // one UTF-8 sequence: a lead byte and its continuation bytes, shortest form
        const int extra = (c & 0xE0) == 0xC0 ? 1 : (c & 0xF0) == 0xE0 ? 2 : (c & 0xF8) == 0xF0 ? 3 : -1;
        if (extra < 0 || c == 0xC0 || c == 0xC1 || c > 0xF4)
          return fail("invalid UTF-8");
        for (int k = 1; k <= extra; ++k) {
          if (at_ + k >= text_.size() || (static_cast<unsigned char>(text_[at_ + k]) & 0xC0) != 0x80)
            return fail("invalid UTF-8");
        }
        at_ += extra + 1;
        continue;
      }
      if (c == '\\') {
        ++at_;
        const char e = peek();
        if (e == 'u') {
          for (int k = 1; k <= 4; ++k) {
            if (!std::isxdigit(static_cast<unsigned char>(at_ + k < text_.size() ? text_[at_ + k] : '\0')))
              return fail("bad \\u escape");
          }
          at_ += 4;
        } else if (std::string("\"\\/bfnrt").find(e) == std::string::npos || e == '\0') {
          return fail("bad escape");
        }
      }
      ++at_;
    }
    return fail("unterminated string");
  }
  bool value(int depth) {
    if (depth > kMaxDepth)
      return fail("nested too deep");
    blanks();
    const char c = peek();
    if (c == '{' || c == '[') {
      const char close = c == '{' ? '}' : ']';
      ++at_;
      blanks();
      if (peek() == close) {
        ++at_;
        return true;
      }
      while (true) {
        blanks();
        if (c == '{') {
          if (peek() != '"')
            return fail("member name expected");
          if (!string())
            return false;
          blanks();
          if (peek() != ':')
            return fail("':' expected");
          ++at_;
        }
        if (!value(depth + 1))
          return false;
        blanks();
        if (peek() == ',') {
          ++at_;
          continue;
        }
        if (peek() == close) {
          ++at_;
          return true;
        }
        return fail("',' or closing bracket expected");
      }
    }
    if (c == '"')
      return string();
    if (c == 't')
      return literal("true");
    if (c == 'f')
      return literal("false");
    if (c == 'n')
      return literal("null");
    if (c == '-' || std::isdigit(static_cast<unsigned char>(c)))
      return number();
    return fail("value expected");
  }

  const std::string& text_;
  size_t at_ = 0;
  std::string error_;
};

}  // namespace mobility_analysis
