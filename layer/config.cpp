#include "config.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>

#include "platform.h"
#include "test_fault.h"

namespace sdfg::layer {
namespace {

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

bool parseFloat(const std::string& text, float lo, float hi, float& out) {
  char* end = nullptr;
  const float v = std::strtof(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !std::isfinite(v) || v < lo || v > hi) return false;
  out = v;
  return true;
}

bool parseBool(const std::string& text, bool& out) {
  if (text == "1" || text == "true" || text == "on" || text == "yes") return out = true, true;
  if (text == "0" || text == "false" || text == "off" || text == "no") return out = false, true;
  return false;
}

const char* const kKeys[] = {"log_level",
                             "solver",
                             "grab_threshold",
                             "release_ratio",
                             "resolution",
                             "curl_step",
                             "exact_check",
                             "sdf_far_band",
                             "synthesis",
                             "attach_alone",
                             "gpu",
                             "extra_queue",
                             "test_gpu_fault",
                             "clear_hand",
                             "clear_bound",
                             "approach",
                             "approach_range",
                             "approach_max_angle",
                             "offset_blend_time",
                             "build_time_limit_ms",
                             "outer_hand",
                             "outer_release_distance",
                             "outer_blend_time",
                             "depth_scene"};

}  // namespace

bool applyConfigValue(Config& config, const std::string& key, const std::string& value) {
  Config c = config;
  bool ok = true;
  if (key == "log_level") {
    c.logLevel = parseLogLevel(value.c_str(), LogLevel(-1));
    ok = c.logLevel != LogLevel(-1);
  } else if (key == "solver") {
    ok = !value.empty() && value.size() < 64;
    c.solver = value;
  } else if (key == "grab_threshold") {
    ok = parseFloat(value, 0.01f, 1.0f, c.grabThreshold);
  } else if (key == "release_ratio") {
    ok = parseFloat(value, 0.0f, 1.0f, c.releaseRatio);
  } else if (key == "resolution") {
    float r = 0;
    ok = parseFloat(value, 2, 128, r) && r == std::floor(r);
    c.resolution = unsigned(r);
  } else if (key == "curl_step") {
    ok = parseFloat(value, 1e-5f, 1.0f, c.curlStep);
  } else if (key == "sdf_far_band") {
    ok = parseFloat(value, 0.0f, 64.0f, c.sdfFarBand);
  } else if (key == "build_time_limit_ms") {
    float ms = 0;
    ok = parseFloat(value, 1, 600000, ms) && ms == std::floor(ms);
    c.buildTimeLimitMs = unsigned(ms);
  } else if (key == "exact_check") {
    ok = parseBool(value, c.exactCheck);
  } else if (key == "synthesis") {
    ok = parseBool(value, c.synthesis);
  } else if (key == "attach_alone") {
    ok = parseBool(value, c.attachAlone);
  } else if (key == "gpu") {
    bool flag = false;
    ok = false;
    if (value == "auto") {
      c.gpu = Config::Gpu::automatic;
      ok = true;
    } else if (parseBool(value, flag)) {
      c.gpu = flag ? Config::Gpu::on : Config::Gpu::off;
      ok = true;
    }
  } else if (key == "depth_scene") {
    bool flag = false;
    ok = false;
    if (value == "auto") {
      c.depthScene = Config::DepthScene::automatic;
      ok = true;
    } else if (parseBool(value, flag)) {
      c.depthScene = flag ? Config::DepthScene::on : Config::DepthScene::off;
      ok = true;
    }
  } else if (key == "extra_queue") {
    ok = parseBool(value, c.extraQueue);
  } else if (key == "clear_hand") {
    ok = parseBool(value, c.clearHand);
  } else if (key == "clear_bound") {
    ok = parseFloat(value, 0.0f, 0.2f, c.clearBound);
  } else if (key == "approach") {
    ok = parseBool(value, c.approach);
  } else if (key == "approach_range") {
    ok = parseFloat(value, 0.001f, 0.2f, c.approachRange);
  } else if (key == "approach_max_angle") {
    ok = parseFloat(value, 0.1f, 180.0f, c.approachMaxAngle);
  } else if (key == "offset_blend_time") {
    ok = parseFloat(value, 0.0f, 2.0f, c.offsetBlendTime);
  } else if (key == "outer_hand") {
    ok = parseBool(value, c.outerHand);
  } else if (key == "outer_release_distance") {
    ok = parseFloat(value, 0.01f, 1.0f, c.outerReleaseDistance);
  } else if (key == "outer_blend_time") {
    ok = parseFloat(value, 0.0f, 2.0f, c.outerBlendTime);
  } else if (key == "test_gpu_fault") {
    ok = value == "none" || value == "lost_at_submit" || value == "lost_at_poll" ||
         value == "never_ready" || value == "stuck_reads_once";
    c.testGpuFault = value;
  } else if (!applyTestFaultKey(c, key, value, ok)) {
    ok = false;  // unknown; test_layer_fault too, outside the layer's test build (test_fault.h)
  }
  if (ok) config = c;
  return ok;
}

Config loadConfig() {
  Config config;
  const std::string dir = platform::userConfigDir();
  if (!dir.empty()) {
    const std::string path = dir + "/sdfg-autograsp/config";
    std::ifstream file(path);
    if (file) {
      config.configPath = path;
      std::string line;
      int number = 0;
      while (std::getline(file, line)) {
        ++number;
        if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
        line = trim(line);
        if (line.empty()) continue;
        const size_t eq = line.find('=');
        const std::string key = eq == std::string::npos ? line : trim(line.substr(0, eq));
        const std::string value = eq == std::string::npos ? "" : trim(line.substr(eq + 1));
        if (!applyConfigValue(config, key, value))
          SDFG_LOG_WARN("config", "%s:%d: ignored '%s = %s' (unknown key or bad value)",
                        path.c_str(), number, key.c_str(), value.c_str());
      }
    }
  }
  const auto fromEnvironment = [&config](const char* key) {
    std::string name = "SDFG_AUTOGRASP_";
    for (const char* p = key; *p != '\0'; ++p)
      name += char(std::toupper(static_cast<unsigned char>(*p)));
    if (const char* value = std::getenv(name.c_str()); value != nullptr) {
      if (!applyConfigValue(config, key, value))
        SDFG_LOG_WARN("config", "ignored %s=%s (bad value)", name.c_str(), value);
    }
  };
  for (const char* key : kKeys) fromEnvironment(key);
  if (const char* key = testFaultKey(); key != nullptr) fromEnvironment(key);
  return config;
}

}  // namespace sdfg::layer
