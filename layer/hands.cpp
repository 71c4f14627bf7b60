// XR_EXT_hand_tracking through the layer: trackers from the runtime (joints passed through
// bit-identical unless a grasp is shown) or synthesized from the controller grip pose and squeeze
// when the runtime has no hand tracking. Hands are drawn from the ShownHand the last grab update
// published (grasp_frame.cpp): a locate never takes the session's lock across a call down, and
// never waits for the thread that updates the grasps.
#include <algorithm>
#include <cmath>
#include <span>

#include "data_source.h"
#include "intercepts.h"
#include "log.h"
#include "rollback.h"
#include "state.h"
#include "test_fault.h"

namespace sdfg::layer {
namespace {

constexpr XrSpaceLocationFlags kValidBits =
    XR_SPACE_LOCATION_ORIENTATION_VALID_BIT | XR_SPACE_LOCATION_POSITION_VALID_BIT;
constexpr XrSpaceLocationFlags kAllBits =
    kValidBits | XR_SPACE_LOCATION_ORIENTATION_TRACKED_BIT | XR_SPACE_LOCATION_POSITION_TRACKED_BIT;

Hand handOf(XrHandEXT hand) {
  return hand == XR_HAND_LEFT_EXT ? Hand::left : Hand::right;
}

// What `hand` shows now (null before the first grab update, or without an engine).
std::shared_ptr<const ShownHand> shownHand(const SessionState& s, Hand hand) {
  return s.shown[hand == Hand::left ? 0 : 1].load();
}

// No hand this frame: not active, no joint or velocity valid (the spec's lost hand).
void withholdHand(XrHandJointLocationsEXT& locations) {
  locations.isActive = XR_FALSE;
  if (locations.jointLocations != nullptr)
    for (auto& l : std::span(locations.jointLocations, locations.jointCount)) l.locationFlags = 0;
  auto* velocities =
      findInChain<XrHandJointVelocitiesEXT>(locations.next, XR_TYPE_HAND_JOINT_VELOCITIES_EXT);
  if (velocities != nullptr && velocities->jointVelocities != nullptr)
    for (auto& v : std::span(velocities->jointVelocities, velocities->jointCount))
      v.velocityFlags = 0;
}

}  // namespace

XrResult XRAPI_CALL SdfgXrCreateHandTrackerEXT(XrSession session,
                                               const XrHandTrackerCreateInfoEXT* info,
                                               XrHandTrackerEXT* tracker) {
  constexpr const char* cmd = "xrCreateHandTrackerEXT";
  SDFG_ENTRY_BEGIN
  auto s = sessions().find(key(session));
  if (s == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(session) is not valid");
  InstanceState& inst = *s->instance;
  auto t = std::make_shared<TrackerState>();
  t->session = s;
  const bool synthesis = inst.config.synthesis;
  if (!inst.provideHandTracking && !(inst.runtimeSystemLacksHands && synthesis)) {
    if (XrResult v = readDataSourceInfo(cmd, inst, info, *t); v != XR_SUCCESS) return v;
    const ChainUnlink unlink(
        layerAnswersDataSource(inst) && info != nullptr ? &info->next : nullptr,
        XR_TYPE_HAND_TRACKING_DATA_SOURCE_INFO_EXT);
    const XrResult r = inst.next.xrCreateHandTrackerEXT(session, info, tracker);
    // A system without hands (the extension listed, controllers only) refuses trackers: the
    // layer synthesizes the hands instead, and remembers, so later trackers skip the runtime.
    if (r == XR_ERROR_FEATURE_UNSUPPORTED && synthesis) {
      if (!inst.runtimeSystemLacksHands.exchange(true))
        SDFG_LOG_WARN(cmd,
                      "the runtime's system cannot track hands; the layer synthesizes "
                      "them from the controllers' grip pose and squeeze");
      return SdfgXrCreateHandTrackerEXT(session, info, tracker);
    }
    if (XR_FAILED(r)) return r;
    const XrHandTrackerEXT made = *tracker;
    Rollback undo([&] {
      inst.next.xrDestroyHandTrackerEXT(made);
      *tracker = XR_NULL_HANDLE;
    });
    t->handle = key(made);
    t->runtimeHandle = made;
    t->hand = handOf(info->hand);
    throwIfTestFault(inst, "after_create_tracker");
    {
      const uint64_t handle = t->handle;
      trackers().insert(handle, std::move(t));
    }
    undo.dismiss();
    return r;
  }
  if (info == nullptr) return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(createInfo) is null");
  if (info->type != XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(createInfo->type) is %d", int(info->type));
  if (tracker == nullptr)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(handTracker) is null");
  if (info->hand != XR_HAND_LEFT_EXT && info->hand != XR_HAND_RIGHT_EXT)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(createInfo->hand) is %d", int(info->hand));
  if (info->handJointSet != XR_HAND_JOINT_SET_DEFAULT_EXT)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(createInfo->handJointSet) is %d",
                    int(info->handJointSet));
  if (!inst.config.synthesis)
    return logError(XR_ERROR_FEATURE_UNSUPPORTED, cmd, "hand synthesis is switched off");
  if (XrResult v = readDataSourceInfo(cmd, inst, info, *t); v != XR_SUCCESS) return v;
  t->handle = newLayerHandle();
  t->hand = handOf(info->hand);
  const uint64_t handle = t->handle;
  trackers().insert(handle, std::move(t));  // first: it is the only step that can fail
  {
    std::lock_guard lock(s->mutex);
    ++s->synthesizedTrackers;
  }
  *tracker = fromKey<XrHandTrackerEXT>(handle);
  return XR_SUCCESS;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrDestroyHandTrackerEXT(XrHandTrackerEXT tracker) {
  constexpr const char* cmd = "xrDestroyHandTrackerEXT";
  SDFG_ENTRY_BEGIN
  auto t = trackers().find(key(tracker));
  if (t == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(handTracker) is not valid");
  if (t->runtimeHandle != XR_NULL_HANDLE) {
    auto s = t->session.lock();
    if (s == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(handTracker) is not valid");
    const XrResult r = s->instance->next.xrDestroyHandTrackerEXT(t->runtimeHandle);
    if (XR_SUCCEEDED(r)) trackers().erase(key(tracker));
    return r;
  }
  trackers().erase(key(tracker));
  if (auto s = t->session.lock()) {
    std::lock_guard lock(s->mutex);
    --s->synthesizedTrackers;
  }
  return XR_SUCCESS;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrLocateHandJointsEXT(XrHandTrackerEXT tracker,
                                              const XrHandJointsLocateInfoEXT* info,
                                              XrHandJointLocationsEXT* locations) {
  constexpr const char* cmd = "xrLocateHandJointsEXT";
  SDFG_ENTRY_BEGIN
  auto t = trackers().find(key(tracker));
  auto s = t == nullptr ? nullptr : t->session.lock();
  if (s == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(handTracker) is not valid");
  InstanceState& inst = *s->instance;

  if (t->runtimeHandle != XR_NULL_HANDLE) {
    XrResult r;
    ChainUnlink unlink(
        layerAnswersDataSource(inst) && locations != nullptr ? &locations->next : nullptr,
        XR_TYPE_HAND_TRACKING_DATA_SOURCE_STATE_EXT);
    if (inst.stripMotionRange && info != nullptr &&
        findInChain<const XrBaseInStructure>(info->next,
                                             XR_TYPE_HAND_JOINTS_MOTION_RANGE_INFO_EXT)) {
      // The runtime lacks the extension: locate without its struct (unobstructed is the default).
      XrHandJointsLocateInfoEXT copy = *info;
      copy.next = nullptr;
      r = inst.next.xrLocateHandJointsEXT(t->runtimeHandle, &copy, locations);
    } else {
      r = inst.next.xrLocateHandJointsEXT(t->runtimeHandle, info, locations);
    }
    unlink.restore();
    if (r == XR_SUCCESS)
      writeDataSourceState(inst, *t, locations, XR_HAND_TRACKING_DATA_SOURCE_UNOBSTRUCTED_EXT);
    if (r != XR_SUCCESS || !locations->isActive) return r;
    try {
      const auto view = shownHand(*s, t->hand);
      // Pass-through, untouched, unless a grasp is shown or its offset still blends out, and
      // always where the runtime marks a joint's pose invalid: the layer draws only on a hand
      // whose every joint the runtime vouches for (the grab update uses no other either).
      if (view == nullptr || !view->changesHand() || locations->jointLocations == nullptr ||
          locations->jointCount != XR_HAND_JOINT_COUNT_EXT)
        return r;
      const std::span<const XrHandJointLocationEXT> given(locations->jointLocations,
                                                          XR_HAND_JOINT_COUNT_EXT);
      if (!std::all_of(given.begin(), given.end(), [](const XrHandJointLocationEXT& l) {
            return (l.locationFlags & kValidBits) == kValidBits;
          }))
        return r;
      JointPoses joints;
      for (int j = 0; j < kJointCount; ++j) joints[j] = toPose(locations->jointLocations[j].pose);
      std::array<bool, kJointCount> changed{};
      if (!drawTrackedHand(*view, joints, changed)) {
        // It may be inside something and nothing places it yet (outer_view.h): not tracked
        // this frame, as a runtime reports a hand it lost.
        withholdHand(*locations);
        return r;
      }
      for (int j = 0; j < kJointCount; ++j)
        if (changed[size_t(j)]) locations->jointLocations[j].pose = toXr(joints[size_t(j)]);
    } catch (...) {
      SDFG_LOG_WARN(cmd, "applying the grasp failed; joints pass through");
    }
    return r;
  }

  // Synthesized: validate as a runtime would, then build the joints from the grip pose.
  if (info == nullptr) return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(locateInfo) is null");
  if (info->type != XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(locateInfo->type) is %d", int(info->type));
  if (locations == nullptr)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(locations) is null");
  if (locations->type != XR_TYPE_HAND_JOINT_LOCATIONS_EXT)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(locations->type) is %d",
                    int(locations->type));
  if (locations->jointCount != XR_HAND_JOINT_COUNT_EXT)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(locations->jointCount) is %u, expected 26",
                    locations->jointCount);
  if (locations->jointLocations == nullptr)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(locations->jointLocations) is null");
  if (info->time <= 0)
    return logError(XR_ERROR_TIME_INVALID, cmd, "(locateInfo->time) is %lld",
                    static_cast<long long>(info->time));
  auto* velocities =
      findInChain<XrHandJointVelocitiesEXT>(locations->next, XR_TYPE_HAND_JOINT_VELOCITIES_EXT);
  if (velocities != nullptr &&
      (velocities->jointCount != XR_HAND_JOINT_COUNT_EXT || velocities->jointVelocities == nullptr))
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(velocities) count or array is wrong");
  MotionRange range = MotionRange::unobstructed;
  if (inst.appMotionRange) {
    if (const auto* mr = findInChain<const XrHandJointsMotionRangeInfoEXT>(
            info->next, XR_TYPE_HAND_JOINTS_MOTION_RANGE_INFO_EXT)) {
      if (mr->handJointsMotionRange == XR_HAND_JOINTS_MOTION_RANGE_CONFORMING_TO_CONTROLLER_EXT)
        range = MotionRange::conforming_to_controller;
      else if (mr->handJointsMotionRange != XR_HAND_JOINTS_MOTION_RANGE_UNOBSTRUCTED_EXT)
        return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(handJointsMotionRange) is %d",
                        int(mr->handJointsMotionRange));
    }
  }

  const int h = t->hand == Hand::left ? 0 : 1;
  XrSpace grip = XR_NULL_HANDLE;
  bool ownSpace = false;
  bool engine = false;
  {
    std::lock_guard lock(s->mutex);
    const auto use = s->spaces.find(key(info->baseSpace));
    ownSpace = (use != s->spaces.end() && !use->second.dying) || info->baseSpace == s->localSpace;
    grip = s->gripSpaces[size_t(h)];
    engine = s->grasp != nullptr;
  }
  if (!ownSpace)
    return logError(XR_ERROR_HANDLE_INVALID, cmd,
                    "(locateInfo->baseSpace) is not a space of this session");
  // The grip in the app's base space at the app's time: the runtime's answer, no lock held.
  std::optional<Pose> baseFromGrip;
  if (grip != XR_NULL_HANDLE) {
    XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
    if (inst.next.xrLocateSpace(grip, info->baseSpace, info->time, &loc) == XR_SUCCESS &&
        (loc.locationFlags & kValidBits) == kValidBits)
      baseFromGrip = toPose(loc.pose);
  }
  const bool active = baseFromGrip.has_value() && engine;
  locations->isActive = active ? XR_TRUE : XR_FALSE;
  if (velocities != nullptr) {
    for (auto& v : std::span(velocities->jointVelocities, XR_HAND_JOINT_COUNT_EXT)) {
      v.velocityFlags = 0;
      v.linearVelocity = {0, 0, 0};
      v.angularVelocity = {0, 0, 0};
    }
  }
  if (!active || (layerAnswersDataSource(inst) && !t->allowController)) {
    // No grip, or the app does not accept joints synthesized from a controller.
    locations->isActive = XR_FALSE;
    writeDataSourceState(inst, *t, locations, XR_HAND_TRACKING_DATA_SOURCE_CONTROLLER_EXT);
    for (auto& l : std::span(locations->jointLocations, XR_HAND_JOINT_COUNT_EXT)) {
      l.locationFlags = 0;
      l.pose = XrPosef{{0, 0, 0, 1}, {0, 0, 0}};
      l.radius = 0;
    }
    return XR_SUCCESS;
  }
  // Before the first grab update: the open hand of the default model.
  const auto published = shownHand(*s, t->hand);
  ShownHand fallback;
  fallback.model = HandModel::defaultAdult(t->hand);
  const ShownHand& view = published != nullptr ? *published : fallback;
  JointPoses joints;
  JointRadii radii;
  if (!drawGripHand(view, *baseFromGrip, range, joints, radii)) {
    withholdHand(*locations);
    writeDataSourceState(inst, *t, locations, XR_HAND_TRACKING_DATA_SOURCE_CONTROLLER_EXT);
    return XR_SUCCESS;
  }
  for (int j = 0; j < kJointCount; ++j) {
    XrHandJointLocationEXT& l = locations->jointLocations[j];
    l.pose = toXr(joints[j]);
    l.radius = radii[j];
    l.locationFlags = kAllBits;
  }
  writeDataSourceState(inst, *t, locations, XR_HAND_TRACKING_DATA_SOURCE_CONTROLLER_EXT);
  return XR_SUCCESS;
  SDFG_ENTRY_END(cmd)
}

}  // namespace sdfg::layer
