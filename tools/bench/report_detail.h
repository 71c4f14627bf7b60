// Internal to autograsp-bench's report and scaling sweep (report.cpp, scaling.cpp,
// json_reader.cpp): the small JSON reader, the number formatting the tables and gnuplot files
// share, and the sweep's Markdown tables.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "report.h"

namespace sdfg::bench {

constexpr float kHandSizeDiagonal = 0.18f;  // as the bench: every object scaled to this diagonal
constexpr uint64_t kScalingSeed = 1;

// A small JSON reader: enough for the bench's own output (objects, arrays, strings, numbers,
// true/false/null). Object members keep their order, so columns come out as the bench wrote them.
struct Json {
  using Object = std::vector<std::pair<std::string, Json>>;
  using Array = std::vector<Json>;
  std::variant<std::nullptr_t, bool, double, std::string, Array, Object> v;

  bool isNumber() const { return std::holds_alternative<double>(v); }
  bool isNull() const { return std::holds_alternative<std::nullptr_t>(v); }
  const Object* object() const { return std::get_if<Object>(&v); }
  const Array* array() const { return std::get_if<Array>(&v); }
  const Json* find(const std::string& key) const {
    if (const Object* o = object()) {
      for (const auto& [k, value] : *o) {
        if (k == key) return &value;
      }
    }
    return nullptr;
  }
  double number() const { return isNumber() ? std::get<double>(v) : std::nan(""); }
  std::string string() const {
    if (const auto* s = std::get_if<std::string>(&v)) return *s;
    return {};
  }
};

// Parses `text`; on failure returns nothing and sets `error` (with the offset).
std::optional<Json> parseJson(const std::string& text, std::string& error);

// Three significant digits, but whole numbers from 1000 up (no "1.1e+04" in a table).
std::string fmt(double v);
std::string withThousands(size_t n);
// Numbers for gnuplot's data files: NaN marks a missing value (set datafile missing "NaN").
std::string datNumber(double v);
std::string datString(const std::string& s);
std::string gpString(const std::string& s);
std::string shellQuote(const std::string& s);

// Markdown tables of the sweep; shared by the console and the report.
std::string scalingTables(const ScalingResults& r, const std::string& level);

}  // namespace sdfg::bench
