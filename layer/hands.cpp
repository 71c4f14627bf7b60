// XR_EXT_hand_tracking through the layer: trackers from the runtime (joints passed through
// bit-identical unless a grasp is active) or synthesized from the controller grip pose and
// squeeze when the runtime has no hand tracking. Also the per-frame grab update.
#include <algorithm>
#include <cmath>

#include "data_source.h"
#include "intercepts.h"
#include "log.h"
#include "state.h"

namespace sdfg::layer {
namespace {

constexpr XrSpaceLocationFlags kValidBits =
    XR_SPACE_LOCATION_ORIENTATION_VALID_BIT | XR_SPACE_LOCATION_POSITION_VALID_BIT;
constexpr XrSpaceLocationFlags kAllBits =
    kValidBits | XR_SPACE_LOCATION_ORIENTATION_TRACKED_BIT | XR_SPACE_LOCATION_POSITION_TRACKED_BIT;

Hand handOf(XrHandEXT hand) {
  return hand == XR_HAND_LEFT_EXT ? Hand::left : Hand::right;
}

// Locates `space` in `base`; nullopt unless position and orientation are valid.
std::optional<Pose> locate(const InstanceState& inst, XrSpace space, XrSpace base, XrTime time) {
  if (space == XR_NULL_HANDLE || base == XR_NULL_HANDLE) return std::nullopt;
  XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
  if (inst.next.xrLocateSpace(space, base, time, &loc) != XR_SUCCESS) return std::nullopt;
  if ((loc.locationFlags & kValidBits) != kValidBits) return std::nullopt;
  return toPose(loc.pose);
}

// Finger curls the hand is allowed to show: per joint the lesser of the user's curl and the
// contact curl. replace[f] is false where the user's own pose is already the more open one.
void graspCurls(const HandGrasp& grasp, const FingerCurls& user, FingerJointCurls& curls,
                std::array<bool, kFingerCount>& replace) {
  for (int f = 0; f < kFingerCount; ++f) {
    const FingerState& fs = grasp.result.fingers[f];
    replace[f] = fs.curl < user[f];
    for (size_t k = 0; k < curls[f].size(); ++k) curls[f][k] = std::min(user[f], fs.jointCurls[k]);
  }
}

HandFrame trackedFrame(SessionState& s, int h, JointPoses& joints, JointRadii& radii) {
  HandFrame frame;
  InstanceState& inst = *s.instance;
  if (!inst.downstreamHandTracking || inst.next.xrLocateHandJointsEXT == nullptr ||
      inst.runtimeSystemLacksHands || s.internalTrackerRefused[h])
    return frame;
  if (s.internalTrackers[h] == XR_NULL_HANDLE) {
    XrHandTrackerCreateInfoEXT info{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
    info.hand = h == 0 ? XR_HAND_LEFT_EXT : XR_HAND_RIGHT_EXT;
    info.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
    const XrResult r = inst.next.xrCreateHandTrackerEXT(s.handle, &info, &s.internalTrackers[h]);
    if (r != XR_SUCCESS) {
      // Remembered for the session: a refusal is not retried every frame (each retry is an
      // error line in the runtime's log).
      s.internalTrackers[h] = XR_NULL_HANDLE;
      s.internalTrackerRefused[h] = true;
      SDFG_LOG_INFO("xrSyncActions",
                    "the runtime refused a %s hand tracker (%d); that hand follows the controller",
                    h == 0 ? "left" : "right", int(r));
      return frame;
    }
  }
  std::array<XrHandJointLocationEXT, XR_HAND_JOINT_COUNT_EXT> loc{};
  XrHandJointLocationsEXT locations{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
  locations.jointCount = XR_HAND_JOINT_COUNT_EXT;
  locations.jointLocations = loc.data();
  XrHandJointsLocateInfoEXT info{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
  info.baseSpace = s.localSpace;
  info.time = s.predictedTime;
  if (inst.next.xrLocateHandJointsEXT(s.internalTrackers[h], &info, &locations) != XR_SUCCESS ||
      !locations.isActive)
    return frame;
  for (int j = 0; j < kJointCount; ++j) {
    joints[j] = toPose(loc[j].pose);
    radii[j] = loc[j].radius;
  }
  frame.valid = true;
  frame.worldFromWrist = joints[size_t(Joint::wrist)];
  frame.trackedJoints = &joints;
  frame.trackedRadii = &radii;
  return frame;
}

}  // namespace

void destroyInternalTrackers(SessionState& s) {
  for (auto& t : s.internalTrackers) {
    if (t != XR_NULL_HANDLE && s.instance->next.xrDestroyHandTrackerEXT != nullptr)
      s.instance->next.xrDestroyHandTrackerEXT(t);
    t = XR_NULL_HANDLE;
  }
}

void updateGrasps(SessionState& s) {
  constexpr const char* cmd = "xrSyncActions";
  InstanceState& inst = *s.instance;
  if (s.predictedTime == 0 || s.grasp == nullptr || s.localSpace == XR_NULL_HANDLE) return;
  std::vector<TargetFrame> frames;
  frames.reserve(s.targets.size());
  for (const auto& [id, t] : s.targets) {
    TargetFrame f;
    f.id = id;
    if (auto p = locate(inst, t->space, s.localSpace, s.predictedTime)) {
      f.valid = true;
      f.worldFromObject = *p * toPose(t->pose);
    }
    frames.push_back(f);
  }
  for (int h = 0; h < 2; ++h) {
    const Hand hand = h == 0 ? Hand::left : Hand::right;
    XrActionStateGetInfo get{XR_TYPE_ACTION_STATE_GET_INFO};
    get.action = inst.squeezeAction;
    get.subactionPath = inst.handPaths[h];
    XrActionStateFloat state{XR_TYPE_ACTION_STATE_FLOAT};
    const bool squeezeActive =
        inst.next.xrGetActionStateFloat(s.handle, &get, &state) == XR_SUCCESS && state.isActive;
    s.squeeze[h] = squeezeActive && std::isfinite(state.currentState) ? state.currentState : 0.0f;

    JointPoses joints;
    JointRadii radii;
    HandFrame frame = trackedFrame(s, h, joints, radii);
    frame.squeeze = s.squeeze[h];
    frame.time = s.predictedTime;
    if (frame.valid && !squeezeActive) {
      // A tracked hand without a controller grabs by closing: its mean finger curl.
      JointPoses local;
      const Pose wristFromWorld = frame.worldFromWrist.inverse();
      for (int j = 0; j < kJointCount; ++j) local[j] = wristFromWorld * joints[j];
      const FingerCurls c = s.grasp->model(hand).estimateCurls(local);
      frame.squeeze = (c[1] + c[2] + c[3] + c[4]) * 0.25f;
    }
    if (!frame.valid) {
      if (auto grip = locate(inst, s.gripSpaces[h], s.localSpace, s.predictedTime)) {
        frame.valid = true;
        frame.worldFromWrist = *grip * wristFromGrip(s.grasp->model(hand)).inverse();
      }
    }
    const HandGrasp& before = s.grasp->grasp(hand);
    const bool wasGrasping = before.holding && before.solves > 0;
    const uint64_t wasTarget = before.target;
    if (Status st = s.grasp->update(hand, frame, frames); st == Status::timed_out)
      SDFG_LOG_WARN(cmd,
                    "the grab's SDF build passed its time bound (build_time_limit_ms = %u); the "
                    "hand stays open until it is released",
                    inst.config.buildTimeLimitMs);
    else if (st != Status::ok)
      SDFG_LOG_WARN(cmd, "grasp solve failed (%s); the hand stays open until it is released",
                    toString(st));
    noteGraspChange(s, hand, wasGrasping, wasTarget);
    advanceHandOffset(s, h);
  }
  // Set-ups run on the session's worker: one line per target on how its mesh was wound, and one
  // per target whose mesh it could not take.
  for (const auto& [id, o] : s.grasp->takeSetupOrientations()) {
    if (o.flipped > 0)
      SDFG_LOG_WARN(cmd, "target %#llx: mesh wound %s; %u triangles flipped to face outward",
                    static_cast<unsigned long long>(id), o.describe(), o.flipped);
    else
      SDFG_LOG_INFO(cmd, "target %#llx: mesh wound %s (%u parts, %u closed)",
                    static_cast<unsigned long long>(id), o.describe(), o.components,
                    o.closedComponents);
  }
  for (const auto& [id, why] : s.grasp->takeRefusedUpdates())
    SDFG_LOG_WARN(
        "xrUpdateGraspTargetVerticesSDFG",
        "grasp target 0x%llx: new vertices refused (%s); it keeps its last accepted shape",
        static_cast<unsigned long long>(id), why.c_str());
  for (const auto& [id, why] : s.grasp->takeSetupFailures())
    SDFG_LOG_WARN(cmd, "grasp target 0x%llx cannot be grasped: its set-up failed (%s)",
                  static_cast<unsigned long long>(id), why.c_str());
}

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
    t->handle = key(*tracker);
    t->runtimeHandle = *tracker;
    t->hand = handOf(info->hand);
    {
      const uint64_t handle = t->handle;
      trackers().insert(handle, std::move(t));
    }
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
  *tracker = fromKey<XrHandTrackerEXT>(t->handle);
  {
    std::lock_guard lock(s->mutex);
    ++s->synthesizedTrackers;
  }
  {
    const uint64_t handle = t->handle;
    trackers().insert(handle, std::move(t));
  }
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
      std::lock_guard lock(s->mutex);
      if (s->grasp == nullptr) return r;
      const HandGrasp& grasp = s->grasp->grasp(t->hand);
      const HandOffset& offset = s->offsets.hands[t->hand == Hand::left ? 0 : 1];
      const bool held = grasp.holding && grasp.solves > 0;
      // Pass-through, untouched, unless a grasp is held or its offset still blends out.
      if (!held && offset.blend <= 0.0f) return r;
      JointPoses joints;
      for (int j = 0; j < kJointCount; ++j) joints[j] = toPose(locations->jointLocations[j].pose);
      const Pose wristFromBase = joints[size_t(Joint::wrist)].inverse();
      JointPoses local;
      for (int j = 0; j < kJointCount; ++j) local[j] = wristFromBase * joints[j];
      Pose baseFromWrist = joints[size_t(Joint::wrist)];
      if (const auto c = s->grasp->reposeCorrection(t->hand)) {
        // A re-solve is on its way: the whole hand follows the target since the shown solve.
        baseFromWrist = baseFromWrist * *c;
        for (int j = 0; j < kJointCount; ++j) {
          joints[j] = baseFromWrist * local[j];
          locations->jointLocations[j].pose = toXr(joints[j]);
        }
      }
      const HandModel& model = s->grasp->model(t->hand);
      FingerJointCurls curls;
      std::array<bool, kFingerCount> replace{};
      if (held) {
        graspCurls(grasp, model.estimateCurls(local), curls, replace);
        replaceFingers(model, curls, replace, baseFromWrist, joints);
      }
      if (offset.blend > 0.0f) {
        // The whole hand moves out of the object, every joint (wrist and palm too).
        applyHandOffset(shownHandOffset(offset), joints);
        for (int j = 0; j < kJointCount; ++j)
          locations->jointLocations[j].pose = toXr(joints[size_t(j)]);
      } else {
        for (int f = 0; f < kFingerCount; ++f) {
          if (!replace[f]) continue;
          for (Joint j : fingerJoints(static_cast<Finger>(f)))
            locations->jointLocations[size_t(j)].pose = toXr(joints[size_t(j)]);
        }
      }
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

  std::unique_lock lock(s->mutex);
  if (s->spaces.count(key(info->baseSpace)) == 0 && info->baseSpace != s->localSpace)
    return logError(XR_ERROR_HANDLE_INVALID, cmd,
                    "(locateInfo->baseSpace) is not a space of this session");
  const int h = t->hand == Hand::left ? 0 : 1;
  std::optional<Pose> grip = locate(inst, s->gripSpaces[h], info->baseSpace, info->time);
  const bool active = grip.has_value() && s->grasp != nullptr;
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
  const HandModel& model = s->grasp->model(t->hand);
  Pose baseFromWrist = *grip * wristFromGrip(model).inverse();
  // A re-solve is on its way: the hand follows the target since the shown solve, so its contacts
  // stay on the surface (docs/threading.md).
  if (const auto c = s->grasp->reposeCorrection(t->hand)) baseFromWrist = baseFromWrist * *c;
  const FingerCurls user = curlsFromSqueeze(s->squeeze[h], range);
  JointPoses joints;
  JointRadii radii;
  placeJoints(model, user, baseFromWrist, joints, radii);
  const HandGrasp& grasp = s->grasp->grasp(t->hand);
  if (grasp.holding && grasp.solves > 0) {
    FingerJointCurls curls;
    std::array<bool, kFingerCount> replace;
    graspCurls(grasp, user, curls, replace);
    replaceFingers(model, curls, replace, baseFromWrist, joints);
  }
  if (const HandOffset& offset = s->offsets.hands[size_t(h)]; offset.blend > 0.0f)
    applyHandOffset(shownHandOffset(offset), joints);
  lock.unlock();
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
