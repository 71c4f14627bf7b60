#include "cli_options.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace sdfg::tools::cli {
namespace {

// The whole of `s` as a decimal number of type T (from_chars: no sign other than a leading '-'
// for signed types, no spaces, no base prefix).
template <class T>
bool decimal(const std::string& s, T& out) {
  const char* end = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(s.data(), end, out);
  return !s.empty() && ec == std::errc{} && ptr == end;
}

CLI::ValidationError valueError(const std::string& name, const std::string& value,
                                const std::string& expected) {
  return CLI::ValidationError(name, "\"" + value + "\" is not " + expected);
}

// One value per occurrence; a later occurrence replaces an earlier one.
CLI::Option* single(CLI::Option* option) {
  return option->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
}

}  // namespace

void addHelpFlag(CLI::App& app, bool& help) {
  app.set_help_flag();
  app.add_flag("-h,--help", help);
}

CLI::Option* addInteger(CLI::App& app, const std::string& name, long long lo, long long hi,
                        std::function<void(long long)> set, std::string expected) {
  if (expected.empty()) expected = std::to_string(lo) + ".." + std::to_string(hi);
  return single(app.add_option_function<std::string>(
      name, [name, lo, hi, set = std::move(set), expected](const std::string& v) {
        long long n = 0;
        if (!decimal(v, n) || n < lo || n > hi) throw valueError(name, v, expected);
        set(n);
      }));
}

CLI::Option* addUnsigned64(CLI::App& app, const std::string& name, std::uint64_t& out) {
  return single(app.add_option_function<std::string>(name, [name, &out](const std::string& v) {
    std::uint64_t n = 0;
    if (!decimal(v, n)) throw valueError(name, v, "a non-negative integer");
    out = n;
  }));
}

CLI::Option* addNumber(CLI::App& app, const std::string& name, float& out,
                       std::function<bool(float)> ok, const std::string& expected) {
  return single(app.add_option_function<std::string>(
      name, [name, &out, ok = std::move(ok), expected](const std::string& v) {
        float x = 0.0f;
        if (!decimal(v, x) || !std::isfinite(x) || !ok(x)) throw valueError(name, v, expected);
        out = x;
      }));
}

CLI::Option* addIntegerList(CLI::App& app, const std::string& name, long long lo, long long hi,
                            const std::string& what, std::vector<long long>& out) {
  return single(app.add_option_function<std::string>(
      name, [name, lo, hi, what, &out](const std::string& text) {
        std::vector<long long> list;
        for (const std::string& item : splitList(text)) {
          long long n = 0;
          if (!decimal(item, n) || n < lo || n > hi) {
            throw valueError(name, item, std::to_string(lo) + ".." + std::to_string(hi));
          }
          list.push_back(n);
        }
        if (list.empty()) throw CLI::ValidationError(name, "no " + what + " given");
        out = std::move(list);
      }));
}

CLI::Option* addOnOff(CLI::App& app, const std::string& name, bool& out) {
  return single(app.add_option_function<std::string>(name, [name, &out](const std::string& v) {
    if (v != "on" && v != "off") throw valueError(name, v, "on or off");
    out = v == "on";
  }));
}

CLI::Option* addName(CLI::App& app, const std::string& name, std::string& out,
                     const std::string& what) {
  return single(
      app.add_option_function<std::string>(name, [name, &out, what](const std::string& v) {
        if (v.empty()) throw CLI::ValidationError(name, "empty " + what);
        out = v;
      }));
}

CLI::Option* addRepeatable(CLI::App& app, const std::string& name, std::vector<std::string>& out) {
  return app.add_option(name, out)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->allow_extra_args(false);
}

CLI::Option* addList(CLI::App& app, const std::string& name, std::vector<std::string> names,
                     const std::string& what, std::vector<std::string>& out) {
  return single(app.add_option_function<std::string>(name, [name, names = std::move(names), what,
                                                            &out](const std::string& text) {
    std::vector<std::string> list;
    for (const std::string& item : splitList(text)) {
      if (std::find(names.begin(), names.end(), item) == names.end()) {
        std::string known;
        for (const auto& k : names) known += (known.empty() ? "" : ", ") + k;
        throw CLI::ValidationError(name, "unknown " + what + " \"" + item + "\"; known: " + known);
      }
      if (std::find(list.begin(), list.end(), item) == list.end()) list.push_back(item);
    }
    if (list.empty()) throw CLI::ValidationError(name, "no " + what + " given");
    out = std::move(list);
  }));
}

std::optional<std::string> parse(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return std::string(e.what());
  }
  return std::nullopt;
}

std::optional<int> parseOrUsage(CLI::App& app, int argc, char** argv, const char* tool,
                                const char* usage) {
  bool help = false;
  addHelpFlag(app, help);
  if (auto error = parse(app, argc, argv)) {
    std::fprintf(stderr, "%s: %s\n%s", tool, error->c_str(), usage);
    return 2;
  }
  if (help) {
    std::fputs(usage, stdout);
    return 0;
  }
  return std::nullopt;
}

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

}  // namespace sdfg::tools::cli
