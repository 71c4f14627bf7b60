// The tools' command lines: CLI11 (Debian's libcli11-dev) takes the arguments apart (--opt VALUE
// and --opt=VALUE, repeated options, unknown options and stray words); these helpers add the
// value rules every tool shares, each error naming the option and the value:
//   - integers are decimal only (CLI11's own conversion also reads 010 as octal and 0x10 as hex,
//     and turns -1 into a huge unsigned) and checked against a range;
//   - an option given twice keeps its last value, as the tools always did; a repeatable one
//     takes one value per occurrence (`--mesh a b` is an error, not two meshes).
// Each tool keeps its own usage text: CLI11's generated help is switched off.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace sdfg::tools::cli {

// A parser with -h / --help as a plain flag that sets `help` (the tool prints its own text).
void addHelpFlag(CLI::App& app, bool& help);

// A decimal integer in [lo, hi]; the error says "is not <expected>" (default "lo..hi").
CLI::Option* addInteger(CLI::App& app, const std::string& name, long long lo, long long hi,
                        std::function<void(long long)> set, std::string expected = {});
template <class T>
CLI::Option* addInteger(CLI::App& app, const std::string& name, T& out, long long lo, long long hi,
                        std::string expected = {}) {
  return addInteger(
      app, name, lo, hi, [&out](long long v) { out = T(v); }, std::move(expected));
}
// A decimal integer from 0 to 2^64 - 1 (a seed).
CLI::Option* addUnsigned64(CLI::App& app, const std::string& name, std::uint64_t& out);

// A finite decimal number for which `ok` holds; the error says "is not <expected>".
CLI::Option* addNumber(CLI::App& app, const std::string& name, float& out,
                       std::function<bool(float)> ok, const std::string& expected);

// A comma-separated list of decimal integers in [lo, hi], empty items skipped; `what` names an
// item in the error for an empty list ("no <what> given").
CLI::Option* addIntegerList(CLI::App& app, const std::string& name, long long lo, long long hi,
                            const std::string& what, std::vector<long long>& out);

// "on" or "off".
CLI::Option* addOnOff(CLI::App& app, const std::string& name, bool& out);

// A value that must not be empty (a file or folder); `what` names it in the error ("file name").
CLI::Option* addName(CLI::App& app, const std::string& name, std::string& out,
                     const std::string& what);

// A value per occurrence, all kept in order (--mesh FILE, repeatable).
CLI::Option* addRepeatable(CLI::App& app, const std::string& name, std::vector<std::string>& out);

// A comma-separated list of names from `names`, each kept once in the order given; empty items
// are skipped, an unknown name is an error listing the known ones ("unknown <what> \"x\"; known:
// a, b"), and so is a list with no name ("no <what> given").
CLI::Option* addList(CLI::App& app, const std::string& name, std::vector<std::string> names,
                     const std::string& what, std::vector<std::string>& out);

// Parses the arguments. Returns the first error's message (CLI11's or one of the rules above).
std::optional<std::string> parse(CLI::App& app, int argc, char** argv);

// Parses a tool's arguments, with -h / --help printing the tool's own `usage`. Returns the exit
// code when the tool is done: 2 after "<tool>: <error>" and the usage on stderr, 0 after the
// usage on stdout for --help; nothing when it goes on.
std::optional<int> parseOrUsage(CLI::App& app, int argc, char** argv, const char* tool,
                                const char* usage);

// Splits a comma-separated list, dropping empty items ("16,,32," gives 16 and 32).
std::vector<std::string> splitList(const std::string& text);

}  // namespace sdfg::tools::cli
