// The layer's grab update, once per sync of its action set (or once per frame while its set is
// not attached: input.cpp): gather, hand over, publish.
//
// 1. Gather, no lock held: the squeeze of each hand (xrGetActionStateFloat, when the layer's set
//    is attached), the hand (the layer's own hand tracker on the runtime, used only when it marks
//    every joint valid; else the grip pose), and where each space that
//    holds placed targets is (one xrLocateSpace per space, whatever the number of targets in it:
//    the engine keeps each target's pose in its space). The spaces are marked in use first, so
//    an xrDestroySpace on another thread waits for these calls instead of the layer passing a
//    destroyed space down.
// 2. Hand over, under the session's lock (microseconds, no call out): the engine's update per
//    hand, the grasp events, the offsets, and a ShownHand per hand published for
//    xrLocateHandJointsEXT.
// 3. After the unlock: the log lines of what the update found, then the GPU pump (the device
//    calls of builds the update recorded).
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "grasp/tracked_squeeze.h"
#include "intercepts.h"
#include "log.h"
#include "state.h"

namespace sdfg::layer {
namespace {

constexpr XrSpaceLocationFlags kValidBits =
    XR_SPACE_LOCATION_ORIENTATION_VALID_BIT | XR_SPACE_LOCATION_POSITION_VALID_BIT;

// Locates `space` in `base`; nothing unless position and orientation are valid.
std::optional<Pose> locate(const InstanceState& inst, XrSpace space, XrSpace base, XrTime time) {
  if (space == XR_NULL_HANDLE || base == XR_NULL_HANDLE) return std::nullopt;
  XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
  if (inst.next.xrLocateSpace(space, base, time, &loc) != XR_SUCCESS) return std::nullopt;
  if ((loc.locationFlags & kValidBits) != kValidBits) return std::nullopt;
  return toPose(loc.pose);
}

// What the gather needs, copied under the lock.
struct Plan {
  XrTime time = 0;
  bool actions = false;  // the layer's set is attached: its squeeze and grips can be read
  XrSpace local = XR_NULL_HANDLE;
  std::array<XrSpace, 2> grips{};
  std::array<XrHandTrackerEXT, 2> trackers{};
  std::array<bool, 2> createTracker{};  // this call asks the runtime for the hand's tracker
  std::array<bool, 2> tracked{};        // the hand may be tracked by the runtime
  std::vector<XrSpace> spaces;          // spaces holding placed targets, marked in use
};

// What the runtime said, for the engine.
struct Gathered {
  std::array<float, 2> squeeze{};
  std::array<bool, 2> squeezeActive{};
  std::array<std::optional<Pose>, 2> grip;  // worldFromGrip
  std::array<bool, 2> trackedValid{};
  std::array<JointPoses, 2> joints{};
  std::array<JointRadii, 2> radii{};
  std::vector<SpaceFrame> spaces;
};

// What planGather() claimed (the uses of spaces, the hands whose tracker this call creates),
// given back whatever happens once they were claimed (an exception in the gather or in the
// engine's update): an xrDestroySpace on another thread waits for the uses to end, and a hand
// left marked as being created would never get its tracker.
class PlanClaims {
 public:
  PlanClaims(SessionState& s, const Plan& plan) : s_(s), plan_(plan) {}
  PlanClaims(const PlanClaims&) = delete;
  PlanClaims& operator=(const PlanClaims&) = delete;
  ~PlanClaims() {
    if (!ended_) {
      std::lock_guard lock(s_.mutex);
      endLocked();
    }
    notify();
  }
  // Gives the claims back; the caller holds the session's lock.
  void endLocked() {
    if (std::exchange(ended_, true)) return;
    for (XrSpace space : plan_.spaces) {
      auto use = s_.spaces.find(key(space));
      if (use != s_.spaces.end() && --use->second.users == 0) released_ = true;
    }
    for (size_t h = 0; h < 2; ++h)
      if (plan_.createTracker[h]) s_.internalTrackerCreating[h] = false;
  }
  // Wakes a destroy waiting for a use that ended; after the unlock.
  void notify() {
    if (std::exchange(released_, false)) s_.spaceReleased.notify_all();
  }

 private:
  SessionState& s_;
  const Plan& plan_;
  bool ended_ = false;
  bool released_ = false;
};

// Whether every joint's position and orientation are valid: the layer uses a runtime's hand only
// then (an invalid joint's pose is whatever the runtime left there, often zero).
bool allJointsValid(const std::array<XrHandJointLocationEXT, XR_HAND_JOINT_COUNT_EXT>& joints) {
  return std::all_of(joints.begin(), joints.end(), [](const XrHandJointLocationEXT& l) {
    return (l.locationFlags & kValidBits) == kValidBits;
  });
}

// Asks the runtime for the layer's own tracker of hand `h` (no lock held) and stores the answer at
// once, so nothing that fails later can lose the handle or leave the hand marked as being created.
XrHandTrackerEXT createInternalTracker(SessionState& s, size_t h, const char* cmd) {
  InstanceState& inst = *s.instance;
  XrHandTrackerCreateInfoEXT info{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
  info.hand = h == 0 ? XR_HAND_LEFT_EXT : XR_HAND_RIGHT_EXT;
  info.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
  XrHandTrackerEXT made = XR_NULL_HANDLE;
  const XrResult r = inst.next.xrCreateHandTrackerEXT(s.handle, &info, &made);
  if (r != XR_SUCCESS) made = XR_NULL_HANDLE;
  {
    std::lock_guard lock(s.mutex);
    // A refusal is remembered for the session (planGather): not retried every frame (each retry
    // is an error line in the runtime's log).
    if (made != XR_NULL_HANDLE)
      s.internalTrackers[h] = made;
    else
      s.internalTrackerRefused[h] = true;
  }
  if (made == XR_NULL_HANDLE)
    SDFG_LOG_INFO(cmd,
                  "the runtime refused a %s hand tracker (%d); that hand follows the controller",
                  h == 0 ? "left" : "right", int(r));
  return made;
}

std::optional<Plan> planGather(SessionState& s) {
  std::lock_guard lock(s.mutex);
  InstanceState& inst = *s.instance;
  if (s.predictedTime == 0 || s.grasp == nullptr || s.localSpace == XR_NULL_HANDLE)
    return std::nullopt;
  Plan p;
  p.time = s.predictedTime;
  p.actions = s.attached;
  p.local = s.localSpace;
  p.grips = s.gripSpaces;
  const bool runtimeHands = inst.downstreamHandTracking &&
                            inst.next.xrLocateHandJointsEXT != nullptr &&
                            !inst.runtimeSystemLacksHands;
  for (size_t h = 0; h < 2; ++h) {
    p.tracked[h] = runtimeHands && !s.internalTrackerRefused[h];
    if (!p.tracked[h]) continue;
    p.trackers[h] = s.internalTrackers[h];
    // One thread asks the runtime for the tracker; a sync on another thread meanwhile does without.
    if (p.trackers[h] == XR_NULL_HANDLE && !s.internalTrackerCreating[h]) {
      s.internalTrackerCreating[h] = true;
      p.createTracker[h] = true;
    }
  }
  for (auto& [space, use] : s.spaces) {
    if (use.targets == 0 || use.dying) continue;
    ++use.users;
    p.spaces.push_back(fromKey<XrSpace>(space));
  }
  return p;
}

// The runtime's answers; no lock held. Only handles the plan named are used.
Gathered gather(SessionState& s, const Plan& p, const char* cmd) {
  InstanceState& inst = *s.instance;
  Gathered g;
  for (size_t h = 0; h < 2; ++h) {
    if (p.actions) {
      XrActionStateGetInfo get{XR_TYPE_ACTION_STATE_GET_INFO};
      get.action = inst.squeezeAction;
      get.subactionPath = inst.handPaths[h];
      XrActionStateFloat state{XR_TYPE_ACTION_STATE_FLOAT};
      g.squeezeActive[h] =
          inst.next.xrGetActionStateFloat(s.handle, &get, &state) == XR_SUCCESS && state.isActive;
      g.squeeze[h] =
          g.squeezeActive[h] && std::isfinite(state.currentState) ? state.currentState : 0.0f;
    }
    const XrHandTrackerEXT tracker =
        p.createTracker[h] ? createInternalTracker(s, h, cmd) : p.trackers[h];
    bool trackerActive = false;
    if (tracker != XR_NULL_HANDLE) {
      std::array<XrHandJointLocationEXT, XR_HAND_JOINT_COUNT_EXT> loc{};
      XrHandJointLocationsEXT locations{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
      locations.jointCount = XR_HAND_JOINT_COUNT_EXT;
      locations.jointLocations = loc.data();
      XrHandJointsLocateInfoEXT info{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
      info.baseSpace = p.local;
      info.time = p.time;
      trackerActive = inst.next.xrLocateHandJointsEXT(tracker, &info, &locations) == XR_SUCCESS &&
                      locations.isActive;
      // A tracked hand with a joint the runtime does not vouch for takes no part this frame, and
      // the app is shown the runtime's joints as they are (hands.cpp).
      if (trackerActive && allJointsValid(loc)) {
        for (int j = 0; j < kJointCount; ++j) {
          g.joints[h][size_t(j)] = toPose(loc[size_t(j)].pose);
          g.radii[h][size_t(j)] = loc[size_t(j)].radius;
        }
        g.trackedValid[h] = true;
      }
    }
    // The controller drives a hand the runtime does not track now, never one it tracks with
    // joints it marks invalid: the app draws that one from the runtime's joints.
    if (!trackerActive && p.actions) g.grip[h] = locate(inst, p.grips[h], p.local, p.time);
  }
  g.spaces.reserve(p.spaces.size());
  for (XrSpace space : p.spaces) {
    SpaceFrame f;
    f.space = key(space);
    if (auto located = locate(inst, space, p.local, p.time)) {
      f.valid = true;
      f.worldFromSpace = *located;
    }
    g.spaces.push_back(f);
  }
  return g;
}

// What the update found, logged after the unlock.
struct UpdateReport {
  std::array<Status, 2> status{Status::ok, Status::ok};
  std::vector<std::pair<uint64_t, MeshSetupReport>> setups;
  std::vector<std::pair<uint64_t, std::string>> refusedUpdates;
  std::vector<std::pair<uint64_t, std::string>> setupFailures;
  std::vector<std::pair<uint64_t, std::string>> readbackNotes;
};

// The engine's update of both hands. The caller holds the lock; nothing here calls out.
void updateHands(SessionState& s, const Gathered& g, UpdateReport& report) {
  for (size_t h = 0; h < 2; ++h) {
    const Hand hand = h == 0 ? Hand::left : Hand::right;
    s.squeeze[h] = g.squeeze[h];
    HandFrame frame;
    frame.squeeze = g.squeeze[h];
    frame.time = s.predictedTime;
    frame.graspOffset = shownHandOffset(s.offsets.hands[h]);
    if (g.trackedValid[h]) {
      frame.valid = true;
      frame.worldFromWrist = g.joints[h][size_t(Joint::wrist)];
      frame.trackedJoints = &g.joints[h];
      frame.trackedRadii = &g.radii[h];
      if (!g.squeezeActive[h]) {
        // A tracked hand without a controller grabs by closing.
        JointPoses local;
        const Pose wristFromWorld = frame.worldFromWrist.inverse();
        for (int j = 0; j < kJointCount; ++j)
          local[size_t(j)] = wristFromWorld * g.joints[h][size_t(j)];
        frame.squeeze = squeezeFromTrackedHand(s.grasp->model(hand), local);
      }
    } else if (g.grip[h]) {
      frame.valid = true;
      frame.worldFromWrist = *g.grip[h] * wristFromGrip(s.grasp->model(hand)).inverse();
    }
    const HandGrasp& before = s.grasp->grasp(hand);
    const bool wasGrasping = before.holdsTarget();
    const uint64_t wasTarget = before.target;
    report.status[h] = s.grasp->update(hand, frame, std::span<const SpaceFrame>(g.spaces));
    noteGraspChange(s, hand, wasGrasping, wasTarget);
    HandOffset& offset = s.offsets.hands[h];
    advanceHandOffset(offset, s.grasp->grasp(hand), s.predictedTime, s.offsets.blendTime);
  }
  publishShownHands(s);
  report.setups = s.grasp->takeSetupReports();
  report.refusedUpdates = s.grasp->takeRefusedUpdates();
  report.setupFailures = s.grasp->takeSetupFailures();
  report.readbackNotes = s.grasp->takeReadbackNotes();
}

void logReport(const InstanceState& inst, const UpdateReport& report, const char* cmd) {
  for (Status st : report.status) {
    if (st == Status::timed_out)
      SDFG_LOG_WARN(cmd,
                    "the grab's SDF build passed its time bound (build_time_limit_ms = %u); the "
                    "hand stays open until it is released",
                    inst.config.buildTimeLimitMs);
    else if (st != Status::ok)
      SDFG_LOG_WARN(cmd, "grasp solve failed (%s); the hand stays open until it is released",
                    toString(st));
  }
  // Set-ups run on the session's worker: one line per target on what its mesh was found to be
  // (split vertices welded, repeated triangles dropped, winding, closed parts), and one per
  // target whose mesh it could not take.
  for (const auto& [id, found] : report.setups) {
    const MeshOrientation& o = found.orientation;
    const std::string weld = found.weld.describe();
    if (o.flipped > 0)
      SDFG_LOG_WARN(cmd,
                    "target %#llx: %s; mesh wound %s, %u triangles flipped to face outward (%u "
                    "parts, %u closed)",
                    static_cast<unsigned long long>(id), weld.c_str(), o.describe(), o.flipped,
                    o.components, o.closedComponents);
    else
      SDFG_LOG_INFO(cmd, "target %#llx: %s; mesh wound %s (%u parts, %u closed)",
                    static_cast<unsigned long long>(id), weld.c_str(), o.describe(), o.components,
                    o.closedComponents);
  }
  for (const auto& [id, why] : report.refusedUpdates)
    SDFG_LOG_WARN(
        "xrUpdateGraspTargetVerticesSDFG",
        "grasp target 0x%llx: new vertices refused (%s); it keeps its last accepted shape",
        static_cast<unsigned long long>(id), why.c_str());
  for (const auto& [id, why] : report.setupFailures)
    SDFG_LOG_WARN(cmd, "grasp target 0x%llx cannot be grasped: its set-up failed (%s)",
                  static_cast<unsigned long long>(id), why.c_str());
  for (const auto& [id, why] : report.readbackNotes)
    SDFG_LOG_WARN(cmd, "grasp target 0x%llx: %s", static_cast<unsigned long long>(id), why.c_str());
}

}  // namespace

void publishShownHands(SessionState& s) {
  if (s.grasp == nullptr) return;
  for (size_t h = 0; h < 2; ++h) {
    const Hand hand = h == 0 ? Hand::left : Hand::right;
    s.shown[h].store(std::make_shared<const ShownHand>(
        takeShownHand(*s.grasp, hand, s.offsets.hands[h], s.squeeze[h])));
  }
}

void syncGrasps(SessionState& s, const char* cmd) {
  const std::optional<Plan> plan = planGather(s);
  if (!plan) return;
  PlanClaims claims(s, *plan);
  const Gathered gathered = gather(s, *plan, cmd);
  UpdateReport report;
  {
    std::lock_guard lock(s.mutex);
    claims.endLocked();
    if (s.grasp != nullptr) updateHands(s, gathered, report);
  }
  claims.notify();
  logReport(*s.instance, report, cmd);
  pumpGpu(s, false);
}

}  // namespace sdfg::layer
