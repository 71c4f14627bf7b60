// The layer's configuration keys (layer/config.h): every key takes a good value into its field
// and refuses a bad one, and a refused value leaves the whole configuration as it was. Built
// twice (tests/CMakeLists.txt): with the layer's test build's key test_layer_fault
// (SDFG_LAYER_TEST_FAULTS=1), and as shipped, without it.
#include <catch2/catch.hpp>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "config.h"
#include "test_fault.h"

using sdfg::layer::applyConfigValue;
using sdfg::layer::Config;
using sdfg::layer::LogLevel;

namespace {

// Field by field: a refused value must leave every one as it was.
bool sameConfig(const Config& a, const Config& b) {
  return a.logLevel == b.logLevel && a.solver == b.solver && a.grabThreshold == b.grabThreshold &&
         a.releaseRatio == b.releaseRatio && a.resolution == b.resolution &&
         a.curlStep == b.curlStep && a.exactCheck == b.exactCheck &&
         a.buildTimeLimitMs == b.buildTimeLimitMs && a.sdfFarBand == b.sdfFarBand &&
         a.synthesis == b.synthesis && a.gpu == b.gpu && a.extraQueue == b.extraQueue &&
         a.testGpuFault == b.testGpuFault && a.testLayerFault == b.testLayerFault &&
         a.configPath == b.configPath && a.clearHand == b.clearHand &&
         a.clearBound == b.clearBound && a.approach == b.approach &&
         a.approachRange == b.approachRange && a.approachMaxAngle == b.approachMaxAngle &&
         a.offsetBlendTime == b.offsetBlendTime;
}

struct KeyCase {
  const char* key;
  const char* good;
  bool (*took)(const Config&);  // the good value is in its field
  const char* bad;
};

// Every key of the configuration (docs/layer.md, "Configuration"), a value it takes and one it
// refuses.
const KeyCase kKeys[] = {
    {"log_level", "debug", [](const Config& c) { return c.logLevel == LogLevel::debug; }, "loud"},
    {"solver", "paper", [](const Config& c) { return c.solver == "paper"; }, ""},
    {"grab_threshold", "0.5", [](const Config& c) { return c.grabThreshold == 0.5f; }, "0"},
    {"release_ratio", "0.5", [](const Config& c) { return c.releaseRatio == 0.5f; }, "1.5"},
    {"resolution", "32", [](const Config& c) { return c.resolution == 32u; }, "33.5"},
    {"curl_step", "0.05", [](const Config& c) { return c.curlStep == 0.05f; }, "0"},
    {"exact_check", "off", [](const Config& c) { return !c.exactCheck; }, "maybe"},
    {"sdf_far_band", "3", [](const Config& c) { return c.sdfFarBand == 3.0f; }, "-1"},
    {"synthesis", "off", [](const Config& c) { return !c.synthesis; }, "perhaps"},
    {"gpu", "off", [](const Config& c) { return c.gpu == Config::Gpu::off; }, "sometimes"},
    {"extra_queue", "off", [](const Config& c) { return !c.extraQueue; }, "2"},
    {"test_gpu_fault", "lost_at_poll",
     [](const Config& c) { return c.testGpuFault == "lost_at_poll"; }, "crash"},
#if SDFG_LAYER_TEST_FAULTS  // the layer's test build alone (test_fault.h)
    {"test_layer_fault", "after_create_session",
     [](const Config& c) { return c.testLayerFault == "after_create_session"; }, "after_lunch"},
#endif
    {"clear_hand", "off", [](const Config& c) { return !c.clearHand; }, "x"},
    {"clear_bound", "0.05", [](const Config& c) { return c.clearBound == 0.05f; }, "0.3"},
    {"approach", "on", [](const Config& c) { return c.approach; }, "x"},
    {"approach_range", "0.05", [](const Config& c) { return c.approachRange == 0.05f; }, "0"},
    {"approach_max_angle", "45", [](const Config& c) { return c.approachMaxAngle == 45.0f; },
     "200"},
    {"offset_blend_time", "0.5", [](const Config& c) { return c.offsetBlendTime == 0.5f; }, "3"},
    {"build_time_limit_ms", "250", [](const Config& c) { return c.buildTimeLimitMs == 250u; }, "0"},
    {"depth_scene", "off", [](const Config& c) { return c.depthScene == Config::DepthScene::off; },
     "sometimes"},
};

}  // namespace

TEST_CASE("Every key takes a good value into its field and refuses a bad one, changing nothing",
          "[layer][config]") {
  for (const KeyCase& k : kKeys) {
    CAPTURE(k.key, k.good, k.bad);
    const Config defaults;
    Config c;
    CHECK_FALSE(k.took(c));  // the good value is not the default: taking it shows
    REQUIRE(applyConfigValue(c, k.key, k.good));
    CHECK(k.took(c));
    const Config taken = c;
    CHECK_FALSE(applyConfigValue(c, k.key, k.bad));
    CHECK(sameConfig(c, taken));
    // And the bad value alone, from the defaults, changes nothing either.
    Config fresh;
    CHECK_FALSE(applyConfigValue(fresh, k.key, k.bad));
    CHECK(sameConfig(fresh, defaults));
  }
}

TEST_CASE("Every key is read from its SDFG_AUTOGRASP_ environment variable", "[layer][config]") {
  // No config file: XDG_CONFIG_HOME points where there is none.
  setenv("XDG_CONFIG_HOME", "/nonexistent-sdfg-config", 1);
  for (const KeyCase& k : kKeys) {
    std::string name = "SDFG_AUTOGRASP_";
    for (const char* p = k.key; *p != '\0'; ++p) name += char(std::toupper(*p));
    CAPTURE(name, k.good);
    setenv(name.c_str(), k.good, 1);
    CHECK(k.took(sdfg::layer::loadConfig()));
    unsetenv(name.c_str());
  }
}

TEST_CASE("gpu takes auto, on and off (and booleans), and anything else changes nothing",
          "[layer][config]") {
  Config c;
  CHECK(c.gpu == Config::Gpu::automatic);
  REQUIRE(applyConfigValue(c, "gpu", "off"));
  CHECK(c.gpu == Config::Gpu::off);
  REQUIRE(applyConfigValue(c, "gpu", "true"));
  CHECK(c.gpu == Config::Gpu::on);
  REQUIRE(applyConfigValue(c, "gpu", "auto"));
  CHECK(c.gpu == Config::Gpu::automatic);
  for (const char* bad : {"sometimes", "", "AUTO", "2"}) {
    CAPTURE(bad);
    CHECK_FALSE(applyConfigValue(c, "gpu", bad));
    CHECK(c.gpu == Config::Gpu::automatic);
  }
}

TEST_CASE("exact_check and sdf_far_band are parsed and range-checked", "[layer][config]") {
  Config c;
  CHECK(c.exactCheck);
  CHECK(c.sdfFarBand == 2.0f);
  REQUIRE(applyConfigValue(c, "exact_check", "off"));
  CHECK_FALSE(c.exactCheck);
  CHECK_FALSE(applyConfigValue(c, "exact_check", "maybe"));
  CHECK_FALSE(c.exactCheck);
  REQUIRE(applyConfigValue(c, "sdf_far_band", "0"));
  CHECK(c.sdfFarBand == 0.0f);
  REQUIRE(applyConfigValue(c, "sdf_far_band", "3.5"));
  CHECK(c.sdfFarBand == 3.5f);
  for (const char* bad : {"-1", "nan", "inf", "65", "two", ""}) {
    CAPTURE(bad);
    CHECK_FALSE(applyConfigValue(c, "sdf_far_band", bad));
    CHECK(c.sdfFarBand == 3.5f);
  }
  CHECK_FALSE(applyConfigValue(c, "no_such_key", "1"));
}

TEST_CASE("test_layer_fault is a key of the layer's test build alone", "[layer][config]") {
  // From a config file, from the environment, and applied directly.
  namespace fs = std::filesystem;
  const fs::path home = fs::temp_directory_path() / ("sdfg-config-" + std::to_string(getpid()));
  fs::create_directories(home / "sdfg-autograsp");
  std::ofstream(home / "sdfg-autograsp" / "config") << "test_layer_fault = after_create_space\n";
  setenv("XDG_CONFIG_HOME", home.c_str(), 1);
  const Config fromFile = sdfg::layer::loadConfig();
  fs::remove_all(home);
  setenv("XDG_CONFIG_HOME", "/nonexistent-sdfg-config", 1);
  setenv("SDFG_AUTOGRASP_TEST_LAYER_FAULT", "after_create_instance", 1);
  const Config fromEnvironment = sdfg::layer::loadConfig();
  unsetenv("SDFG_AUTOGRASP_TEST_LAYER_FAULT");
  Config c;
  const bool took = applyConfigValue(c, "test_layer_fault", "after_create_session");
#if SDFG_LAYER_TEST_FAULTS
  CHECK(fromFile.testLayerFault == "after_create_space");
  CHECK(fromEnvironment.testLayerFault == "after_create_instance");
  CHECK(took);
  CHECK_THROWS(sdfg::layer::throwIfTestFault(c, "after_create_session"));
  CHECK_NOTHROW(sdfg::layer::throwIfTestFault(c, "after_create_instance"));
#else
  // Unknown: the file's line is ignored with the usual warning, the variable is not read.
  CHECK(fromFile.testLayerFault == "none");
  CHECK(fromEnvironment.testLayerFault == "none");
  CHECK_FALSE(took);
  CHECK(c.testLayerFault == "none");
  // Nor does anything throw, whatever the field holds.
  c.testLayerFault = "after_create_session";
  CHECK_NOTHROW(sdfg::layer::throwIfTestFault(c, "after_create_session"));
#endif
}
