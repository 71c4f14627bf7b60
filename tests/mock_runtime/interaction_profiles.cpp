// Interaction profiles the runtime accepts bindings for (the five hello_xr suggests), their
// input and output paths per hand (spec 6.4), and how a bound source reads the script.
#include <algorithm>
#include <cstring>

#include "entry_points.h"

namespace sdfg::mock {
namespace {

struct Profile {
  const char* path;
  const char* localizedName;
  std::vector<std::string> both, leftOnly, rightOnly;  // relative to /user/hand/<hand>/
};

const std::vector<Profile>& profiles() {
  static const std::vector<Profile> list = {
      {"/interaction_profiles/khr/simple_controller",
       "Simple Controller",
       {"input/select/click", "input/menu/click", "input/grip/pose", "input/aim/pose",
        "output/haptic"},
       {},
       {}},
      {"/interaction_profiles/oculus/touch_controller",
       "Oculus Touch Controller",
       {"input/squeeze/value", "input/trigger/value", "input/trigger/touch", "input/thumbstick/x",
        "input/thumbstick/y", "input/thumbstick/click", "input/thumbstick/touch",
        "input/thumbrest/touch", "input/grip/pose", "input/aim/pose", "output/haptic"},
       {"input/x/click", "input/x/touch", "input/y/click", "input/y/touch", "input/menu/click"},
       {"input/a/click", "input/a/touch", "input/b/click", "input/b/touch", "input/system/click"}},
      {"/interaction_profiles/valve/index_controller",
       "Valve Index Controller",
       {"input/system/click",   "input/system/touch",     "input/a/click",
        "input/a/touch",        "input/b/click",          "input/b/touch",
        "input/squeeze/value",  "input/squeeze/force",    "input/trigger/click",
        "input/trigger/value",  "input/trigger/touch",    "input/thumbstick/x",
        "input/thumbstick/y",   "input/thumbstick/click", "input/thumbstick/touch",
        "input/trackpad/x",     "input/trackpad/y",       "input/trackpad/force",
        "input/trackpad/touch", "input/grip/pose",        "input/aim/pose",
        "output/haptic"},
       {},
       {}},
      {"/interaction_profiles/htc/vive_controller",
       "HTC Vive Controller",
       {"input/system/click", "input/squeeze/click", "input/menu/click", "input/trigger/click",
        "input/trigger/value", "input/trackpad/x", "input/trackpad/y", "input/trackpad/click",
        "input/trackpad/touch", "input/grip/pose", "input/aim/pose", "output/haptic"},
       {},
       {}},
      {"/interaction_profiles/microsoft/motion_controller",
       "Microsoft Motion Controller",
       {"input/menu/click", "input/squeeze/click", "input/trigger/value", "input/thumbstick/x",
        "input/thumbstick/y", "input/thumbstick/click", "input/trackpad/x", "input/trackpad/y",
        "input/trackpad/click", "input/trackpad/touch", "input/grip/pose", "input/aim/pose",
        "output/haptic"},
       {},
       {}},
  };
  return list;
}

const Profile* findProfile(const std::string& path) {
  for (const Profile& p : profiles()) {
    if (path == p.path) return &p;
  }
  return nullptr;
}

// Scalar from the script, with the fallbacks a real device has: a click reads as value > 0.5
// when only the value is scripted, a force reads the value, and a value reads the click.
float readComponent(const Session& session, Target hand, const std::string& identifier,
                    const std::string& component) {
  const Script& script = session.instance->script;
  const uint64_t f = session.frame();
  if (auto v = script.scalar(hand, identifier + "/" + component, f)) return *v;
  if (component == "click") {
    if (auto v = script.scalar(hand, identifier + "/value", f)) return *v > 0.5f ? 1.0f : 0.0f;
  }
  if (component == "force") {  // a squeeze force reads the squeeze value when only that is scripted
    if (auto v = script.scalar(hand, identifier + "/value", f)) return *v;
  }
  if (component == "value") {
    if (auto v = script.scalar(hand, identifier + "/click", f)) return *v;
  }
  return 0.0f;
}

}  // namespace

bool isKnownProfile(const std::string& profilePath) {
  return findProfile(profilePath) != nullptr;
}

std::string profileLocalizedName(const std::string& profilePath) {
  const Profile* p = findProfile(profilePath);
  return p == nullptr ? std::string() : p->localizedName;
}

bool resolveBinding(const std::string& profilePath, const std::string& bindingPath, Binding& out) {
  const Profile* profile = findProfile(profilePath);
  if (profile == nullptr) return false;
  std::string rest;
  Target hand{};
  for (const auto& [prefix, h] : {std::pair<std::string, Target>{"/user/hand/left/", kLeft},
                                  std::pair<std::string, Target>{"/user/hand/right/", kRight}}) {
    if (bindingPath.compare(0, prefix.size(), prefix) == 0) {
      rest = bindingPath.substr(prefix.size());
      hand = h;
    }
  }
  if (rest.empty()) return false;
  std::vector<std::string> paths = profile->both;
  const auto& own = hand == kLeft ? profile->leftOnly : profile->rightOnly;
  paths.insert(paths.end(), own.begin(), own.end());

  out.hand = hand;
  if (std::find(paths.begin(), paths.end(), rest) != paths.end()) {
    if (rest == "output/haptic") {
      out.identifier = "haptic";
      out.component.clear();
      return true;
    }
    // "input/<identifier>/<component>"
    const size_t slash = rest.find('/', 6);
    out.identifier = rest.substr(6, slash - 6);
    out.component = rest.substr(slash + 1);
    return true;
  }
  // A parent path ("input/squeeze", "input/thumbstick") binds whichever component fits the
  // action type (spec 6.3 "Input path descriptions").
  if (rest.compare(0, 6, "input/") == 0 && rest.find('/', 6) == std::string::npos) {
    const std::string prefix = rest + "/";
    for (const std::string& p : paths) {
      if (p.compare(0, prefix.size(), prefix) == 0) {
        out.identifier = rest.substr(6);
        out.component.clear();
        return true;
      }
    }
  }
  return false;
}

float readScalar(const Session& session, const Binding& b, XrActionType type) {
  if (!b.component.empty()) return readComponent(session, b.hand, b.identifier, b.component);
  // Parent path: booleans prefer click, floats prefer value.
  const Script& script = session.instance->script;
  const uint64_t f = session.frame();
  const bool wantsClick = type == XR_ACTION_TYPE_BOOLEAN_INPUT;
  const char* first = wantsClick ? "click" : "value";
  const char* second = wantsClick ? "value" : "click";
  if (script.scalar(b.hand, b.identifier + "/" + first, f))
    return readComponent(session, b.hand, b.identifier, first);
  return readComponent(session, b.hand, b.identifier, second);
}

}  // namespace sdfg::mock
