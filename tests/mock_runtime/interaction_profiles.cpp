// Interaction profiles the runtime accepts bindings for: every profile of core OpenXR 1.0
// (spec 6.4), with the input and output paths each lists per top-level user path, and how a
// bound source reads the script. Only profiles with hand paths can be the simulated
// controllers; Vive Pro (/user/head) and Xbox (/user/gamepad) are binding targets only, so an
// app may suggest for them as it would on a runtime that lacks those devices.
#include <algorithm>
#include <cstring>
#include <string_view>

#include "entry_points.h"

namespace sdfg::mock {
namespace {

// Paths one or more top-level user paths share, relative to "<user path>/".
struct PathGroup {
  std::vector<const char*> users;
  std::vector<const char*> paths;
};

struct Profile {
  const char* path;
  const char* localizedName;
  std::vector<PathGroup> groups;
};

constexpr const char* kLeftHand = "/user/hand/left";
constexpr const char* kRightHand = "/user/hand/right";

const std::vector<Profile>& profiles() {
  static const std::vector<Profile> list = {
      {"/interaction_profiles/khr/simple_controller",
       "Simple Controller",
       {{{kLeftHand, kRightHand},
         {"input/select/click", "input/menu/click", "input/grip/pose", "input/aim/pose",
          "output/haptic"}}}},
      {"/interaction_profiles/google/daydream_controller",
       "Google Daydream Controller",
       {{{kLeftHand, kRightHand},
         {"input/select/click", "input/trackpad/x", "input/trackpad/y", "input/trackpad/click",
          "input/trackpad/touch", "input/grip/pose", "input/aim/pose"}}}},
      {"/interaction_profiles/htc/vive_controller",
       "HTC Vive Controller",
       {{{kLeftHand, kRightHand},
         {"input/system/click", "input/squeeze/click", "input/menu/click", "input/trigger/click",
          "input/trigger/value", "input/trackpad/x", "input/trackpad/y", "input/trackpad/click",
          "input/trackpad/touch", "input/grip/pose", "input/aim/pose", "output/haptic"}}}},
      {"/interaction_profiles/htc/vive_pro",
       "HTC Vive Pro",
       {{{"/user/head"},
         {"input/system/click", "input/volume_up/click", "input/volume_down/click",
          "input/mute_mic/click"}}}},
      {"/interaction_profiles/microsoft/motion_controller",
       "Microsoft Motion Controller",
       {{{kLeftHand, kRightHand},
         {"input/menu/click", "input/squeeze/click", "input/trigger/value", "input/thumbstick/x",
          "input/thumbstick/y", "input/thumbstick/click", "input/trackpad/x", "input/trackpad/y",
          "input/trackpad/click", "input/trackpad/touch", "input/grip/pose", "input/aim/pose",
          "output/haptic"}}}},
      {"/interaction_profiles/microsoft/xbox_controller",
       "Microsoft Xbox Controller",
       {{{"/user/gamepad"},
         {"input/menu/click",
          "input/view/click",
          "input/a/click",
          "input/b/click",
          "input/x/click",
          "input/y/click",
          "input/dpad_down/click",
          "input/dpad_right/click",
          "input/dpad_up/click",
          "input/dpad_left/click",
          "input/shoulder_left/click",
          "input/shoulder_right/click",
          "input/thumbstick_left/click",
          "input/thumbstick_right/click",
          "input/trigger_left/value",
          "input/trigger_right/value",
          "input/thumbstick_left/x",
          "input/thumbstick_left/y",
          "input/thumbstick_right/x",
          "input/thumbstick_right/y",
          "output/haptic_left",
          "output/haptic_right",
          "output/haptic_left_trigger",
          "output/haptic_right_trigger"}}}},
      {"/interaction_profiles/oculus/go_controller",
       "Oculus Go Controller",
       {{{kLeftHand, kRightHand},
         {"input/system/click", "input/trigger/click", "input/back/click", "input/trackpad/x",
          "input/trackpad/y", "input/trackpad/click", "input/trackpad/touch", "input/grip/pose",
          "input/aim/pose"}}}},
      {"/interaction_profiles/oculus/touch_controller",
       "Oculus Touch Controller",
       {{{kLeftHand, kRightHand},
         {"input/squeeze/value", "input/trigger/value", "input/trigger/touch", "input/thumbstick/x",
          "input/thumbstick/y", "input/thumbstick/click", "input/thumbstick/touch",
          "input/thumbrest/touch", "input/grip/pose", "input/aim/pose", "output/haptic"}},
        {{kLeftHand},
         {"input/x/click", "input/x/touch", "input/y/click", "input/y/touch", "input/menu/click"}},
        {{kRightHand},
         {"input/a/click", "input/a/touch", "input/b/click", "input/b/touch",
          "input/system/click"}}}},
      {"/interaction_profiles/valve/index_controller",
       "Valve Index Controller",
       {{{kLeftHand, kRightHand},
         {"input/system/click",   "input/system/touch",     "input/a/click",
          "input/a/touch",        "input/b/click",          "input/b/touch",
          "input/squeeze/value",  "input/squeeze/force",    "input/trigger/click",
          "input/trigger/value",  "input/trigger/touch",    "input/thumbstick/x",
          "input/thumbstick/y",   "input/thumbstick/click", "input/thumbstick/touch",
          "input/trackpad/x",     "input/trackpad/y",       "input/trackpad/force",
          "input/trackpad/touch", "input/grip/pose",        "input/aim/pose",
          "output/haptic"}}}},
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

bool isSimulatedProfile(const std::string& profilePath) {
  const Profile* p = findProfile(profilePath);
  if (p == nullptr) return false;
  return std::any_of(p->groups.begin(), p->groups.end(), [](const PathGroup& g) {
    return std::find(g.users.begin(), g.users.end(), std::string_view(kLeftHand)) != g.users.end();
  });
}

std::string profileLocalizedName(const std::string& profilePath) {
  const Profile* p = findProfile(profilePath);
  return p == nullptr ? std::string() : p->localizedName;
}

bool resolveBinding(const std::string& profilePath, const std::string& bindingPath, Binding& out) {
  const Profile* profile = findProfile(profilePath);
  if (profile == nullptr) return false;
  // The paths of the binding's top-level user path, over all groups that list it.
  std::string rest;
  std::string_view user;
  std::vector<std::string_view> paths;
  for (const PathGroup& g : profile->groups) {
    for (const char* u : g.users) {
      const size_t n = std::strlen(u);
      if (bindingPath.size() <= n + 1 || bindingPath.compare(0, n, u) != 0 || bindingPath[n] != '/')
        continue;
      rest = bindingPath.substr(n + 1);
      user = u;
      paths.insert(paths.end(), g.paths.begin(), g.paths.end());
    }
  }
  if (rest.empty()) return false;

  // Head and gamepad bindings are accepted but never read: their profiles cannot be the
  // simulated one (isSimulatedProfile), so they never become the session's current profile.
  out.hand = user == kLeftHand ? kLeft : user == kRightHand ? kRight : kHead;
  if (std::find(paths.begin(), paths.end(), rest) != paths.end()) {
    if (rest.compare(0, 7, "output/") == 0) {
      out.identifier = rest.substr(7);  // "haptic", or the Xbox's "haptic_left"...
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
  if (rest.compare(0, 6, "input/") == 0 && rest.size() > 6 &&
      rest.find('/', 6) == std::string::npos) {
    const std::string prefix = rest + "/";
    for (std::string_view p : paths) {
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
