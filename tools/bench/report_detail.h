// Internal to autograsp-bench's report and scaling sweep (report.cpp, scaling.cpp,
// report_format.cpp): reading the bench's JSON, the number formatting the tables and gnuplot
// files share, and the sweep's Markdown tables.
#pragma once

#include <cstdint>
#include <string>

#include "json_file.h"
#include "report.h"

namespace sdfg::bench {

constexpr float kHandSizeDiagonal = 0.18f;  // as the bench: every object scaled to this diagonal
constexpr uint64_t kScalingSeed = 1;

// The bench's JSON files (json_file.h), read leniently: a member that is missing or of another
// type reads as absent, NaN or "".
using tools::Json;
// The member `key` of an object; nullptr when `j` is no object or has no such member.
const Json* member(const Json& j, const std::string& key);
// A number's value; NaN for anything else, nullptr included.
double numberOf(const Json* j);
// A string's value; "" for anything else, nullptr included.
std::string stringOf(const Json* j);
// The number at row[key][sub] (row[key] when `sub` is empty); NaN when any step is missing.
double numberAt(const Json& row, const std::string& key, const std::string& sub = {});

// Three significant digits, but whole numbers from 1000 up (no "1.1e+04" in a table).
std::string fmt(double v);
std::string withThousands(size_t n);
// Numbers for gnuplot's data files: NaN marks a missing value (set datafile missing "NaN").
std::string datNumber(double v);
std::string datString(const std::string& s);
std::string gpString(const std::string& s);
std::string shellQuote(const std::string& s);

// The report's "Scenes" section from the results JSON ("scenes", --scenes); empty without one.
std::string scenesSection(const Json& results);

// Markdown tables of the sweep; shared by the console and the report.
std::string scalingTables(const ScalingResults& r, const std::string& level);

}  // namespace sdfg::bench
