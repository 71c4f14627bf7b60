// Actions: action sets and actions, suggested bindings, attach, sync and state queries, and
// haptics. The simulated controllers are those of the profile in Options::profile when the
// app suggested bindings for it, else khr/simple_controller when suggested, else none.
// Priorities between action sets are not modelled: every active set reads its sources.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "entry_points.h"

namespace sdfg::mock {
namespace {

const char* const kTopLevelPaths[] = {"/user/hand/left", "/user/hand/right", "/user/head",
                                      "/user/gamepad", "/user/treadmill"};

bool isTopLevelUserPath(const Instance& instance, XrPath path) {
  const std::string* s = instance.pathString(path);
  if (s == nullptr) return false;
  for (const char* p : kTopLevelPaths) {
    if (*s == p) return true;
  }
  return false;
}

// Action and action-set names: a single path component (spec 11.2).
XrResult verifyNames(const char* cmd, const char* name, size_t nameSize, const char* localized,
                     size_t localizedSize) {
  const size_t n = strnlen(name, nameSize);
  if (n == nameSize) return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "name is not terminated");
  if (n == 0) return fail(cmd, XR_ERROR_NAME_INVALID, "empty name");
  for (size_t i = 0; i < n; ++i) {
    const char c = name[i];
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.'))
      return fail(cmd, XR_ERROR_PATH_FORMAT_INVALID, "name '%s' has character '%c'", name, c);
  }
  const size_t l = strnlen(localized, localizedSize);
  if (l == localizedSize)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "localized name is not terminated");
  if (l == 0) return fail(cmd, XR_ERROR_LOCALIZED_NAME_INVALID, "empty localized name");
  return XR_SUCCESS;
}

bool attachedTo(const Session& session, const ActionSet* set) {
  return std::find(session.attachedSets.begin(), session.attachedSets.end(), set) !=
         session.attachedSets.end();
}

const std::vector<Binding>* currentBindings(const Session& session) {
  if (session.profile == XR_NULL_PATH) return nullptr;
  const auto it = session.instance->suggested.find(session.profile);
  return it == session.instance->suggested.end() ? nullptr : &it->second;
}

// Common checks of the state queries and haptics: live action of the right type, attached to
// this session, subaction path null or one of the action's.
XrResult verifyAction(const char* cmd, const Session& session, XrAction handle,
                      XrPath subactionPath, XrActionType expectedType, const Action** out,
                      int* slot) {
  const Action* action = lookup<Action>(handle);
  if (action == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "action is not valid");
  if (action->type != expectedType)
    return fail(cmd, XR_ERROR_ACTION_TYPE_MISMATCH, "action '%s' has type %d, expected %d",
                action->name.c_str(), int(action->type), int(expectedType));
  if (!attachedTo(session, action->set))
    return fail(cmd, XR_ERROR_ACTIONSET_NOT_ATTACHED, "action set '%s' is not attached",
                action->set->name.c_str());
  if (subactionPath != XR_NULL_PATH) {
    if (session.instance->pathString(subactionPath) == nullptr)
      return fail(cmd, XR_ERROR_PATH_INVALID, "subactionPath is not a path");
    const auto& list = action->subactionPaths;
    if (std::find(list.begin(), list.end(), subactionPath) == list.end())
      return fail(cmd, XR_ERROR_PATH_UNSUPPORTED, "subactionPath not given at action creation");
  }
  *out = action;
  *slot = subactionSlot(*session.instance, subactionPath);
  return XR_SUCCESS;
}

const ActionValue* stateOf(const Session& session, const Action* action, int slot) {
  if (slot < 0) return nullptr;
  const auto it = session.actionStates.find(action);
  return it == session.actionStates.end() ? nullptr : &it->second[size_t(slot)];
}

void recordHaptic(Session& session, const Action* action, int slot, float amplitude) {
  const auto* bindings = currentBindings(session);
  if (bindings == nullptr) return;
  for (const Binding& b : *bindings) {
    if (b.action != action || (slot != 2 && int(b.hand) != slot)) continue;
    ++session.stats.hapticCount[b.hand];
    session.stats.lastHapticAmplitude[b.hand] = amplitude;
  }
}

}  // namespace

int subactionSlot(const Instance& instance, XrPath path) {
  if (path == XR_NULL_PATH) return 2;
  const std::string* s = instance.pathString(path);
  if (s == nullptr) return -1;
  if (*s == "/user/hand/left") return 0;
  if (*s == "/user/hand/right") return 1;
  return -1;
}

bool actionActive(const Session& session, const Action* action, XrPath subactionPath) {
  const ActionValue* v = stateOf(session, action, subactionSlot(*session.instance, subactionPath));
  return v != nullptr && v->active;
}

const Binding* poseBinding(const Session& session, const Action* action, XrPath subactionPath) {
  const auto* bindings = currentBindings(session);
  const int slot = subactionSlot(*session.instance, subactionPath);
  if (bindings == nullptr || slot < 0) return nullptr;
  for (const Binding& b : *bindings) {
    if (b.action == action && (slot == 2 || int(b.hand) == slot) &&
        (b.identifier == "grip" || b.identifier == "aim"))
      return &b;
  }
  return nullptr;
}

XrResult createActionSet(XrInstance handle, const XrActionSetCreateInfo* info, XrActionSet* out) {
  constexpr const char* cmd = "xrCreateActionSet";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_ACTION_SET_CREATE_INFO);
  MOCK_VERIFY_NOT_NULL(cmd, out);
  if (XrResult r = verifyNames(cmd, info->actionSetName, XR_MAX_ACTION_SET_NAME_SIZE,
                               info->localizedActionSetName, XR_MAX_LOCALIZED_ACTION_SET_NAME_SIZE);
      r != XR_SUCCESS)
    return r;
  for (const auto& s : instance->actionSets) {
    if (!s->alive) continue;
    if (s->name == info->actionSetName)
      return fail(cmd, XR_ERROR_NAME_DUPLICATED, "action set '%s' exists", info->actionSetName);
    if (s->localizedName == info->localizedActionSetName)
      return fail(cmd, XR_ERROR_LOCALIZED_NAME_DUPLICATED, "localized name '%s' exists",
                  info->localizedActionSetName);
  }
  auto set = std::make_unique<ActionSet>();
  set->name = info->actionSetName;
  set->localizedName = info->localizedActionSetName;
  set->priority = info->priority;
  set->instance = instance;
  registerHandle(set.get());
  *out = toHandle<XrActionSet>(set.get());
  instance->actionSets.push_back(std::move(set));
  return XR_SUCCESS;
}

XrResult destroyActionSet(XrActionSet handle) {
  ActionSet* set = lookup<ActionSet>(handle);
  if (set == nullptr) return fail("xrDestroyActionSet", XR_ERROR_HANDLE_INVALID, "action set");
  set->alive = false;
  for (Action* a : set->actions) {
    a->alive = false;
    unregisterHandle(a);
  }
  unregisterHandle(set);
  return XR_SUCCESS;
}

XrResult createAction(XrActionSet handle, const XrActionCreateInfo* info, XrAction* out) {
  constexpr const char* cmd = "xrCreateAction";
  ActionSet* set = lookup<ActionSet>(handle);
  if (set == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "action set is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_ACTION_CREATE_INFO);
  MOCK_VERIFY_NOT_NULL(cmd, out);
  if (XrResult r = verifyNames(cmd, info->actionName, XR_MAX_ACTION_NAME_SIZE,
                               info->localizedActionName, XR_MAX_LOCALIZED_ACTION_NAME_SIZE);
      r != XR_SUCCESS)
    return r;
  switch (info->actionType) {
    case XR_ACTION_TYPE_BOOLEAN_INPUT:
    case XR_ACTION_TYPE_FLOAT_INPUT:
    case XR_ACTION_TYPE_VECTOR2F_INPUT:
    case XR_ACTION_TYPE_POSE_INPUT:
    case XR_ACTION_TYPE_VIBRATION_OUTPUT:
      break;
    default:
      return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "actionType %d", int(info->actionType));
  }
  if (set->attached)
    return fail(cmd, XR_ERROR_ACTIONSETS_ALREADY_ATTACHED, "set '%s'", set->name.c_str());
  for (const Action* a : set->actions) {
    if (!a->alive) continue;
    if (a->name == info->actionName)
      return fail(cmd, XR_ERROR_NAME_DUPLICATED, "action '%s' exists", info->actionName);
    if (a->localizedName == info->localizedActionName)
      return fail(cmd, XR_ERROR_LOCALIZED_NAME_DUPLICATED, "localized '%s' exists",
                  info->localizedActionName);
  }
  if (info->countSubactionPaths > 0) MOCK_VERIFY_NOT_NULL(cmd, info->subactionPaths);
  Instance& instance = *set->instance;
  auto action = std::make_unique<Action>();
  for (uint32_t i = 0; i < info->countSubactionPaths; ++i) {
    const XrPath p = info->subactionPaths[i];
    if (instance.pathString(p) == nullptr)
      return fail(cmd, XR_ERROR_PATH_INVALID, "subactionPaths[%u] is not a path", i);
    if (!isTopLevelUserPath(instance, p))
      return fail(cmd, XR_ERROR_PATH_UNSUPPORTED,
                  "subactionPaths[%u] '%s' is no top-level user path", i,
                  instance.pathString(p)->c_str());
    if (std::find(action->subactionPaths.begin(), action->subactionPaths.end(), p) !=
        action->subactionPaths.end())
      return fail(cmd, XR_ERROR_PATH_UNSUPPORTED, "subactionPaths[%u] is a duplicate", i);
    action->subactionPaths.push_back(p);
  }
  action->set = set;
  action->name = info->actionName;
  action->localizedName = info->localizedActionName;
  action->type = info->actionType;
  registerHandle(action.get());
  *out = toHandle<XrAction>(action.get());
  set->actions.push_back(action.get());
  instance.actions.push_back(std::move(action));
  return XR_SUCCESS;
}

XrResult destroyAction(XrAction handle) {
  Action* action = lookup<Action>(handle);
  if (action == nullptr) return fail("xrDestroyAction", XR_ERROR_HANDLE_INVALID, "action");
  action->alive = false;
  unregisterHandle(action);
  return XR_SUCCESS;
}

XrResult suggestInteractionProfileBindings(XrInstance handle,
                                           const XrInteractionProfileSuggestedBinding* suggested) {
  constexpr const char* cmd = "xrSuggestInteractionProfileBindings";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  MOCK_VERIFY_TYPE(cmd, suggested, XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING);
  const std::string* profile = instance->pathString(suggested->interactionProfile);
  if (profile == nullptr)
    return fail(cmd, XR_ERROR_PATH_INVALID, "interactionProfile is not a path");
  if (!isKnownProfile(*profile))
    return fail(cmd, XR_ERROR_PATH_UNSUPPORTED, "profile %s", profile->c_str());
  if (suggested->countSuggestedBindings == 0)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "countSuggestedBindings is 0");
  MOCK_VERIFY_NOT_NULL(cmd, suggested->suggestedBindings);
  std::vector<Binding> bindings;
  for (uint32_t i = 0; i < suggested->countSuggestedBindings; ++i) {
    const XrActionSuggestedBinding& s = suggested->suggestedBindings[i];
    Action* action = lookup<Action>(s.action);
    if (action == nullptr || action->set->instance != instance)
      return fail(cmd, XR_ERROR_HANDLE_INVALID, "suggestedBindings[%u].action is not valid", i);
    if (action->set->attached)
      return fail(cmd, XR_ERROR_ACTIONSETS_ALREADY_ATTACHED, "action '%s' is in an attached set",
                  action->name.c_str());
    const std::string* path = instance->pathString(s.binding);
    if (path == nullptr)
      return fail(cmd, XR_ERROR_PATH_INVALID, "suggestedBindings[%u].binding", i);
    Binding b;
    if (!resolveBinding(*profile, *path, b))
      return fail(cmd, XR_ERROR_PATH_UNSUPPORTED, "%s has no %s", profile->c_str(), path->c_str());
    b.action = action;
    b.path = s.binding;
    bindings.push_back(b);
  }
  // A later suggestion for the same profile replaces the earlier one (spec 11.4).
  instance->suggested[suggested->interactionProfile] = std::move(bindings);
  return XR_SUCCESS;
}

XrResult attachSessionActionSets(XrSession handle, const XrSessionActionSetsAttachInfo* info) {
  constexpr const char* cmd = "xrAttachSessionActionSets";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO);
  if (info->countActionSets == 0)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "countActionSets is 0");
  MOCK_VERIFY_NOT_NULL(cmd, info->actionSets);
  if (!session->attachedSets.empty())
    return fail(cmd, XR_ERROR_ACTIONSETS_ALREADY_ATTACHED, "this session has attached sets");
  std::vector<ActionSet*> sets;
  for (uint32_t i = 0; i < info->countActionSets; ++i) {
    ActionSet* set = lookup<ActionSet>(info->actionSets[i]);
    if (set == nullptr || set->instance != session->instance)
      return fail(cmd, XR_ERROR_HANDLE_INVALID, "actionSets[%u] is not valid", i);
    sets.push_back(set);
  }
  for (ActionSet* set : sets) {
    set->attached = true;
    session->attachedSets.push_back(set);
    for (const Action* a : set->actions) session->actionStates[a] = ActionStates{};
  }
  Instance& instance = *session->instance;
  const XrPath wanted = instance.path(instance.options.profile);
  const XrPath simple = instance.path("/interaction_profiles/khr/simple_controller");
  if (instance.suggested.count(wanted) != 0)
    session->profile = wanted;
  else if (instance.suggested.count(simple) != 0)
    session->profile = simple;
  session->stats.currentProfile = session->profile;
  // The change is announced by the next xrSyncActions: the spec queues the event only there
  // (the CTS's conformance layer checks it).
  session->profileChangePending = session->profile != XR_NULL_PATH;
  return XR_SUCCESS;
}

XrResult getCurrentInteractionProfile(XrSession handle, XrPath topLevelUserPath,
                                      XrInteractionProfileState* profile) {
  constexpr const char* cmd = "xrGetCurrentInteractionProfile";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, profile, XR_TYPE_INTERACTION_PROFILE_STATE);
  if (session->attachedSets.empty())
    return fail(cmd, XR_ERROR_ACTIONSET_NOT_ATTACHED, "nothing attached");
  if (session->instance->pathString(topLevelUserPath) == nullptr)
    return fail(cmd, XR_ERROR_PATH_INVALID, "topLevelUserPath is not a path");
  if (!isTopLevelUserPath(*session->instance, topLevelUserPath))
    return fail(cmd, XR_ERROR_PATH_UNSUPPORTED, "%s is no top-level user path",
                session->instance->pathString(topLevelUserPath)->c_str());
  const int slot = subactionSlot(*session->instance, topLevelUserPath);
  profile->interactionProfile = slot == 0 || slot == 1 ? session->profile : XR_NULL_PATH;
  return XR_SUCCESS;
}

XrResult syncActions(XrSession handle, const XrActionsSyncInfo* info) {
  constexpr const char* cmd = "xrSyncActions";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_ACTIONS_SYNC_INFO);
  if (info->countActiveActionSets > 0) MOCK_VERIFY_NOT_NULL(cmd, info->activeActionSets);
  Instance& instance = *session->instance;
  // A runtime that takes one active set at a time (the layer must then sync the app's alone).
  if (instance.options.fault == "sync_one_set" && info->countActiveActionSets > 1)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "fault sync_one_set: %u active sets",
                info->countActiveActionSets);
  // Per attached set: which slots the app activated (bit 0 left, bit 1 right).
  std::map<const ActionSet*, int> activeSlots;
  for (uint32_t i = 0; i < info->countActiveActionSets; ++i) {
    const XrActiveActionSet& a = info->activeActionSets[i];
    const ActionSet* set = lookup<ActionSet>(a.actionSet);
    if (set == nullptr)
      return fail(cmd, XR_ERROR_HANDLE_INVALID, "activeActionSets[%u] is not valid", i);
    if (!attachedTo(*session, set))
      return fail(cmd, XR_ERROR_ACTIONSET_NOT_ATTACHED, "set '%s' is not attached",
                  set->name.c_str());
    if (a.subactionPath != XR_NULL_PATH) {
      if (instance.pathString(a.subactionPath) == nullptr)
        return fail(cmd, XR_ERROR_PATH_INVALID, "activeActionSets[%u].subactionPath", i);
      if (!isTopLevelUserPath(instance, a.subactionPath))
        return fail(cmd, XR_ERROR_PATH_UNSUPPORTED, "activeActionSets[%u].subactionPath", i);
    }
    const int slot = subactionSlot(instance, a.subactionPath);
    activeSlots[set] |= slot == 2 ? 3 : slot >= 0 ? 1 << slot : 0;
  }
  const bool focused = session->focused();
  const auto* bindings = currentBindings(*session);
  const XrTime t = now();
  for (auto& [action, states] : session->actionStates) {
    const auto it = activeSlots.find(action->set);
    const int mask = focused && action->alive && it != activeSlots.end() ? it->second : 0;
    ActionValue next[2];
    for (int hand = 0; hand < 2; ++hand) {
      ActionValue& v = next[hand];
      if ((mask & (1 << hand)) == 0 || bindings == nullptr) continue;
      for (const Binding& b : *bindings) {
        if (b.action != action || int(b.hand) != hand) continue;
        v.active = true;
        switch (action->type) {
          case XR_ACTION_TYPE_BOOLEAN_INPUT:
            v.boolean = v.boolean || readScalar(*session, b, action->type) > 0.5f;
            break;
          case XR_ACTION_TYPE_FLOAT_INPUT: {
            const float f = readScalar(*session, b, action->type);
            if (std::fabs(f) > std::fabs(v.value)) v.value = f;
            break;
          }
          case XR_ACTION_TYPE_VECTOR2F_INPUT: {
            Binding x = b, y = b;
            if (b.component.empty()) x.component = "x", y.component = "y";
            const XrVector2f vec{
                readScalar(*session, x, action->type),
                b.component.empty() ? readScalar(*session, y, action->type) : 0.0f};
            if (vec.x * vec.x + vec.y * vec.y > v.vector.x * v.vector.x + v.vector.y * v.vector.y)
              v.vector = vec;
            break;
          }
          default:
            break;
        }
      }
    }
    ActionValue any;
    any.active = next[0].active || next[1].active;
    any.boolean = next[0].boolean || next[1].boolean;
    any.value =
        std::fabs(next[0].value) >= std::fabs(next[1].value) ? next[0].value : next[1].value;
    const auto len = [](const XrVector2f& v) { return v.x * v.x + v.y * v.y; };
    any.vector = len(next[0].vector) >= len(next[1].vector) ? next[0].vector : next[1].vector;
    const ActionValue fresh[3] = {next[0], next[1], any};
    for (size_t s = 0; s < 3; ++s) {
      ActionValue v = fresh[s];
      const ActionValue& old = states[s];
      const bool differs = v.boolean != old.boolean || v.value != old.value ||
                           v.vector.x != old.vector.x || v.vector.y != old.vector.y;
      v.changed = v.active && old.active && differs;
      v.lastChange = v.changed || (v.active && !old.active) ? t : old.lastChange;
      states[s] = v;
    }
  }
  ++session->stats.syncCount;
  if (session->profileChangePending) {
    session->profileChangePending = false;
    XrEventDataBuffer buffer{XR_TYPE_EVENT_DATA_BUFFER};
    auto* e = reinterpret_cast<XrEventDataInteractionProfileChanged*>(&buffer);
    e->type = XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED;
    e->next = nullptr;
    e->session = handle;
    queueEvent(instance, buffer);
  }
  return focused ? XR_SUCCESS : XR_SESSION_NOT_FOCUSED;
}

// The four xrGetActionState* calls run the same checks and differ only in the action type they
// accept and in what of the stored value they report; `report` gets the value when the action is
// active in this slot, else null.
template <typename State, typename Report>
XrResult getActionState(const char* cmd, XrSession handle, const XrActionStateGetInfo* info,
                        State* state, XrStructureType stateType, XrActionType actionType,
                        Report report) {
  const Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_ACTION_STATE_GET_INFO);
  if (state == nullptr) return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "(state) is null");
  if (state->type != stateType)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "(state->type) is %d, expected %d",
                int(state->type), int(stateType));
  const Action* action = nullptr;
  int slot = 0;
  if (XrResult r = verifyAction(cmd, *session, info->action, info->subactionPath, actionType,
                                &action, &slot);
      r != XR_SUCCESS)
    return r;
  const ActionValue* v = stateOf(*session, action, slot);
  report(*state, v != nullptr && v->active ? v : nullptr);
  return XR_SUCCESS;
}

// Fills the fields every non-pose state has.
template <typename State>
void reportChange(State& state, const ActionValue* active) {
  state.isActive = active != nullptr;
  state.changedSinceLastSync = active != nullptr && active->changed;
  state.lastChangeTime = active != nullptr ? active->lastChange : 0;
}

XrResult getActionStateBoolean(XrSession handle, const XrActionStateGetInfo* info,
                               XrActionStateBoolean* state) {
  return getActionState("xrGetActionStateBoolean", handle, info, state,
                        XR_TYPE_ACTION_STATE_BOOLEAN, XR_ACTION_TYPE_BOOLEAN_INPUT,
                        [](XrActionStateBoolean& s, const ActionValue* v) {
                          reportChange(s, v);
                          s.currentState = v != nullptr && v->boolean;
                        });
}

XrResult getActionStateFloat(XrSession handle, const XrActionStateGetInfo* info,
                             XrActionStateFloat* state) {
  return getActionState("xrGetActionStateFloat", handle, info, state, XR_TYPE_ACTION_STATE_FLOAT,
                        XR_ACTION_TYPE_FLOAT_INPUT,
                        [](XrActionStateFloat& s, const ActionValue* v) {
                          reportChange(s, v);
                          s.currentState = v != nullptr ? v->value : 0.0f;
                        });
}

XrResult getActionStateVector2f(XrSession handle, const XrActionStateGetInfo* info,
                                XrActionStateVector2f* state) {
  return getActionState("xrGetActionStateVector2f", handle, info, state,
                        XR_TYPE_ACTION_STATE_VECTOR2F, XR_ACTION_TYPE_VECTOR2F_INPUT,
                        [](XrActionStateVector2f& s, const ActionValue* v) {
                          reportChange(s, v);
                          s.currentState = v != nullptr ? v->vector : XrVector2f{0, 0};
                        });
}

XrResult getActionStatePose(XrSession handle, const XrActionStateGetInfo* info,
                            XrActionStatePose* state) {
  return getActionState("xrGetActionStatePose", handle, info, state, XR_TYPE_ACTION_STATE_POSE,
                        XR_ACTION_TYPE_POSE_INPUT, [](XrActionStatePose& s, const ActionValue* v) {
                          s.isActive = v != nullptr;
                        });
}

XrResult enumerateBoundSourcesForAction(XrSession handle,
                                        const XrBoundSourcesForActionEnumerateInfo* info,
                                        uint32_t capacity, uint32_t* countOutput, XrPath* sources) {
  constexpr const char* cmd = "xrEnumerateBoundSourcesForAction";
  const Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_BOUND_SOURCES_FOR_ACTION_ENUMERATE_INFO);
  const Action* action = lookup<Action>(info->action);
  if (action == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "action is not valid");
  if (!attachedTo(*session, action->set))
    return fail(cmd, XR_ERROR_ACTIONSET_NOT_ATTACHED, "set '%s' is not attached",
                action->set->name.c_str());
  std::vector<XrPath> found;
  if (const auto* bindings = currentBindings(*session)) {
    for (const Binding& b : *bindings) {
      if (b.action == action && std::find(found.begin(), found.end(), b.path) == found.end())
        found.push_back(b.path);
    }
  }
  return twoCall(cmd, capacity, countOutput, sources, found.data(), uint32_t(found.size()));
}

XrResult getInputSourceLocalizedName(XrSession handle,
                                     const XrInputSourceLocalizedNameGetInfo* info,
                                     uint32_t capacity, uint32_t* countOutput, char* buffer) {
  constexpr const char* cmd = "xrGetInputSourceLocalizedName";
  const Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_INPUT_SOURCE_LOCALIZED_NAME_GET_INFO);
  if (info->whichComponents == 0)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "whichComponents is 0");
  if (session->attachedSets.empty())
    return fail(cmd, XR_ERROR_ACTIONSET_NOT_ATTACHED, "nothing attached");
  const std::string* source = session->instance->pathString(info->sourcePath);
  if (source == nullptr) return fail(cmd, XR_ERROR_PATH_INVALID, "sourcePath is not a path");
  const std::string* profile = session->instance->pathString(session->profile);
  Binding b;
  if (profile == nullptr || !resolveBinding(*profile, *source, b))
    return fail(cmd, XR_ERROR_PATH_UNSUPPORTED, "%s is no source of the current profile",
                source->c_str());
  std::string name;
  auto add = [&](const std::string& part) { name += (name.empty() ? "" : " ") + part; };
  if (info->whichComponents & XR_INPUT_SOURCE_LOCALIZED_NAME_USER_PATH_BIT)
    add(b.hand == kLeft ? "Left Hand" : "Right Hand");
  if (info->whichComponents & XR_INPUT_SOURCE_LOCALIZED_NAME_INTERACTION_PROFILE_BIT)
    add(profileLocalizedName(*profile));
  if (info->whichComponents & XR_INPUT_SOURCE_LOCALIZED_NAME_COMPONENT_BIT)
    add(b.component.empty() ? b.identifier : b.identifier + " " + b.component);
  return twoCallString(cmd, capacity, countOutput, buffer, name);
}

XrResult applyHapticFeedback(XrSession handle, const XrHapticActionInfo* info,
                             const XrHapticBaseHeader* feedback) {
  constexpr const char* cmd = "xrApplyHapticFeedback";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_HAPTIC_ACTION_INFO);
  MOCK_VERIFY_TYPE(cmd, feedback, XR_TYPE_HAPTIC_VIBRATION);
  const Action* action = nullptr;
  int slot = 0;
  if (XrResult r = verifyAction(cmd, *session, info->action, info->subactionPath,
                                XR_ACTION_TYPE_VIBRATION_OUTPUT, &action, &slot);
      r != XR_SUCCESS)
    return r;
  if (!session->focused()) return XR_SESSION_NOT_FOCUSED;
  const auto* v = reinterpret_cast<const XrHapticVibration*>(feedback);
  recordHaptic(*session, action, slot, v->amplitude);
  return XR_SUCCESS;
}

XrResult stopHapticFeedback(XrSession handle, const XrHapticActionInfo* info) {
  constexpr const char* cmd = "xrStopHapticFeedback";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_HAPTIC_ACTION_INFO);
  const Action* action = nullptr;
  int slot = 0;
  if (XrResult r = verifyAction(cmd, *session, info->action, info->subactionPath,
                                XR_ACTION_TYPE_VIBRATION_OUTPUT, &action, &slot);
      r != XR_SUCCESS)
    return r;
  if (!session->focused()) return XR_SESSION_NOT_FOCUSED;
  for (int h = 0; h < 2; ++h) {
    if (slot == 2 || slot == h) session->stats.lastHapticAmplitude[h] = 0.0f;
  }
  return XR_SUCCESS;
}

}  // namespace sdfg::mock
