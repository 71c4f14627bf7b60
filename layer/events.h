// The layer's own events (XR_SDFG_auto_grasp version 2: XrEventDataGraspChangedSDFG) and how
// xrPollEvent interleaves them with the runtime's: a small bounded queue per instance, and at
// runtime events held back (at most one per thread polling at once) while an earlier layer event
// goes first. The queue's lock is never held across the runtime's xrPollEvent.
#pragma once

#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>

#include "xr_includes.h"

namespace sdfg::layer {

class EventQueue {
 public:
  // Beyond this many undelivered events the oldest is dropped (an app that never polls must not
  // grow the layer's memory).
  static constexpr size_t kCapacity = 64;

  void push(const XrEventDataGraspChangedSDFG& event);
  // Drops the layer's events of a destroyed session, and a held-back runtime event naming it.
  void dropSession(XrSession session);
  // xrPollEvent: the next event of the layer or the runtime (`next`), in the order the header
  // documents: a layer event goes before a runtime event only when its time is earlier than the
  // runtime event's time; runtime events without a time go first. With no layer event waiting
  // and none held back, the call is the runtime's, untouched.
  XrResult poll(PFN_xrPollEvent next, XrInstance instance, XrEventDataBuffer* out);
  size_t dropped() const;

 private:
  mutable std::mutex mutex_;  // guards everything below
  std::deque<XrEventDataGraspChangedSDFG> events_;
  std::deque<XrEventDataBuffer> heldBack_;  // runtime events polled but not yet returned
  size_t dropped_ = 0;
};

static_assert(sizeof(XrEventDataGraspChangedSDFG) <= sizeof(XrEventDataBuffer),
              "a layer event must fit in XrEventDataBuffer");

}  // namespace sdfg::layer
