// The bench's JSON reader (report_detail.h) and writers (report.h): the report reads back what
// the bench wrote, so the two sides live together.
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "report_detail.h"

namespace sdfg::bench {
namespace {

class JsonParser {
 public:
  explicit JsonParser(const std::string& text) : s_(text) {}

  std::optional<Json> parse(std::string& error) {
    Json out;
    if (!value(out, 0) || (skip(), pos_ != s_.size())) {
      error = error_.empty() ? "unexpected text at offset " + std::to_string(pos_) : error_;
      return std::nullopt;
    }
    return out;
  }

 private:
  void skip() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool fail(const std::string& what) {
    if (error_.empty()) error_ = what + " at offset " + std::to_string(pos_);
    return false;
  }
  bool literal(const char* word) {
    const size_t n = std::char_traits<char>::length(word);
    if (s_.compare(pos_, n, word) != 0) return fail("bad literal");
    pos_ += n;
    return true;
  }
  bool str(std::string& out) {
    ++pos_;  // opening quote
    while (pos_ < s_.size() && s_[pos_] != '"') {
      char c = s_[pos_++];
      if (c == '\\') {
        if (pos_ >= s_.size()) return fail("unterminated escape");
        const char e = s_[pos_++];
        switch (e) {
          case 'n':
            c = '\n';
            break;
          case 't':
            c = '\t';
            break;
          case 'r':
            c = '\r';
            break;
          case 'b':
            c = '\b';
            break;
          case 'f':
            c = '\f';
            break;
          case 'u': {
            if (pos_ + 4 > s_.size()) return fail("short \\u escape");
            const unsigned code = unsigned(std::strtoul(s_.substr(pos_, 4).c_str(), nullptr, 16));
            pos_ += 4;
            c = code < 0x80 ? char(code) : '?';  // the bench writes only control characters so
            break;
          }
          default:
            c = e;
        }
      }
      out += c;
    }
    if (pos_ >= s_.size()) return fail("unterminated string");
    ++pos_;
    return true;
  }
  bool value(Json& out, int depth) {
    if (depth > 64) return fail("nesting too deep");
    skip();
    if (pos_ >= s_.size()) return fail("unexpected end");
    const char c = s_[pos_];
    if (c == '{') {
      ++pos_;
      Json::Object members;
      skip();
      if (pos_ < s_.size() && s_[pos_] == '}') {
        ++pos_;
      } else {
        for (;;) {
          skip();
          if (pos_ >= s_.size() || s_[pos_] != '"') return fail("expected a member name");
          std::string key;
          if (!str(key)) return false;
          skip();
          if (pos_ >= s_.size() || s_[pos_] != ':') return fail("expected ':'");
          ++pos_;
          Json member;
          if (!value(member, depth + 1)) return false;
          members.emplace_back(std::move(key), std::move(member));
          skip();
          if (pos_ < s_.size() && s_[pos_] == ',') {
            ++pos_;
          } else if (pos_ < s_.size() && s_[pos_] == '}') {
            ++pos_;
            break;
          } else {
            return fail("expected ',' or '}'");
          }
        }
      }
      out.v = std::move(members);
      return true;
    }
    if (c == '[') {
      ++pos_;
      Json::Array items;
      skip();
      if (pos_ < s_.size() && s_[pos_] == ']') {
        ++pos_;
      } else {
        for (;;) {
          Json item;
          if (!value(item, depth + 1)) return false;
          items.push_back(std::move(item));
          skip();
          if (pos_ < s_.size() && s_[pos_] == ',') {
            ++pos_;
          } else if (pos_ < s_.size() && s_[pos_] == ']') {
            ++pos_;
            break;
          } else {
            return fail("expected ',' or ']'");
          }
        }
      }
      out.v = std::move(items);
      return true;
    }
    if (c == '"') {
      std::string text;
      if (!str(text)) return false;
      out.v = std::move(text);
      return true;
    }
    if (c == 'n') return literal("null") && (out.v = nullptr, true);
    if (c == 't') return literal("true") && (out.v = true, true);
    if (c == 'f') return literal("false") && (out.v = false, true);
    char* end = nullptr;
    const double d = std::strtod(s_.c_str() + pos_, &end);
    if (end == s_.c_str() + pos_) return fail("unexpected character");
    pos_ = size_t(end - s_.c_str());
    out.v = d;
    return true;
  }

  const std::string& s_;
  size_t pos_ = 0;
  std::string error_;
};

}  // namespace

std::optional<Json> parseJson(const std::string& text, std::string& error) {
  return JsonParser(text).parse(error);
}

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += char(c);
        }
    }
  }
  return out + "\"";
}

std::string jsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string fmt(double v) {
  if (!std::isfinite(v)) return "-";
  char buf[48];
  if (std::fabs(v) >= 1000.0) {
    std::snprintf(buf, sizeof buf, "%.0f", v);
  } else {
    std::snprintf(buf, sizeof buf, "%.3g", v);
  }
  return buf;
}

std::string withThousands(size_t n) {
  std::string digits = std::to_string(n), out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

std::string datNumber(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string datString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) out += c == '"' ? '\'' : c;
  return out + "\"";
}

std::string gpString(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'')
      out += "''";
    else
      out += c;
  }
  return out + "'";
}

std::string shellQuote(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                        "0123456789_-./=,:+@%") == std::string::npos) {
    return s;
  }
  std::string out = "'";
  for (char c : s) {
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  return out + "'";
}

}  // namespace sdfg::bench
