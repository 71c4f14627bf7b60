// Grasp events: what changed for a hand (queued from the grab update, xrDestroyGraspTargetSDFG
// and xrDestroySpace)
// and xrPollEvent's merge of the layer's queue with the runtime's events.
#include "events.h"

#include <cstring>

#include "intercepts.h"
#include "log.h"
#include "state.h"

namespace sdfg::layer {
namespace {

// The time a runtime event carries, if its type has one.
std::optional<XrTime> runtimeEventTime(const XrEventDataBuffer& e) {
  switch (e.type) {
    case XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED:
      return reinterpret_cast<const XrEventDataSessionStateChanged&>(e).time;
    case XR_TYPE_EVENT_DATA_REFERENCE_SPACE_CHANGE_PENDING:
      return reinterpret_cast<const XrEventDataReferenceSpaceChangePending&>(e).changeTime;
    case XR_TYPE_EVENT_DATA_INSTANCE_LOSS_PENDING:
      return reinterpret_cast<const XrEventDataInstanceLossPending&>(e).lossTime;
    default:
      return std::nullopt;
  }
}

// The session a runtime event names, for the core types that name one.
XrSession runtimeEventSession(const XrEventDataBuffer& e) {
  switch (e.type) {
    case XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED:
      return reinterpret_cast<const XrEventDataSessionStateChanged&>(e).session;
    case XR_TYPE_EVENT_DATA_REFERENCE_SPACE_CHANGE_PENDING:
      return reinterpret_cast<const XrEventDataReferenceSpaceChangePending&>(e).session;
    case XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED:
      return reinterpret_cast<const XrEventDataInteractionProfileChanged&>(e).session;
    default:
      return XR_NULL_HANDLE;
  }
}

void copyOut(const XrEventDataGraspChangedSDFG& e, XrEventDataBuffer* out) {
  // The app's buffer is 4000 bytes of varying content: only the event's own bytes are written,
  // as a runtime writes only its event's struct.
  std::memcpy(static_cast<void*>(out), &e, sizeof(e));
}

}  // namespace

void EventQueue::push(const XrEventDataGraspChangedSDFG& event) {
  std::lock_guard lock(mutex_);
  if (events_.size() >= kCapacity) {
    events_.pop_front();
    ++dropped_;
  }
  events_.push_back(event);
}

void EventQueue::dropSession(XrSession session) {
  std::lock_guard lock(mutex_);
  std::erase_if(events_, [&](const auto& e) { return e.session == session; });
  std::erase_if(heldBack_, [&](const auto& e) { return runtimeEventSession(e) == session; });
}

size_t EventQueue::dropped() const {
  std::lock_guard lock(mutex_);
  return dropped_;
}

XrResult EventQueue::poll(PFN_xrPollEvent next, XrInstance instance, XrEventDataBuffer* out) {
  constexpr const char* cmd = "xrPollEvent";
  std::unique_lock lock(mutex_);
  if (events_.empty() && heldBack_.empty()) {
    lock.unlock();
    return next(instance, out);
  }
  lock.unlock();
  if (out == nullptr) return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(eventData) is null");
  if (out->type != XR_TYPE_EVENT_DATA_BUFFER)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(eventData->type) is %d", int(out->type));
  lock.lock();
  if (heldBack_.empty()) {
    // The runtime's next event, asked with no lock held; another thread polling meanwhile may
    // hold one back too: they queue in the order the runtime gave them.
    lock.unlock();
    XrEventDataBuffer e{XR_TYPE_EVENT_DATA_BUFFER};
    const XrResult r = next(instance, &e);
    if (r != XR_SUCCESS && r != XR_EVENT_UNAVAILABLE)
      return r;  // the runtime's error (instance lost ...): the app must see it
    lock.lock();
    if (r == XR_SUCCESS) heldBack_.push_back(e);
  }
  const std::optional<XrTime> runtimeTime =
      heldBack_.empty() ? std::nullopt : runtimeEventTime(heldBack_.front());
  const bool layerFirst =
      !events_.empty() &&
      (heldBack_.empty() || (runtimeTime && events_.front().time < *runtimeTime));
  if (layerFirst) {
    copyOut(events_.front(), out);
    events_.pop_front();
    return XR_SUCCESS;
  }
  if (heldBack_.empty()) {
    // Both queues emptied by another thread meanwhile.
    lock.unlock();
    return next(instance, out);
  }
  *out = heldBack_.front();
  heldBack_.pop_front();
  return XR_SUCCESS;
}

void noteGraspChange(SessionState& s, Hand hand, bool wasGrasping, uint64_t wasTarget,
                     bool destroyed) {
  InstanceState& inst = *s.instance;
  if (!inst.appAutoGrasp || s.grasp == nullptr) return;
  const HandGrasp& g = s.grasp->grasp(hand);
  const bool grasping = !destroyed && g.holdsTarget();
  const uint64_t target = grasping ? g.target : 0;
  XrEventDataGraspChangedSDFG e{XR_TYPE_EVENT_DATA_GRASP_CHANGED_SDFG};
  e.session = s.handle;
  e.hand = hand == Hand::left ? XR_HAND_LEFT_EXT : XR_HAND_RIGHT_EXT;
  e.time = s.predictedTime;
  if (wasGrasping && (!grasping || target != wasTarget)) {
    e.target = appTarget(wasTarget);
    e.isGrasping = XR_FALSE;
    e.reason = destroyed ? XR_GRASP_CHANGE_REASON_TARGET_DESTROYED_SDFG
                         : XR_GRASP_CHANGE_REASON_RELEASED_SDFG;
    inst.events.push(e);
  }
  if (grasping && (!wasGrasping || target != wasTarget)) {
    e.target = appTarget(target);
    e.isGrasping = XR_TRUE;
    e.reason = XR_GRASP_CHANGE_REASON_GRABBED_SDFG;
    inst.events.push(e);
  }
}

XrResult XRAPI_CALL SdfgXrPollEvent(XrInstance instance, XrEventDataBuffer* eventData) {
  constexpr const char* cmd = "xrPollEvent";
  SDFG_ENTRY_BEGIN
  auto inst = instances().find(key(instance));
  if (inst == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(instance) is not valid");
  return inst->events.poll(inst->next.xrPollEvent, instance, eventData);
  SDFG_ENTRY_END(cmd)
}

}  // namespace sdfg::layer
