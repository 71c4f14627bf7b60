// XR_SDFG_auto_grasp version 2: per-target settings (which hands may grasp a target), on
// creation and through xrSetGraspTargetSettingsSDFG (which also takes a version 3 role).
#include "intercepts.h"
#include "log.h"
#include "state.h"

namespace sdfg::layer {
namespace {

constexpr XrGraspHandFlagsSDFG kKnownHands =
    XR_GRASP_HAND_LEFT_BIT_SDFG | XR_GRASP_HAND_RIGHT_BIT_SDFG;

}  // namespace

XrResult verifyTargetSettings(const char* cmd, const XrGraspTargetSettingsSDFG* settings) {
  if (settings == nullptr) return XR_SUCCESS;
  if ((settings->graspableBy & ~kKnownHands) != 0)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd,
                    "(settings->graspableBy) is 0x%llx: unknown bits",
                    static_cast<unsigned long long>(settings->graspableBy));
  return XR_SUCCESS;
}

void applyTargetSettings(SessionState& s, uint64_t target,
                         const XrGraspTargetSettingsSDFG* settings) {
  if (settings == nullptr || s.grasp == nullptr) return;
  (void)s.grasp->setTargetHands(target, (settings->graspableBy & XR_GRASP_HAND_LEFT_BIT_SDFG) != 0,
                                (settings->graspableBy & XR_GRASP_HAND_RIGHT_BIT_SDFG) != 0);
}

XrResult XRAPI_CALL SdfgXrSetGraspTargetSettingsSDFG(XrGraspTargetSDFG target,
                                                     const XrGraspTargetSettingsSDFG* settings) {
  constexpr const char* cmd = "xrSetGraspTargetSettingsSDFG";
  SDFG_ENTRY_BEGIN
  auto t = targets().find(key(target));
  auto s = t == nullptr ? nullptr : t->session.lock();
  if (s == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(target) is not valid");
  if (settings == nullptr) return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(settings) is null");
  if (settings->type != XR_TYPE_GRASP_TARGET_SETTINGS_SDFG)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(settings->type) is %d",
                    int(settings->type));
  if (XrResult r = verifyTargetSettings(cmd, settings); r != XR_SUCCESS) return r;
  // Version 3: a role chained on the settings.
  if (chainLength(settings->next) < 0)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd,
                    "(settings->next) has more than %zu structs: a cycle, or not a chain",
                    kMaxChainLength);
  const auto* role =
      findInChain<const XrGraspTargetRoleInfoSDFG>(settings->next, XR_TYPE_GRASP_TARGET_ROLE_SDFG);
  if (XrResult r = verifyTargetRole(cmd, role); r != XR_SUCCESS) return r;
  bool lost = false;
  {
    std::lock_guard lock(s->mutex);
    lost = s->grasp == nullptr;
    if (!lost) {
      applyTargetSettings(*s, t->handle, settings);
      applyTargetRole(*s, t->handle, role);
    }
  }
  if (lost) return logError(XR_ERROR_HANDLE_INVALID, cmd, "the session is being destroyed");
  return XR_SUCCESS;
  SDFG_ENTRY_END(cmd)
}

}  // namespace sdfg::layer
