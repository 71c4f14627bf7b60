#include "data_source.h"

#include <span>

#include "intercepts.h"
#include "log.h"

namespace sdfg::layer {

XrResult readDataSourceInfo(const char* cmd, const InstanceState& inst,
                            const XrHandTrackerCreateInfoEXT* info, TrackerState& tracker) {
  if (!layerAnswersDataSource(inst) || info == nullptr) return XR_SUCCESS;
  const auto* ds = findInChain<const XrHandTrackingDataSourceInfoEXT>(
      info->next, XR_TYPE_HAND_TRACKING_DATA_SOURCE_INFO_EXT);
  if (ds == nullptr) return XR_SUCCESS;  // no preference: every source
  if (ds->requestedDataSourceCount == 0)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(requestedDataSourceCount) is 0");
  if (ds->requestedDataSources == nullptr)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(requestedDataSources) is null");
  bool unobstructed = false, controller = false;
  for (uint32_t i = 0; i < ds->requestedDataSourceCount; ++i) {
    // Checked as an integer: an out-of-range value is not a valid enumerant to compare.
    const int32_t v = static_cast<int32_t>(ds->requestedDataSources[i]);
    bool* seen = v == XR_HAND_TRACKING_DATA_SOURCE_UNOBSTRUCTED_EXT ? &unobstructed
                 : v == XR_HAND_TRACKING_DATA_SOURCE_CONTROLLER_EXT ? &controller
                                                                    : nullptr;
    if (seen == nullptr)
      return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(requestedDataSources[%u]) is %d", i, v);
    if (*seen)
      return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(requestedDataSources[%u]) repeats %d", i,
                      v);
    *seen = true;
  }
  tracker.allowUnobstructed = unobstructed;
  tracker.allowController = controller;
  return XR_SUCCESS;
}

ChainUnlink::ChainUnlink(const void* const* head, XrStructureType type) {
  if (head == nullptr) return;
  // The chain's structs belong to the app, which keeps them alive during its call; each link is
  // a `next` pointer at the same offset of an XrBaseInStructure.
  auto** link = const_cast<const void**>(head);
  for (int guard = 0; *link != nullptr && guard < 64; ++guard) {
    const auto* s = static_cast<const XrBaseInStructure*>(*link);
    if (s->type == type) {
      link_ = link;
      removed_ = s;
      *link = s->next;
      return;
    }
    link = reinterpret_cast<const void**>(const_cast<const XrBaseInStructure**>(&s->next));
  }
}

void ChainUnlink::restore() {
  if (link_ != nullptr) *link_ = removed_;
  link_ = nullptr;
}

void writeDataSourceState(const InstanceState& inst, const TrackerState& tracker,
                          XrHandJointLocationsEXT* locations, XrHandTrackingDataSourceEXT source) {
  if (!layerAnswersDataSource(inst) || locations == nullptr) return;
  const bool allowed = source == XR_HAND_TRACKING_DATA_SOURCE_CONTROLLER_EXT
                           ? tracker.allowController
                           : tracker.allowUnobstructed;
  if (!allowed && locations->isActive) {
    locations->isActive = XR_FALSE;
    if (locations->jointLocations != nullptr) {
      for (auto& l : std::span(locations->jointLocations, locations->jointCount)) {
        l.locationFlags = 0;
        l.pose = XrPosef{{0, 0, 0, 1}, {0, 0, 0}};
        l.radius = 0;
      }
    }
    if (auto* v = findInChain<XrHandJointVelocitiesEXT>(locations->next,
                                                        XR_TYPE_HAND_JOINT_VELOCITIES_EXT);
        v != nullptr && v->jointVelocities != nullptr) {
      for (auto& j : std::span(v->jointVelocities, v->jointCount)) j.velocityFlags = 0;
    }
  }
  if (auto* st = findInChain<XrHandTrackingDataSourceStateEXT>(
          locations->next, XR_TYPE_HAND_TRACKING_DATA_SOURCE_STATE_EXT)) {
    st->isActive = locations->isActive;
    st->dataSource = source;
  }
}

}  // namespace sdfg::layer
