// Spaces and views. Every pose lives in LOCAL: the head starts at its origin (scripted as
// "head pose"), STAGE is kStageHeight below it, controllers come from the script (grip / aim
// per hand) at the session's current frame. The time argument of locate calls is checked but
// otherwise ignored: tests get exactly the scripted value of the frame they are in.
#include <algorithm>

#include "entry_points.h"
#include "pose_math.h"
#include "system_constants.h"

namespace sdfg::mock {
namespace {

bool supportedReferenceSpace(XrReferenceSpaceType t) {
  return t == XR_REFERENCE_SPACE_TYPE_VIEW || t == XR_REFERENCE_SPACE_TYPE_LOCAL ||
         t == XR_REFERENCE_SPACE_TYPE_STAGE;
}

XrResult verifyReferenceSpaceType(const char* cmd, XrReferenceSpaceType t) {
  if (supportedReferenceSpace(t)) return XR_SUCCESS;
  // Any other value, an extension's or none at all, is a type this runtime does not have (the
  // CTS passes XR_REFERENCE_SPACE_TYPE_MAX_ENUM and expects exactly this).
  return fail(cmd, XR_ERROR_REFERENCE_SPACE_UNSUPPORTED, "reference space %d", int(t));
}

XrResult verifyPose(const char* cmd, const XrPosef& pose) {
  if (!isUnitQuaternion(pose.orientation) || !isFinite(pose.position))
    return fail(cmd, XR_ERROR_POSE_INVALID, "pose is not a unit quaternion and finite position");
  return XR_SUCCESS;
}

XrPosef defaultGrip(Target hand) {
  return XrPosef{{0, 0, 0, 1}, {hand == kLeft ? -0.2f : 0.2f, -0.3f, -0.4f}};
}

}  // namespace

XrPosef headPose(const Session& session) {
  return session.instance->script.pose(kHead, "pose", session.frame()).value_or(identityPose());
}

bool handTracked(const Session& session, Target hand) {
  return session.instance->script.scalar(hand, "tracked", session.frame()).value_or(1.0f) > 0.5f;
}

std::optional<XrPosef> controllerPose(const Session& session, Target hand,
                                      const std::string& which) {
  if (!handTracked(session, hand)) return std::nullopt;
  const Script& script = session.instance->script;
  const uint64_t f = session.frame();
  if (which == "aim") {
    if (auto aim = script.pose(hand, "aim", f)) return aim;
  }
  return script.pose(hand, "grip", f).value_or(defaultGrip(hand));
}

std::optional<XrPosef> spacePoseInLocal(const Session& session, const Space& space) {
  if (!space.isAction) {
    switch (space.referenceType) {
      case XR_REFERENCE_SPACE_TYPE_VIEW:
        return compose(headPose(session), space.offset);
      case XR_REFERENCE_SPACE_TYPE_STAGE:
        return compose(XrPosef{{0, 0, 0, 1}, {0, -kStageHeight, 0}}, space.offset);
      default:
        return space.offset;
    }
  }
  if (!actionActive(session, space.action, space.subactionPath)) return std::nullopt;
  const Binding* binding = poseBinding(session, space.action, space.subactionPath);
  if (binding == nullptr) return std::nullopt;
  const auto pose = controllerPose(session, binding->hand, binding->identifier);
  if (!pose) return std::nullopt;
  return compose(*pose, space.offset);
}

XrResult enumerateReferenceSpaces(XrSession handle, uint32_t capacity, uint32_t* countOutput,
                                  XrReferenceSpaceType* spaces) {
  constexpr const char* cmd = "xrEnumerateReferenceSpaces";
  if (lookup<Session>(handle) == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session");
  static const XrReferenceSpaceType types[] = {
      XR_REFERENCE_SPACE_TYPE_VIEW, XR_REFERENCE_SPACE_TYPE_LOCAL, XR_REFERENCE_SPACE_TYPE_STAGE};
  return twoCall(cmd, capacity, countOutput, spaces, types, 3);
}

XrResult createReferenceSpace(XrSession handle, const XrReferenceSpaceCreateInfo* info,
                              XrSpace* out) {
  constexpr const char* cmd = "xrCreateReferenceSpace";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_REFERENCE_SPACE_CREATE_INFO);
  MOCK_VERIFY_NOT_NULL(cmd, out);
  if (XrResult r = verifyReferenceSpaceType(cmd, info->referenceSpaceType); r != XR_SUCCESS)
    return r;
  if (XrResult r = verifyPose(cmd, info->poseInReferenceSpace); r != XR_SUCCESS) return r;
  auto space = std::make_unique<Space>();
  space->session = session;
  space->referenceType = info->referenceSpaceType;
  space->offset = info->poseInReferenceSpace;
  registerHandle(space.get());
  *out = toHandle<XrSpace>(space.get());
  session->spaces.push_back(std::move(space));
  return XR_SUCCESS;
}

XrResult getReferenceSpaceBoundsRect(XrSession handle, XrReferenceSpaceType type,
                                     XrExtent2Df* bounds) {
  constexpr const char* cmd = "xrGetReferenceSpaceBoundsRect";
  if (lookup<Session>(handle) == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session");
  if (XrResult r = verifyReferenceSpaceType(cmd, type); r != XR_SUCCESS) return r;
  MOCK_VERIFY_NOT_NULL(cmd, bounds);
  if (type == XR_REFERENCE_SPACE_TYPE_STAGE) {
    *bounds = {2.0f, 2.0f};
    return XR_SUCCESS;
  }
  *bounds = {0, 0};
  return XR_SPACE_BOUNDS_UNAVAILABLE;
}

XrResult createActionSpace(XrSession handle, const XrActionSpaceCreateInfo* info, XrSpace* out) {
  constexpr const char* cmd = "xrCreateActionSpace";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_ACTION_SPACE_CREATE_INFO);
  MOCK_VERIFY_NOT_NULL(cmd, out);
  Action* action = lookup<Action>(info->action);
  if (action == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "action is not valid");
  if (action->type != XR_ACTION_TYPE_POSE_INPUT)
    return fail(cmd, XR_ERROR_ACTION_TYPE_MISMATCH, "action '%s' is no pose action",
                action->name.c_str());
  if (info->subactionPath != XR_NULL_PATH) {
    if (session->instance->pathString(info->subactionPath) == nullptr)
      return fail(cmd, XR_ERROR_PATH_INVALID, "subactionPath is not a path");
    const auto& list = action->subactionPaths;
    if (std::find(list.begin(), list.end(), info->subactionPath) == list.end())
      return fail(cmd, XR_ERROR_PATH_UNSUPPORTED, "subactionPath not given at action creation");
  }
  if (XrResult r = verifyPose(cmd, info->poseInActionSpace); r != XR_SUCCESS) return r;
  auto space = std::make_unique<Space>();
  space->session = session;
  space->isAction = true;
  space->action = action;
  space->subactionPath = info->subactionPath;
  space->offset = info->poseInActionSpace;
  registerHandle(space.get());
  *out = toHandle<XrSpace>(space.get());
  session->spaces.push_back(std::move(space));
  return XR_SUCCESS;
}

XrResult locateSpace(XrSpace spaceHandle, XrSpace baseHandle, XrTime time,
                     XrSpaceLocation* location) {
  constexpr const char* cmd = "xrLocateSpace";
  const Space* space = lookup<Space>(spaceHandle);
  const Space* base = lookup<Space>(baseHandle);
  if (space == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "space is not valid");
  if (base == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "baseSpace is not valid");
  if (space->session != base->session)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE,
                "space and baseSpace belong to different sessions");
  MOCK_VERIFY_TYPE(cmd, location, XR_TYPE_SPACE_LOCATION);
  if (time <= 0) return fail(cmd, XR_ERROR_TIME_INVALID, "time %lld", (long long)time);
  const auto a = spacePoseInLocal(*space->session, *space);
  const auto b = spacePoseInLocal(*space->session, *base);
  if (a && b) {
    location->pose = compose(inverse(*b), *a);
    location->locationFlags =
        XR_SPACE_LOCATION_ORIENTATION_VALID_BIT | XR_SPACE_LOCATION_POSITION_VALID_BIT |
        XR_SPACE_LOCATION_ORIENTATION_TRACKED_BIT | XR_SPACE_LOCATION_POSITION_TRACKED_BIT;
  } else {
    location->pose = identityPose();
    location->locationFlags = 0;
  }
  for (auto* p = static_cast<XrBaseOutStructure*>(location->next); p != nullptr; p = p->next) {
    if (p->type == XR_TYPE_SPACE_VELOCITY) {
      auto* v = reinterpret_cast<XrSpaceVelocity*>(p);
      v->velocityFlags = 0;  // the script has no velocities
      v->linearVelocity = {0, 0, 0};
      v->angularVelocity = {0, 0, 0};
    }
  }
  return XR_SUCCESS;
}

XrResult destroySpace(XrSpace handle) {
  Space* space = lookup<Space>(handle);
  if (space == nullptr)
    return fail("xrDestroySpace", XR_ERROR_HANDLE_INVALID, "space is not valid");
  unregisterHandle(space);
  std::erase_if(space->session->spaces, [&](const auto& s) { return s.get() == space; });
  return XR_SUCCESS;
}

XrResult locateViews(XrSession handle, const XrViewLocateInfo* info, XrViewState* viewState,
                     uint32_t capacity, uint32_t* countOutput, XrView* views) {
  constexpr const char* cmd = "xrLocateViews";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_VIEW_LOCATE_INFO);
  MOCK_VERIFY_TYPE(cmd, viewState, XR_TYPE_VIEW_STATE);
  MOCK_VERIFY_NOT_NULL(cmd, countOutput);
  if (info->viewConfigurationType != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO)
    return fail(cmd, XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED, "only PRIMARY_STEREO");
  if (info->displayTime <= 0) return fail(cmd, XR_ERROR_TIME_INVALID, "displayTime");
  const Space* space = lookup<Space>(info->space);
  if (space == nullptr || space->session != session)
    return fail(cmd, XR_ERROR_HANDLE_INVALID, "space is not valid for this session");
  *countOutput = kViewCount;
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < kViewCount) return fail(cmd, XR_ERROR_SIZE_INSUFFICIENT, "capacity %u", capacity);
  MOCK_VERIFY_NOT_NULL(cmd, views);
  for (uint32_t i = 0; i < kViewCount; ++i) {
    if (views[i].type != XR_TYPE_VIEW)
      return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "(views[%u].type) is wrong", i);
  }
  const auto base = spacePoseInLocal(*session, *space);
  viewState->viewStateFlags =
      base ? XR_VIEW_STATE_ORIENTATION_VALID_BIT | XR_VIEW_STATE_POSITION_VALID_BIT |
                 XR_VIEW_STATE_ORIENTATION_TRACKED_BIT | XR_VIEW_STATE_POSITION_TRACKED_BIT
           : 0;
  const XrPosef head = headPose(*session);
  for (uint32_t i = 0; i < kViewCount; ++i) {
    const XrPosef eye = compose(head, XrPosef{{0, 0, 0, 1}, {i == 0 ? -kHalfIpd : kHalfIpd, 0, 0}});
    views[i].pose = base ? compose(inverse(*base), eye) : identityPose();
    views[i].fov = XrFovf{-kHalfFov, kHalfFov, kHalfFov, -kHalfFov};
  }
  return XR_SUCCESS;
}

}  // namespace sdfg::mock
