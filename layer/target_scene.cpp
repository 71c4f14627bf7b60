// XR_SDFG_auto_grasp version 3, scenes: a target's placement as the engine and the per-frame
// gather know it, its role, analytic shapes, and what each finger touches.
#include "intercepts.h"
#include "log.h"
#include "state.h"

namespace sdfg::layer {

void placeTarget(SessionState& s, TargetState& t, XrSpace space, const XrPosef& pose) {
  if (t.placed && t.space != XR_NULL_HANDLE) {
    if (auto use = s.spaces.find(key(t.space)); use != s.spaces.end()) --use->second.targets;
  }
  t.space = space;
  t.pose = pose;
  t.placed = true;
  if (auto use = s.spaces.find(key(space)); use != s.spaces.end()) ++use->second.targets;
  if (s.grasp != nullptr) (void)s.grasp->placeTarget(t.handle, key(space), toPose(pose));
}

void unplaceTarget(SessionState& s, TargetState& t) {
  if (t.placed && t.space != XR_NULL_HANDLE) {
    if (auto use = s.spaces.find(key(t.space)); use != s.spaces.end()) --use->second.targets;
  }
  t.placed = false;
  t.space = XR_NULL_HANDLE;
  if (s.grasp != nullptr) (void)s.grasp->unplaceTarget(t.handle);
}

XrResult verifyTargetRole(const char* cmd, const XrGraspTargetRoleInfoSDFG* role) {
  if (role == nullptr) return XR_SUCCESS;
  const int32_t value = rawEnum(role->role);
  if (value < int32_t(XR_GRASP_TARGET_ROLE_GRASPABLE_SDFG) ||
      value > int32_t(XR_GRASP_TARGET_ROLE_IGNORED_SDFG))
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd,
                    "(role->role) is %d: not GRASPABLE (0), SCENE (1) or IGNORED (2)", int(value));
  return XR_SUCCESS;
}

void applyTargetRole(SessionState& s, uint64_t target, const XrGraspTargetRoleInfoSDFG* role) {
  if (role == nullptr || s.grasp == nullptr) return;
  const TargetRole r = role->role == XR_GRASP_TARGET_ROLE_SCENE_SDFG     ? TargetRole::scene
                       : role->role == XR_GRASP_TARGET_ROLE_IGNORED_SDFG ? TargetRole::ignored
                                                                         : TargetRole::graspable;
  (void)s.grasp->setTargetRole(target, r);
}

XrResult readShape(const char* cmd, const XrGraspTargetShapeSDFG* in, AnalyticShape& out) {
  const int32_t type = rawEnum(in->shapeType);
  if (type != int32_t(XR_GRASP_SHAPE_TYPE_BOX_SDFG) &&
      type != int32_t(XR_GRASP_SHAPE_TYPE_PLANE_SDFG))
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd,
                    "(shape->shapeType) is %d: not BOX (1) or PLANE (2)", int(type));
  AnalyticShape shape;
  shape.kind = type == int32_t(XR_GRASP_SHAPE_TYPE_BOX_SDFG) ? ShapeKind::box : ShapeKind::plane;
  shape.halfExtents = glm::vec3(in->halfExtents.x, in->halfExtents.y, in->halfExtents.z);
  if (auto e = shape.validate())
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(shape->halfExtents) is (%g, %g, %g): %s",
                    double(in->halfExtents.x), double(in->halfExtents.y), double(in->halfExtents.z),
                    e->message.c_str());
  out = shape;
  return XR_SUCCESS;
}

void writeTouches(const HandGrasp& g, XrGraspTouchesSDFG& out) {
  out.isClosed = g.shown() ? XR_TRUE : XR_FALSE;
  for (int f = 0; f < kFingerCount; ++f) {
    const uint64_t t = g.shown() ? g.touched[size_t(f)] : 0;
    out.touched[f] = appTarget(t);
  }
}

}  // namespace sdfg::layer
