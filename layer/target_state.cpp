// XR_SDFG_auto_grasp version 3: a target's own state (xrGetGraspTargetStateSDFG): whether it is
// placed, or its space was destroyed (session.cpp, xrDestroySpace).
#include "intercepts.h"
#include "log.h"
#include "state.h"

namespace sdfg::layer {

XrResult XRAPI_CALL SdfgXrGetGraspTargetStateSDFG(XrGraspTargetSDFG target,
                                                  XrGraspTargetStateSDFG* state) {
  constexpr const char* cmd = "xrGetGraspTargetStateSDFG";
  SDFG_ENTRY_BEGIN
  auto t = targets().find(key(target));
  auto s = t == nullptr ? nullptr : t->session.lock();
  if (s == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(target) is not valid");
  if (state == nullptr) return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(state) is null");
  if (rawEnum(state->type) != int32_t(XR_TYPE_GRASP_TARGET_STATE_SDFG))
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd,
                    "(state->type) is %d, expected XR_TYPE_GRASP_TARGET_STATE_SDFG",
                    int(rawEnum(state->type)));
  if (chainLength(state->next) < 0)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd,
                    "(state->next) has more than %zu structs: a cycle, or not a chain",
                    kMaxChainLength);
  bool placed = false;
  {
    std::lock_guard lock(s->mutex);
    placed = t->placed;
  }
  state->isPlaced = placed ? XR_TRUE : XR_FALSE;
  return XR_SUCCESS;
  SDFG_ENTRY_END(cmd)
}

}  // namespace sdfg::layer
