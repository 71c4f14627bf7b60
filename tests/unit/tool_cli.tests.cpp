// The value rules the tools' command lines share (tools/common/cli_options.h, on CLI11): numbers
// are decimal and in range, a repeated option keeps its last value, lists keep known names once,
// and every error names the option and the value.
#include <catch2/catch.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cli_options.h"

namespace cli = sdfg::tools::cli;

namespace {

// Parses `args` (without the program name); the error message, if any.
std::optional<std::string> parse(CLI::App& app, std::vector<std::string> args) {
  std::vector<char*> argv = {const_cast<char*>("tool")};
  for (std::string& a : args) argv.push_back(a.data());
  return cli::parse(app, int(argv.size()), argv.data());
}

}  // namespace

TEST_CASE("Integers are decimal and in range", "[tools][cli]") {
  CLI::App app;
  int n = -55;
  cli::addInteger(app, "--n", n, 2, 128);
  SECTION("a decimal value in range is taken, leading zeros included (not octal)") {
    CHECK_FALSE(parse(app, {"--n", "010"}));
    CHECK(n == 10);
  }
  SECTION("--n=VALUE is the same as --n VALUE") {
    CHECK_FALSE(parse(app, {"--n=64"}));
    CHECK(n == 64);
  }
  SECTION("the last of repeated values wins") {
    CHECK_FALSE(parse(app, {"--n", "3", "--n", "4"}));
    CHECK(n == 4);
  }
  SECTION("out of range, hexadecimal, trailing text and nothing are errors naming the value") {
    for (const char* bad : {"1", "129", "0x10", "12abc", "", " 5", "+5", "1e2"}) {
      CAPTURE(bad);
      CLI::App fresh;
      int v = -55;
      cli::addInteger(fresh, "--n", v, 2, 128);
      const auto error = parse(fresh, {"--n", bad});
      REQUIRE(error);
      CHECK(*error == std::string("--n: \"") + bad + "\" is not 2..128");
      CHECK(v == -55);
    }
  }
  SECTION("a missing value is an error") {
    const auto error = parse(app, {"--n"});
    REQUIRE(error);
    CHECK(error->find("--n") != std::string::npos);
  }
}

TEST_CASE("A seed takes the whole unsigned 64-bit range and nothing negative", "[tools][cli]") {
  CLI::App app;
  uint64_t seed = 1;
  cli::addUnsigned64(app, "--seed", seed);
  SECTION("the largest") {
    CHECK_FALSE(parse(app, {"--seed", "18446744073709551615"}));
    CHECK(seed == UINT64_MAX);
  }
  SECTION("negative (CLI11 alone would wrap it), too large, not a number; the seed unchanged") {
    for (const char* bad : {"-1", "18446744073709551616", "x", "12x"}) {
      CAPTURE(bad);
      CLI::App fresh;
      uint64_t v = 1;
      cli::addUnsigned64(fresh, "--seed", v);
      const auto error = parse(fresh, {"--seed", bad});
      REQUIRE(error);
      CHECK(*error == std::string("--seed: \"") + bad + "\" is not a non-negative integer");
      CHECK(v == 1);
    }
  }
}

TEST_CASE("Numbers are finite and pass the tool's check", "[tools][cli]") {
  for (const char* bad : {"0", "1.5", "nan", "inf", "abc", ""}) {
    CAPTURE(bad);
    CLI::App app;
    float x = 0.5f;
    cli::addNumber(
        app, "--da", x, [](float v) { return v > 0.0f && v <= 1.0f; }, "a number in (0, 1]");
    const auto error = parse(app, {"--da", bad});
    REQUIRE(error);
    CHECK(*error == std::string("--da: \"") + bad + "\" is not a number in (0, 1]");
    CHECK(x == 0.5f);
  }
  CLI::App app;
  float x = 0.5f;
  cli::addNumber(
      app, "--da", x, [](float v) { return v > 0.0f && v <= 1.0f; }, "a number in (0, 1]");
  CHECK_FALSE(parse(app, {"--da", "0.25"}));
  CHECK(x == 0.25f);
}

TEST_CASE("Lists keep known names once, in order", "[tools][cli]") {
  CLI::App app;
  std::vector<std::string> out = {"default"};
  cli::addList(app, "--methods", {"ours", "paper", "physics"}, "method", out);
  SECTION("duplicates and empty items are dropped") {
    CHECK_FALSE(parse(app, {"--methods", "paper,,ours,paper,"}));
    CHECK(out == std::vector<std::string>{"paper", "ours"});
  }
  SECTION("an unknown name is named, with the known ones") {
    const auto error = parse(app, {"--methods", "ours,nope"});
    REQUIRE(error);
    CHECK(*error == "--methods: unknown method \"nope\"; known: ours, paper, physics");
    CHECK(out == std::vector<std::string>{"default"});
  }
  SECTION("no name at all") {
    const auto error = parse(app, {"--methods", ","});
    REQUIRE(error);
    CHECK(*error == "--methods: no method given");
  }
}

namespace {

// A parser with one option of each remaining kind, and where their values go.
struct MixedOptions {
  CLI::App app;
  std::vector<long long> res;
  std::string json;
  bool on = false;
  std::vector<std::string> meshes;
  MixedOptions() {
    cli::addIntegerList(app, "--res", 2, 128, "resolution", res);
    cli::addName(app, "--json", json, "file name");
    cli::addOnOff(app, "--check", on);
    cli::addRepeatable(app, "--mesh", meshes);
  }
};

}  // namespace

TEST_CASE("Integer lists, names, switches and repeatable options", "[tools][cli]") {
  SECTION("all taken") {
    MixedOptions o;
    CHECK_FALSE(parse(o.app, {"--res", "16,32", "--json", "a b.json", "--check", "on", "--mesh",
                              "x.obj", "--mesh=y.obj"}));
    CHECK(o.res == std::vector<long long>{16, 32});
    CHECK(o.json == "a b.json");
    CHECK(o.on);
    CHECK(o.meshes == std::vector<std::string>{"x.obj", "y.obj"});
  }
  SECTION("errors") {
    using Case = std::pair<std::vector<std::string>, std::string>;
    for (const auto& [args, message] :
         {Case{{"--res", "16,1"}, "--res: \"1\" is not 2..128"},
          Case{{"--res", ","}, "--res: no resolution given"},
          Case{{"--json", ""}, "--json: empty file name"},
          Case{{"--check", "yes"}, "--check: \"yes\" is not on or off"},
          Case{{"--mesh", "x.obj", "y.obj"}, "The following argument was not expected: y.obj"},
          Case{{"--bogus"}, "The following argument was not expected: --bogus"}}) {
      CAPTURE(args);
      MixedOptions o;
      const auto error = parse(o.app, args);
      REQUIRE(error);
      CHECK(*error == message);
      CHECK(o.res.empty());
      CHECK(o.json.empty());
    }
  }
}

TEST_CASE("--help is a plain flag: the tool prints its own text", "[tools][cli]") {
  for (const char* flag : {"-h", "--help"}) {
    CAPTURE(flag);
    CLI::App app;
    bool help = false;
    cli::addHelpFlag(app, help);
    CHECK_FALSE(parse(app, {flag}));
    CHECK(help);
  }
}
