// The formatting the bench's report shares (report_detail.h): lenient reads of its JSON, numbers
// for tables and gnuplot data files, and quoting for gnuplot and the shell.
#include <cmath>
#include <cstdio>

#include "report_detail.h"

namespace sdfg::bench {

const Json* member(const Json& j, const std::string& key) {
  if (!j.is_object()) return nullptr;
  const auto it = j.find(key);
  return it == j.end() ? nullptr : &*it;
}

double numberOf(const Json* j) {
  return j && j->is_number() ? j->get<double>() : std::nan("");
}

std::string stringOf(const Json* j) {
  return j && j->is_string() ? j->get<std::string>() : std::string();
}

double numberAt(const Json& row, const std::string& key, const std::string& sub) {
  const Json* v = member(row, key);
  if (v && !sub.empty()) v = member(*v, sub);
  return numberOf(v);
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
