// XR_EXT_hand_tracking: hand trackers that report the script's joint sets (channel "joints"),
// or, without one, a flat open hand whose wrist sits at the hand's grip pose. The extension can
// be offered but unsupported by the system (SDFG_MOCK_HAND_TRACKING=0) or not offered at all
// ("absent"), so a layer's synthesis path meets a runtime with controllers only.
#include <algorithm>

#include "entry_points.h"
#include "pose_math.h"

namespace sdfg::mock {
namespace {

struct TemplateJoint {
  float x, y, z, radius;
};

// Left hand, metres, wrist at the origin, fingers along -Z, back of the hand +Y, thumb +X
// (XR_EXT_hand_tracking axes). Straight fingers, so identity orientations are exact for them.
constexpr TemplateJoint kOpenLeftHand[kJointCount] = {
    {0.000f, 0.000f, -0.048f, 0.020f},   // palm
    {0.000f, 0.000f, 0.000f, 0.025f},    // wrist
    {0.020f, -0.010f, -0.020f, 0.015f},  // thumb metacarpal
    {0.040f, -0.015f, -0.050f, 0.012f},  // thumb proximal
    {0.055f, -0.015f, -0.080f, 0.010f},  // thumb distal
    {0.065f, -0.015f, -0.100f, 0.009f},  // thumb tip
    {0.010f, 0.000f, -0.010f, 0.011f},   // index metacarpal
    {0.022f, 0.000f, -0.085f, 0.010f},   // index proximal
    {0.024f, 0.000f, -0.125f, 0.009f},   // index intermediate
    {0.025f, 0.000f, -0.150f, 0.008f},   // index distal
    {0.025f, 0.000f, -0.172f, 0.007f},   // index tip
    {0.000f, 0.000f, -0.010f, 0.011f},   // middle metacarpal
    {0.002f, 0.000f, -0.088f, 0.010f},   // middle proximal
    {0.002f, 0.000f, -0.133f, 0.009f},   // middle intermediate
    {0.002f, 0.000f, -0.161f, 0.008f},   // middle distal
    {0.002f, 0.000f, -0.185f, 0.007f},   // middle tip
    {-0.010f, 0.000f, -0.010f, 0.010f},  // ring metacarpal
    {-0.018f, 0.000f, -0.083f, 0.009f},  // ring proximal
    {-0.020f, 0.000f, -0.125f, 0.008f},  // ring intermediate
    {-0.021f, 0.000f, -0.151f, 0.007f},  // ring distal
    {-0.021f, 0.000f, -0.173f, 0.006f},  // ring tip
    {-0.018f, 0.000f, -0.012f, 0.009f},  // little metacarpal
    {-0.036f, 0.000f, -0.077f, 0.008f},  // little proximal
    {-0.039f, 0.000f, -0.107f, 0.007f},  // little intermediate
    {-0.040f, 0.000f, -0.125f, 0.006f},  // little distal
    {-0.040f, 0.000f, -0.143f, 0.006f},  // little tip
};

JointSet defaultJoints(const Session& session, Target hand) {
  const Script& script = session.instance->script;
  const XrPosef grip =
      script.pose(hand, "grip", session.frame())
          .value_or(XrPosef{{0, 0, 0, 1}, {hand == kLeft ? -0.2f : 0.2f, -0.3f, -0.4f}});
  JointSet set;
  for (uint32_t j = 0; j < kJointCount; ++j) {
    const TemplateJoint& t = kOpenLeftHand[j];
    // Same axes for both hands (not mirrored): the right hand's thumb is on -X.
    const XrPosef local{{0, 0, 0, 1}, {hand == kLeft ? t.x : -t.x, t.y, t.z}};
    set.pose[j] = compose(grip, local);
    set.radius[j] = t.radius;
  }
  return set;
}

}  // namespace

XrResult createHandTracker(XrSession handle, const XrHandTrackerCreateInfoEXT* info,
                           XrHandTrackerEXT* out) {
  constexpr const char* cmd = "xrCreateHandTrackerEXT";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT);
  MOCK_VERIFY_NOT_NULL(cmd, out);
  if (info->hand != XR_HAND_LEFT_EXT && info->hand != XR_HAND_RIGHT_EXT)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "hand %d", int(info->hand));
  if (info->handJointSet != XR_HAND_JOINT_SET_DEFAULT_EXT)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "handJointSet %d", int(info->handJointSet));
  if (session->instance->handTracking != HandTrackingMode::supported) {
    ++session->stats.handTrackersRefused;
    return fail(cmd, XR_ERROR_FEATURE_UNSUPPORTED, "the system has no hand tracking");
  }
  auto tracker = std::make_unique<HandTracker>();
  tracker->session = session;
  tracker->hand = info->hand;
  registerHandle(tracker.get());
  *out = toHandle<XrHandTrackerEXT>(tracker.get());
  session->handTrackers.push_back(std::move(tracker));
  return XR_SUCCESS;
}

XrResult destroyHandTracker(XrHandTrackerEXT handle) {
  HandTracker* tracker = lookup<HandTracker>(handle);
  if (tracker == nullptr)
    return fail("xrDestroyHandTrackerEXT", XR_ERROR_HANDLE_INVALID, "tracker");
  unregisterHandle(tracker);
  std::erase_if(tracker->session->handTrackers, [&](const auto& t) { return t.get() == tracker; });
  return XR_SUCCESS;
}

XrResult locateHandJoints(XrHandTrackerEXT handle, const XrHandJointsLocateInfoEXT* info,
                          XrHandJointLocationsEXT* locations) {
  constexpr const char* cmd = "xrLocateHandJointsEXT";
  const HandTracker* tracker = lookup<HandTracker>(handle);
  if (tracker == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "hand tracker is not valid");
  Session& session = *tracker->session;
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT);
  MOCK_VERIFY_TYPE(cmd, locations, XR_TYPE_HAND_JOINT_LOCATIONS_EXT);
  const Space* base = lookup<Space>(info->baseSpace);
  if (base == nullptr || base->session != &session)
    return fail(cmd, XR_ERROR_HANDLE_INVALID, "baseSpace is not valid for this session");
  if (info->time <= 0) return fail(cmd, XR_ERROR_TIME_INVALID, "time %lld", (long long)info->time);
  if (locations->jointCount != kJointCount)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "jointCount %u, expected %u",
                locations->jointCount, kJointCount);
  MOCK_VERIFY_NOT_NULL(cmd, locations->jointLocations);
  XrHandJointVelocitiesEXT* velocities = nullptr;
  for (auto* p = static_cast<XrBaseOutStructure*>(locations->next); p != nullptr; p = p->next) {
    if (p->type == XR_TYPE_HAND_JOINT_VELOCITIES_EXT)
      velocities = reinterpret_cast<XrHandJointVelocitiesEXT*>(p);
  }
  if (velocities != nullptr) {
    if (velocities->jointCount != kJointCount)
      return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "velocities jointCount %u",
                  velocities->jointCount);
    MOCK_VERIFY_NOT_NULL(cmd, velocities->jointVelocities);
  }
  const Target hand = tracker->hand == XR_HAND_LEFT_EXT ? kLeft : kRight;
  for (auto* p = static_cast<const XrBaseInStructure*>(info->next); p != nullptr; p = p->next) {
    if (p->type == XR_TYPE_HAND_JOINTS_MOTION_RANGE_INFO_EXT && session.instance->extMotionRange)
      session.stats.lastMotionRange[hand] =
          reinterpret_cast<const XrHandJointsMotionRangeInfoEXT*>(p)->handJointsMotionRange;
  }

  const Script& script = session.instance->script;
  const uint64_t f = session.frame();
  const bool handSeen =
      script.scalar(hand, "hand_tracked", f).value_or(handTracked(session, hand) ? 1.0f : 0.0f) >
      0.5f;
  const auto basePose = spacePoseInLocal(session, *base);
  // Not focused counts as not tracked (XR_EXT_hand_tracking).
  const bool active = handSeen && basePose.has_value() && session.focused();
  locations->isActive = active ? XR_TRUE : XR_FALSE;
  const JointSet joints =
      active ? script.joints(hand, f).value_or(defaultJoints(session, hand)) : JointSet{};
  const XrPosef toBase = active ? inverse(*basePose) : identityPose();
  for (uint32_t j = 0; j < kJointCount; ++j) {
    XrHandJointLocationEXT& l = locations->jointLocations[j];
    if (active) {
      l.pose = compose(toBase, joints.pose[j]);
      l.radius = joints.radius[j];
      l.locationFlags =
          XR_SPACE_LOCATION_ORIENTATION_VALID_BIT | XR_SPACE_LOCATION_POSITION_VALID_BIT |
          XR_SPACE_LOCATION_ORIENTATION_TRACKED_BIT | XR_SPACE_LOCATION_POSITION_TRACKED_BIT;
    } else {
      l.pose = identityPose();
      l.radius = 0;
      l.locationFlags = 0;
    }
    // A runtime that loses one joint of a tracked hand: its pose not valid (and garbage).
    if (active && j == XR_HAND_JOINT_LITTLE_TIP_EXT &&
        session.instance->options.fault == "invalid_joint") {
      l.locationFlags = 0;
      l.pose.orientation = {0, 0, 0, 0};
    }
    if (velocities != nullptr) {
      velocities->jointVelocities[j].velocityFlags = 0;  // the script has no velocities
      velocities->jointVelocities[j].linearVelocity = {0, 0, 0};
      velocities->jointVelocities[j].angularVelocity = {0, 0, 0};
    }
  }
  return XR_SUCCESS;
}

}  // namespace sdfg::mock
