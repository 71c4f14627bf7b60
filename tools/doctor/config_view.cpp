#include "config_view.h"

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>

#include "log.h"
#include "platform.h"
#include "system.h"

namespace sdfg::doctor {
namespace {

using layer::Config;

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

std::string formatNumber(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

Setting number(const char* key, double v) {
  Setting s;
  s.key = key;
  s.kind = Setting::Kind::number;
  s.text = formatNumber(v);
  // From the text, so a float setting such as 0.7 reads 0.7 in JSON, not 0.699999988.
  s.number = std::strtod(s.text.c_str(), nullptr);
  return s;
}

Setting boolean(const char* key, bool v) {
  Setting s;
  s.key = key;
  s.kind = Setting::Kind::boolean;
  s.boolean = v;
  s.text = v ? "on" : "off";
  return s;
}

Setting text(const char* key, const std::string& v) {
  Setting s;
  s.key = key;
  s.text = v;
  return s;
}

const char* logLevelName(layer::LogLevel level) {
  switch (level) {
    case layer::LogLevel::none:
      return "none";
    case layer::LogLevel::error:
      return "error";
    case layer::LogLevel::warn:
      return "warn";
    case layer::LogLevel::info:
      return "info";
    case layer::LogLevel::debug:
      return "debug";
  }
  return "?";
}

const char* gpuName(Config::Gpu gpu) {
  switch (gpu) {
    case Config::Gpu::automatic:
      return "auto";
    case Config::Gpu::on:
      return "on";
    case Config::Gpu::off:
      return "off";
  }
  return "?";
}

// The settings docs/layer.md lists, in its order, as the file would write them.
std::vector<Setting> settingsOf(const Config& c) {
  return {text("log_level", logLevelName(c.logLevel)),
          text("solver", c.solver),
          number("grab_threshold", c.grabThreshold),
          number("release_ratio", c.releaseRatio),
          number("resolution", c.resolution),
          number("curl_step", c.curlStep),
          number("sdf_far_band", c.sdfFarBand),
          boolean("exact_check", c.exactCheck),
          number("build_time_limit_ms", c.buildTimeLimitMs),
          boolean("synthesis", c.synthesis),
          boolean("attach_alone", c.attachAlone),
          text("gpu", gpuName(c.gpu)),
          boolean("extra_queue", c.extraQueue),
          boolean("clear_hand", c.clearHand),
          number("clear_bound", c.clearBound),
          boolean("approach", c.approach),
          number("approach_range", c.approachRange),
          number("approach_max_angle", c.approachMaxAngle),
          boolean("outer_hand", c.outerHand),
          number("outer_release_distance", c.outerReleaseDistance),
          number("outer_blend_time", c.outerBlendTime),
          number("offset_blend_time", c.offsetBlendTime),
          text("test_gpu_fault", c.testGpuFault)};
}

// Walks the configuration file line by line with the rules of layer/config.cpp's loadConfig
// ('#' comments, "key = value", blanks trimmed), calling `entry` for each setting.
void forEachFileEntry(
    const std::string& path,
    const std::function<void(int line, const std::string& key, const std::string& value)>& entry) {
  std::ifstream file(path);
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
    entry(number, key, value);
  }
}

}  // namespace

Report::Config describeConfig(Config& inForce) {
  Report::Config out;
  const std::string dir = layer::platform::userConfigDir();
  if (!dir.empty()) out.file = dir + "/sdfg-autograsp/config";
  // The layer's own warnings about ignored entries would go to stderr; the report lists them.
  layer::setLogLevel(layer::LogLevel::none);
  inForce = layer::loadConfig();
  out.fileExists = !inForce.configPath.empty();

  std::vector<std::string> fromFile, fromEnvironment;
  if (out.fileExists) {
    forEachFileEntry(
        inForce.configPath, [&](int line, const std::string& key, const std::string& value) {
          Config scratch;
          if (layer::applyConfigValue(scratch, key, value))
            fromFile.push_back(key);
          else
            out.ignored.push_back({inForce.configPath + ":" + std::to_string(line), key, value});
        });
  }
  const std::string prefix = "SDFG_AUTOGRASP_";
  for (const std::string& name : environmentNamesWithPrefix(prefix)) {
    std::string key = name.substr(prefix.size());
    for (char& ch : key) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    const std::string value = environmentValue(name).value_or("");
    Config scratch;
    if (layer::applyConfigValue(scratch, key, value))
      fromEnvironment.push_back(key);
    else
      out.ignored.push_back({name, key, value});
  }
  const auto contains = [](const std::vector<std::string>& keys, const std::string& key) {
    for (const std::string& k : keys)
      if (k == key) return true;
    return false;
  };
  out.values = settingsOf(inForce);
  for (Setting& s : out.values) {
    s.origin = contains(fromEnvironment, s.key) ? "environment"
               : contains(fromFile, s.key)      ? "file"
                                                : "default";
  }
  return out;
}

std::string originOf(const Report::Config& config, const std::string& key) {
  for (const Setting& s : config.values)
    if (s.key == key) return s.origin;
  return "default";
}

}  // namespace sdfg::doctor
