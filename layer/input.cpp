// The layer's own input: an action set with a squeeze value and a grip pose per hand, merged
// into the app's suggested bindings, attached with the app's sets and synced with every app sync
// (notes/openxr-layer.md section 12). Priority 0 and bindings added only to profiles the app
// suggests, so the app's actions report exactly what they would without the layer. The layer
// never attaches its set alone unless configured to (attach_alone): an app may attach once per
// session, at any time, and must not be refused because of the layer.
#include <array>
#include <cstring>
#include <utility>
#include <vector>

#include "intercepts.h"
#include "log.h"
#include "state.h"

namespace sdfg::layer {
namespace {

struct ProfileInputs {
  const char* profile;
  const char* squeeze;  // under /user/hand/<hand>/
};

// Profiles the layer binds; a float action reads a click as 0 or 1.
constexpr ProfileInputs kProfiles[] = {
    {"/interaction_profiles/oculus/touch_controller", "input/squeeze/value"},
    {"/interaction_profiles/valve/index_controller", "input/squeeze/value"},
    {"/interaction_profiles/htc/vive_controller", "input/squeeze/click"},
    {"/interaction_profiles/microsoft/motion_controller", "input/squeeze/click"},
    {"/interaction_profiles/khr/simple_controller", "input/select/click"},
};

constexpr const char* kHandNames[2] = {"left", "right"};

// Paths of kProfiles, resolved once per instance.
std::vector<ProfilePaths> resolveProfiles(InstanceState& instance) {
  std::vector<ProfilePaths> out;
  auto path = [&](const std::string& s) {
    XrPath p = XR_NULL_PATH;
    return instance.next.xrStringToPath(instance.handle, s.c_str(), &p) == XR_SUCCESS
               ? p
               : XR_NULL_PATH;
  };
  for (const ProfileInputs& in : kProfiles) {
    ProfilePaths pp;
    pp.profile = path(in.profile);
    for (int h = 0; h < 2; ++h) {
      const std::string hand = std::string("/user/hand/") + kHandNames[h] + "/";
      pp.squeeze[h] = path(hand + in.squeeze);
      pp.grip[h] = path(hand + "input/grip/pose");
    }
    out.push_back(pp);
  }
  return out;
}

const ProfilePaths* findProfile(const InstanceState& instance, XrPath profile) {
  for (const ProfilePaths& p : instance.profiles) {
    if (p.profile == profile && profile != XR_NULL_PATH) return &p;
  }
  return nullptr;
}

void appendLayerBindings(const InstanceState& instance, const ProfilePaths& paths,
                         std::vector<XrActionSuggestedBinding>& out) {
  for (int h = 0; h < 2; ++h) {
    out.push_back({instance.squeezeAction, paths.squeeze[h]});
    out.push_back({instance.gripAction, paths.grip[h]});
  }
}

// An app without suggestions gets the layer's alone, on every profile it knows.
void suggestOwnBindingsIfAlone(InstanceState& inst) {
  {
    std::lock_guard lock(inst.inputMutex);
    if (!inst.appSuggestedProfiles.empty()) return;
  }
  for (const ProfilePaths& paths : inst.profiles) {
    if (paths.profile == XR_NULL_PATH) continue;
    std::vector<XrActionSuggestedBinding> own;
    appendLayerBindings(inst, paths, own);
    XrInteractionProfileSuggestedBinding b{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
    b.interactionProfile = paths.profile;
    b.countSuggestedBindings = uint32_t(own.size());
    b.suggestedBindings = own.data();
    (void)inst.next.xrSuggestInteractionProfileBindings(inst.handle, &b);
  }
}

// Makes `make` a layer space of the session unless another thread stored one first (then its own
// is given back). Made on the runtime with no lock held, then stored under it.
template <class Make>
void storeLayerSpace(SessionState& s, XrSpace SessionState::*field, Make make) {
  {
    std::lock_guard lock(s.mutex);
    if (s.*field != XR_NULL_HANDLE) return;
  }
  XrSpace made = make();
  if (made == XR_NULL_HANDLE) return;
  {
    std::lock_guard lock(s.mutex);
    if (s.*field == XR_NULL_HANDLE) {
      s.*field = made;
      return;
    }
  }
  s.instance->next.xrDestroySpace(made);
}

// The grip spaces of the layer's pose action, once its set is attached.
void createGripSpaces(SessionState& s) {
  auto& next = s.instance->next;
  std::array<XrSpace, 2> grips{};
  for (size_t h = 0; h < 2; ++h) {
    XrActionSpaceCreateInfo spaceInfo{XR_TYPE_ACTION_SPACE_CREATE_INFO};
    spaceInfo.action = s.instance->gripAction;
    spaceInfo.subactionPath = s.instance->handPaths[h];
    spaceInfo.poseInActionSpace.orientation.w = 1.0f;
    if (next.xrCreateActionSpace(s.handle, &spaceInfo, &grips[h]) != XR_SUCCESS)
      grips[h] = XR_NULL_HANDLE;
  }
  bool stored = false;
  {
    std::lock_guard lock(s.mutex);
    if (s.gripSpaces == std::array<XrSpace, 2>{}) {
      s.gripSpaces = grips;
      stored = true;
    }
  }
  if (stored) return;
  for (XrSpace space : grips)
    if (space != XR_NULL_HANDLE) next.xrDestroySpace(space);
}

// The LOCAL space the grab update works in. A reference space needs no action set, so every
// session gets one at its first frame: an app that tracks hands through the runtime and has no
// actions grasps too, and one that attaches late has it ready.
void ensureLocalSpace(SessionState& s) {
  storeLayerSpace(s, &SessionState::localSpace, [&] {
    XrReferenceSpaceCreateInfo local{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
    local.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
    local.poseInReferenceSpace.orientation.w = 1.0f;
    XrSpace space = XR_NULL_HANDLE;
    if (s.instance->next.xrCreateReferenceSpace(s.handle, &local, &space) != XR_SUCCESS)
      return XrSpace(XR_NULL_HANDLE);
    return space;
  });
}

// Once the layer's set is attached (with the app's, or alone).
void createLayerSpaces(SessionState& s) {
  ensureLocalSpace(s);
  createGripSpaces(s);
}

// An app that made synthesized trackers and has attached no action sets yet: the layer waits for
// its attach (its set goes with the app's) unless attach_alone is set. Says so once.
void attachAloneIfAllowed(SessionState& s) {
  constexpr const char* cmd = "xrWaitFrame";
  InstanceState& inst = *s.instance;
  bool sayWaiting = false;
  {
    // Claimed under the lock, attached without it.
    std::lock_guard lock(s.mutex);
    if (s.attached || s.appAttached || s.selfAttachFailed || s.selfAttaching ||
        s.synthesizedTrackers == 0 || inst.actionSet == XR_NULL_HANDLE)
      return;
    if (inst.config.attachAlone)
      s.selfAttaching = true;
    else
      sayWaiting = !std::exchange(s.waitingForAttachLogged, true);
  }
  if (!inst.config.attachAlone) {
    if (sayWaiting)
      SDFG_LOG_INFO(cmd,
                    "the app has attached no action sets yet: hands synthesized from the "
                    "controllers stay inactive until it does (attach_alone = true attaches the "
                    "layer's set alone, after which the app can attach none)");
    return;
  }
  suggestOwnBindingsIfAlone(inst);
  XrSessionActionSetsAttachInfo info{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  info.countActionSets = 1;
  info.actionSets = &inst.actionSet;
  const XrResult r = inst.next.xrAttachSessionActionSets(s.handle, &info);
  if (XR_SUCCEEDED(r)) createLayerSpaces(s);
  {
    std::lock_guard lock(s.mutex);
    s.selfAttaching = false;
    // A failure is remembered: never tried again on this session.
    s.selfAttachFailed = XR_FAILED(r);
    s.attached = s.attached || XR_SUCCEEDED(r);
    s.selfAttached = XR_SUCCEEDED(r);
  }
  if (XR_FAILED(r))
    SDFG_LOG_WARN(cmd,
                  "could not attach the layer's action set (%d); synthesized hands stay "
                  "inactive in this session",
                  int(r));
  else
    SDFG_LOG_INFO(cmd,
                  "attach_alone: the app attached no action sets, so the layer attached its own "
                  "for synthesized hands to follow the controllers (a later app attach is "
                  "refused)");
}

}  // namespace

void updateInputAtFrame(SessionState& s) {
  ensureLocalSpace(s);
  attachAloneIfAllowed(s);
  bool attached = false;
  bool selfAttached = false;
  {
    std::lock_guard lock(s.mutex);
    attached = s.attached;
    selfAttached = s.selfAttached;
  }
  if (selfAttached) {
    InstanceState& inst = *s.instance;
    XrActiveActionSet active{inst.actionSet, XR_NULL_PATH};
    XrActionsSyncInfo sync{XR_TYPE_ACTIONS_SYNC_INFO};
    sync.countActiveActionSets = 1;
    sync.activeActionSets = &active;
    const XrResult r = inst.next.xrSyncActions(s.handle, &sync);
    if (r == XR_SUCCESS || r == XR_SESSION_NOT_FOCUSED) syncGrasps(s, "xrWaitFrame");
  } else if (!attached) {
    // The layer's set is not attached (the app has attached none yet, or the runtime refused the
    // layer's): the update runs once a frame on what the runtime gives without actions, the
    // hands it tracks, so the outer hand and grabs by closing the hand work. Without them there
    // is no input at all, and the frame is left alone (a frame-timing app pays nothing).
    const InstanceState& inst = *s.instance;
    if (inst.downstreamHandTracking && inst.next.xrLocateHandJointsEXT != nullptr &&
        !inst.runtimeSystemLacksHands)
      syncGrasps(s, "xrWaitFrame");
  }
  // Attached with the app's set: the app's xrSyncActions runs the update.
}

void createLayerActions(InstanceState& instance) {
  constexpr const char* cmd = "xrCreateInstance";
  auto& next = instance.next;
  if (next.xrCreateActionSet == nullptr || next.xrCreateAction == nullptr ||
      next.xrStringToPath == nullptr)
    return;
  for (int h = 0; h < 2; ++h) {
    const std::string p = std::string("/user/hand/") + kHandNames[h];
    if (next.xrStringToPath(instance.handle, p.c_str(), &instance.handPaths[h]) != XR_SUCCESS)
      return;
  }
  instance.profiles = resolveProfiles(instance);
  XrActionSetCreateInfo setInfo{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::strcpy(setInfo.actionSetName, "sdfg_autograsp_layer");
  std::strcpy(setInfo.localizedActionSetName, "SDF Autograsp layer");
  setInfo.priority = 0;  // never outranks the app's sets on a shared input
  if (next.xrCreateActionSet(instance.handle, &setInfo, &instance.actionSet) != XR_SUCCESS) {
    SDFG_LOG_WARN(cmd, "could not create the layer's action set; no grab input");
    instance.actionSet = XR_NULL_HANDLE;
    return;
  }
  XrActionCreateInfo info{XR_TYPE_ACTION_CREATE_INFO};
  info.countSubactionPaths = 2;
  info.subactionPaths = instance.handPaths.data();
  info.actionType = XR_ACTION_TYPE_FLOAT_INPUT;
  std::strcpy(info.actionName, "sdfg_autograsp_squeeze");
  std::strcpy(info.localizedActionName, "SDF Autograsp squeeze");
  XrResult r = next.xrCreateAction(instance.actionSet, &info, &instance.squeezeAction);
  info.actionType = XR_ACTION_TYPE_POSE_INPUT;
  std::strcpy(info.actionName, "sdfg_autograsp_grip");
  std::strcpy(info.localizedActionName, "SDF Autograsp grip");
  if (r == XR_SUCCESS) r = next.xrCreateAction(instance.actionSet, &info, &instance.gripAction);
  if (r != XR_SUCCESS) {
    SDFG_LOG_WARN(cmd, "could not create the layer's actions (%d); no grab input", int(r));
    if (next.xrDestroyActionSet != nullptr) next.xrDestroyActionSet(instance.actionSet);
    instance.actionSet = XR_NULL_HANDLE;
  }
}

XrResult XRAPI_CALL SdfgXrSuggestInteractionProfileBindings(
    XrInstance instance, const XrInteractionProfileSuggestedBinding* suggested) {
  constexpr const char* cmd = "xrSuggestInteractionProfileBindings";
  SDFG_ENTRY_BEGIN
  auto state = instances().find(key(instance));
  if (state == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(instance) is not valid");
  auto& next = state->next;
  // A call the runtime must refuse as the app made it (no bindings at all, VUID
  // -XrInteractionProfileSuggestedBinding-countSuggestedBindings-arraylength) goes down untouched:
  // the layer's bindings would make it valid.
  if (state->actionSet == XR_NULL_HANDLE || suggested == nullptr ||
      suggested->type != XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING ||
      suggested->countSuggestedBindings == 0 || suggested->suggestedBindings == nullptr)
    return next.xrSuggestInteractionProfileBindings(instance, suggested);
  const ProfilePaths* paths = findProfile(*state, suggested->interactionProfile);
  if (paths == nullptr) return next.xrSuggestInteractionProfileBindings(instance, suggested);
  // A second suggestion for a profile replaces the first, so the layer's bindings ride along
  // with every one the app makes.
  std::vector<XrActionSuggestedBinding> merged(
      suggested->suggestedBindings,
      suggested->suggestedBindings + suggested->countSuggestedBindings);
  appendLayerBindings(*state, *paths, merged);
  XrInteractionProfileSuggestedBinding copy = *suggested;
  copy.countSuggestedBindings = uint32_t(merged.size());
  copy.suggestedBindings = merged.data();
  XrResult r = next.xrSuggestInteractionProfileBindings(instance, &copy);
  if (XR_FAILED(r)) {
    // Never fail the app's call because of the layer's additions.
    const XrResult own = next.xrSuggestInteractionProfileBindings(instance, suggested);
    if (XR_SUCCEEDED(own))
      SDFG_LOG_WARN(cmd,
                    "the runtime refused the layer's bindings (%d); no grab input on this profile",
                    int(r));
    r = own;
  }
  if (XR_SUCCEEDED(r)) {
    std::lock_guard lock(state->inputMutex);
    state->appSuggestedProfiles.insert(suggested->interactionProfile);
  }
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrAttachSessionActionSets(XrSession session,
                                                  const XrSessionActionSetsAttachInfo* info) {
  constexpr const char* cmd = "xrAttachSessionActionSets";
  SDFG_ENTRY_BEGIN
  auto s = sessions().find(key(session));
  if (s == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(session) is not valid");
  InstanceState& inst = *s->instance;
  auto& next = inst.next;
  // As for suggestions: no action set at all (VUID-XrSessionActionSetsAttachInfo
  // -countActionSets-arraylength) is the runtime's to refuse, and a session the layer already
  // attached its own set to (selfAttach) can take no more.
  bool selfAttached;
  {
    std::lock_guard lock(s->mutex);
    selfAttached = s->selfAttached;
  }
  if (selfAttached) {
    const XrResult r = next.xrAttachSessionActionSets(session, info);
    if (r == XR_ERROR_ACTIONSETS_ALREADY_ATTACHED)
      SDFG_LOG_WARN(cmd,
                    "refused because the layer attached its own set at the first frame "
                    "(attach_alone = true); set attach_alone = false for this app");
    return r;
  }
  if (inst.actionSet == XR_NULL_HANDLE || info == nullptr ||
      info->type != XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO || info->countActionSets == 0 ||
      info->actionSets == nullptr)
    return next.xrAttachSessionActionSets(session, info);
  suggestOwnBindingsIfAlone(inst);
  std::vector<XrActionSet> sets(info->actionSets, info->actionSets + info->countActionSets);
  sets.push_back(inst.actionSet);
  XrSessionActionSetsAttachInfo copy = *info;
  copy.countActionSets = uint32_t(sets.size());
  copy.actionSets = sets.data();
  XrResult r = next.xrAttachSessionActionSets(session, &copy);
  if (XR_FAILED(r)) {
    const XrResult own = next.xrAttachSessionActionSets(session, info);
    if (XR_SUCCEEDED(own)) {
      {
        std::lock_guard lock(s->mutex);
        s->appAttached = true;
      }
      SDFG_LOG_WARN(cmd, "could not attach the layer's action set (%d)", int(r));
    }
    return own;
  }
  createLayerSpaces(*s);
  std::lock_guard lock(s->mutex);
  s->attached = true;
  s->appAttached = true;
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrSyncActions(XrSession session, const XrActionsSyncInfo* info) {
  constexpr const char* cmd = "xrSyncActions";
  SDFG_ENTRY_BEGIN
  auto s = sessions().find(key(session));
  if (s == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(session) is not valid");
  InstanceState& inst = *s->instance;
  bool attached;
  bool selfAttached;
  {
    std::lock_guard lock(s->mutex);
    attached = s->attached;
    selfAttached = s->selfAttached;
  }
  // A session the layer attached alone: the app has no sets, and its sync is the runtime's to
  // answer; the layer syncs its own in xrWaitFrame.
  if (!attached || selfAttached || info == nullptr || info->type != XR_TYPE_ACTIONS_SYNC_INFO ||
      (info->countActiveActionSets > 0 && info->activeActionSets == nullptr))
    return inst.next.xrSyncActions(session, info);
  std::vector<XrActiveActionSet> active(info->activeActionSets,
                                        info->activeActionSets + info->countActiveActionSets);
  active.push_back({inst.actionSet, XR_NULL_PATH});
  XrActionsSyncInfo copy = *info;
  copy.countActiveActionSets = uint32_t(active.size());
  copy.activeActionSets = active.data();
  XrResult r = inst.next.xrSyncActions(session, &copy);
  if (XR_FAILED(r)) {
    // Never fail the app's call because of the layer's set: asked again as the app made it, the
    // runtime's answer to that is the app's. The layer's input is not read this frame.
    const XrResult own = inst.next.xrSyncActions(session, info);
    if (XR_SUCCEEDED(own)) {
      bool first = false;
      {
        std::lock_guard lock(s->mutex);
        first = !std::exchange(s->syncRefusedLogged, true);
      }
      if (first)
        SDFG_LOG_WARN(cmd,
                      "the runtime refused the sync with the layer's action set (%d); synced "
                      "as the app asked, the layer's squeeze and grip are not read",
                      int(r));
    }
    return own;
  }
  if (r == XR_SUCCESS || r == XR_SESSION_NOT_FOCUSED) {
    // A failure in the layer's own work never changes the app's result. Builds the update
    // records go to a queue of the layer's own at once (the pump in syncGrasps); the app's queue
    // waits for the frame calls.
    try {
      syncGrasps(*s, cmd);
    } catch (...) {
      SDFG_LOG_WARN(cmd, "grab update failed; hands pass through this frame");
    }
  }
  return r;
  SDFG_ENTRY_END(cmd)
}

}  // namespace sdfg::layer
