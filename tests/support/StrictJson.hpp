#pragma once
// A strict check of JSON text (RFC 8259 in well-formed UTF-8), for tests of what a run writes: a
// reader that accepts what this accepts accepts summary.json.
#include <cstddef>
#include <string>

namespace mfsi::test {

namespace detail {

class StrictJson {
 public:
  explicit StrictJson(const std::string& s) : s_(s) {}

  /// "" when the text is one JSON value with only whitespace around it, else what is wrong where.
  std::string check() {
    space();
    if (!value(0)) return error_;
    space();
    if (i_ != s_.size()) return at("text after the value");
    return "";
  }

 private:
  bool fail(const std::string& what) {
    if (error_.empty()) error_ = at(what);
    return false;
  }
  std::string at(const std::string& what) const { return what + " at byte " + std::to_string(i_); }
  unsigned char peek() const { return i_ < s_.size() ? static_cast<unsigned char>(s_[i_]) : 0; }
  void space() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r')) ++i_;
  }
  bool literal(const char* word) {
    for (const char* c = word; *c; ++c, ++i_)
      if (i_ >= s_.size() || s_[i_] != *c) return fail(std::string("not '") + word + "'");
    return true;
  }
  bool digits() {
    if (peek() < '0' || peek() > '9') return fail("a digit expected");
    while (peek() >= '0' && peek() <= '9') ++i_;
    return true;
  }
  bool number() {
    if (peek() == '-') ++i_;
    if (peek() == '0') {
      ++i_;
    } else if (!digits()) {
      return false;
    }
    if (peek() == '.') {
      ++i_;
      if (!digits()) return false;
    }
    if (peek() == 'e' || peek() == 'E') {
      ++i_;
      if (peek() == '+' || peek() == '-') ++i_;
      if (!digits()) return false;
    }
    return true;
  }
  int hex4() {
    int v = 0;
    for (int k = 0; k < 4; ++k, ++i_) {
      const unsigned char c = peek();
      int d = -1;
      if (c >= '0' && c <= '9') d = c - '0';
      if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
      if (c >= 'A' && c <= 'F') d = c - 'A' + 10;
      if (d < 0) return -1;
      v = 16 * v + d;
    }
    return v;
  }
  /// One UTF-8 encoded character of a string (Unicode table 3-7).
  bool utf8() {
    const unsigned char lead = peek();
    std::size_t n = 0;
    unsigned char lo = 0x80, hi = 0xBF;
    if (lead >= 0xC2 && lead <= 0xDF) {
      n = 2;
    } else if (lead >= 0xE0 && lead <= 0xEF) {
      n = 3;
      lo = lead == 0xE0 ? 0xA0 : 0x80;
      hi = lead == 0xED ? 0x9F : 0xBF;
    } else if (lead >= 0xF0 && lead <= 0xF4) {
      n = 4;
      lo = lead == 0xF0 ? 0x90 : 0x80;
      hi = lead == 0xF4 ? 0x8F : 0xBF;
    } else {
      return fail("a byte that starts no UTF-8 character");
    }
    for (std::size_t k = 1; k < n; ++k) {
      const unsigned char c = i_ + k < s_.size() ? static_cast<unsigned char>(s_[i_ + k]) : 0;
      if (c < (k == 1 ? lo : 0x80) || c > (k == 1 ? hi : 0xBF)) return fail("ill-formed UTF-8");
    }
    i_ += n;
    return true;
  }
  bool string() {
    ++i_;  // the opening quote
    for (;;) {
      const unsigned char c = peek();
      if (i_ >= s_.size()) return fail("an unterminated string");
      if (c == '"') {
        ++i_;
        return true;
      }
      if (c < 0x20) return fail("a raw control character in a string");
      if (c >= 0x80) {
        if (!utf8()) return false;
        continue;
      }
      ++i_;
      if (c != '\\') continue;
      const unsigned char e = peek();
      ++i_;
      if (e == 'u') {
        const int u = hex4();
        if (u < 0) return fail("a bad \\u escape");
        if (u >= 0xDC00 && u <= 0xDFFF) return fail("a lone low surrogate escape");
        if (u >= 0xD800 && u <= 0xDBFF) {
          if (peek() != '\\') return fail("a lone high surrogate escape");
          ++i_;
          if (peek() != 'u') return fail("a lone high surrogate escape");
          ++i_;
          const int low = hex4();
          if (low < 0xDC00 || low > 0xDFFF) return fail("a lone high surrogate escape");
        }
      } else if (std::string("\"\\/bfnrt").find(static_cast<char>(e)) == std::string::npos || e == 0) {
        return fail("a bad escape");
      }
    }
  }
  bool value(int depth) {
    if (depth > 64) return fail("nesting too deep");
    const unsigned char c = peek();
    if (c == '{' || c == '[') {
      const char close = c == '{' ? '}' : ']';
      ++i_;
      space();
      if (peek() == close) {
        ++i_;
        return true;
      }
      for (;;) {
        if (c == '{') {
          if (peek() != '"') return fail("a member name expected");
          if (!string()) return false;
          space();
          if (peek() != ':') return fail("':' expected");
          ++i_;
          space();
        }
        if (!value(depth + 1)) return false;
        space();
        if (peek() == ',') {
          ++i_;
          space();
          continue;
        }
        if (peek() == close) {
          ++i_;
          return true;
        }
        return fail("',' or the end of the object or array expected");
      }
    }
    if (c == '"') return string();
    if (c == '-' || (c >= '0' && c <= '9')) return number();
    if (c == 't') return literal("true");
    if (c == 'f') return literal("false");
    if (c == 'n') return literal("null");
    return fail("a value expected");
  }

  const std::string& s_;
  std::size_t i_ = 0;
  std::string error_;
};

}  // namespace detail

/// "" when `text` is one JSON value (RFC 8259: no NaN, no raw control characters, no lone
/// surrogate escapes) in well-formed UTF-8, else what is wrong and at which byte.
inline std::string strictJsonError(const std::string& text) { return detail::StrictJson(text).check(); }

}  // namespace mfsi::test
