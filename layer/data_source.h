// XR_EXT_hand_tracking_data_source through the layer. Apps that enable it learn where joints come
// from: the layer's hands synthesized from a controller report
// XR_HAND_TRACKING_DATA_SOURCE_CONTROLLER_EXT. A runtime that has hand tracking and the extension
// answers itself (everything passes through); a runtime with hand tracking but without the
// extension gets neither of its structs, and the layer reports its joints as
// XR_HAND_TRACKING_DATA_SOURCE_UNOBSTRUCTED_EXT (a hand tracked on its own, not through a held
// controller).
#pragma once

#include "state.h"
#include "xr_includes.h"

namespace sdfg::layer {

// Whether the layer answers the extension's structs on this instance (the app enabled it and the
// runtime does not take them).
inline bool layerAnswersDataSource(const InstanceState& inst) {
  return inst.appDataSource && !inst.runtimeDataSource;
}

// Reads the XrHandTrackingDataSourceInfoEXT chained on `info` (when the layer answers it) into
// the tracker's allowed sources. XR_ERROR_VALIDATION_FAILURE for a count of 0, a null array, a
// value that is not a data source, or one listed twice; nothing changes then.
XrResult readDataSourceInfo(const char* cmd, const InstanceState& inst,
                            const XrHandTrackerCreateInfoEXT* info, TrackerState& tracker);

// Takes the struct of `type` out of a `next` chain for the duration of a call down (the runtime
// does not know it) and puts it back when destroyed. Does nothing when `head` is null or the
// chain has no such struct.
class ChainUnlink {
 public:
  ChainUnlink(const void* const* head, XrStructureType type);
  ~ChainUnlink() { restore(); }
  // Puts the struct back now.
  void restore();
  ChainUnlink(const ChainUnlink&) = delete;
  ChainUnlink& operator=(const ChainUnlink&) = delete;

 private:
  const void** link_ = nullptr;    // the pointer that pointed at the struct
  const void* removed_ = nullptr;  // the struct
};

// The layer's answer in the XrHandTrackingDataSourceStateEXT chained on `locations` (when it
// answers): `source`, active when the joints are. When the tracker does not allow `source`, the
// hand is reported inactive (no valid joints), as the extension asks.
void writeDataSourceState(const InstanceState& inst, const TrackerState& tracker,
                          XrHandJointLocationsEXT* locations, XrHandTrackingDataSourceEXT source);

}  // namespace sdfg::layer
