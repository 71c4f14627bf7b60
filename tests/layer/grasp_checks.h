// Checks shared by the grasp tests of the layer (CPU and Vulkan paths): the extension's
// functions, trackers and targets, and the finger-contact checks every grasp must pass (each
// finger in contact ends within 2 mm of the surface, no tip inside the object).
#pragma once

#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <thread>

#include "test_scenes.h"
#include "xr_harness.h"

namespace sdfg::test {

// The extension's functions (and the hand tracker's), as the app gets them.
struct Ext {
  PFN_xrCreateGraspTargetSDFG create;
  PFN_xrDestroyGraspTargetSDFG destroy;
  PFN_xrUpdateGraspTargetVerticesSDFG update;
  PFN_xrSetGraspTargetPlacementSDFG place;
  PFN_xrGetGraspStateSDFG state;
  PFN_xrSetGraspOptionsSDFG options;
  PFN_xrCreateHandTrackerEXT createTracker;
  explicit Ext(const App& app)
      : create(app.fn<PFN_xrCreateGraspTargetSDFG>("xrCreateGraspTargetSDFG")),
        destroy(app.fn<PFN_xrDestroyGraspTargetSDFG>("xrDestroyGraspTargetSDFG")),
        update(app.fn<PFN_xrUpdateGraspTargetVerticesSDFG>("xrUpdateGraspTargetVerticesSDFG")),
        place(app.fn<PFN_xrSetGraspTargetPlacementSDFG>("xrSetGraspTargetPlacementSDFG")),
        state(app.fn<PFN_xrGetGraspStateSDFG>("xrGetGraspStateSDFG")),
        options(app.fn<PFN_xrSetGraspOptionsSDFG>("xrSetGraspOptionsSDFG")),
        createTracker(app.fn<PFN_xrCreateHandTrackerEXT>("xrCreateHandTrackerEXT")) {}
  // Every grasp function was handed out.
  bool ok() const { return create && destroy && update && place && state && options; }
};

inline XrHandTrackerEXT makeTracker(const App& app, const Ext& ext, XrHandEXT hand) {
  XrHandTrackerCreateInfoEXT ci{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
  ci.hand = hand;
  ci.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
  XrHandTrackerEXT t = XR_NULL_HANDLE;
  REQUIRE(ext.createTracker(app.session, &ci, &t) == XR_SUCCESS);
  return t;
}

inline XrGraspTargetSDFG makeTarget(const App& app, const Ext& ext, const TestMesh& mesh,
                                    const XrPosef& pose) {
  XrGraspTargetVerticesSDFG v{XR_TYPE_GRASP_TARGET_VERTICES_SDFG};
  v.vertexCount = uint32_t(mesh.vertices.size());
  v.vertices = mesh.vertices.data();
  v.indexCount = uint32_t(mesh.indices.size());
  v.indices = mesh.indices.data();
  XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG, &v};
  ci.placement = {XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, app.local, pose};
  XrGraspTargetSDFG t = XR_NULL_HANDLE;
  REQUIRE(ext.create(app.session, &ci, &t) == XR_SUCCESS);
  return t;
}

// Runs frames until `hand`'s grasp state says `grasping` (the layer solves on its session's
// worker, so a grasp shows some frames after the squeeze, depending on the machine), at most
// `timeout`; returns whether it got there. The sleep is the test's, to give the worker the core.
inline bool framesUntilGrasping(App& app, const Ext& ext, XrHandEXT hand, bool grasping = true,
                                std::chrono::milliseconds timeout = std::chrono::seconds(60)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    app.frame();
    XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, hand};
    XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG};
    if (ext.state(app.session, &gi, &st) != XR_SUCCESS) return false;
    if ((st.isGrasping == XR_TRUE) == grasping) return true;
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

// The session's target set-up counts (XrGraspTargetsSetupInfoSDFG, chained on a state query).
inline XrGraspTargetsSetupInfoSDFG setupInfo(const App& app, const Ext& ext) {
  XrGraspTargetsSetupInfoSDFG setup{XR_TYPE_GRASP_TARGETS_SETUP_INFO_SDFG};
  XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG, &setup};
  XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
  REQUIRE(ext.state(app.session, &gi, &st) == XR_SUCCESS);
  return setup;
}

// Waits, without running frames (so a scripted squeeze waits too), until `done(setupInfo)` holds:
// set-ups run on the session's worker, as long as the machine needs. False after `timeout`.
template <class F>
bool untilSetUp(const App& app, const Ext& ext, F done,
                std::chrono::milliseconds timeout = std::chrono::seconds(60)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done(setupInfo(app, ext))) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// Milliseconds since `start` (steady clock).
inline double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// The bound of a destroy that must stop the worker's work, not wait for it: half the time that
// work took run whole in this process (`wholeMs`). A number written down would be either too
// tight for a loaded machine or a sanitizer (a stop takes tens of milliseconds here, 0.35 s at
// worst with other builds running: docs/threading.md, "Measured") or too loose to tell a stop
// from a wait. Measured, it grows with the load and the sanitizer as the stop does, while a
// destroy that waited would still take about the whole.
inline double destroyBoundMs(double wholeMs) {
  return wholeMs / 2;
}

// How long the worker takes to set `mesh` up, run whole (from xrCreateGraspTargetSDFG's return
// until the target is ready), in a session of its own made with `env`.
inline double wholeSetUpMs(const XrEnv& env, const TestMesh& mesh) {
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  makeTarget(app, ext, mesh, {{0, 0, 0, 1}, {0, 0, -1}});
  const auto start = std::chrono::steady_clock::now();
  REQUIRE(untilSetUp(
      app, ext, [](const auto& s) { return s.readyCount == 1; }, std::chrono::minutes(10)));
  return msSince(start);
}

inline float length(const XrVector3f& v) {
  return std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
}
inline XrVector3f sub(const XrVector3f& a, const XrVector3f& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}

inline constexpr int kTips[5] = {XR_HAND_JOINT_THUMB_TIP_EXT, XR_HAND_JOINT_INDEX_TIP_EXT,
                                 XR_HAND_JOINT_MIDDLE_TIP_EXT, XR_HAND_JOINT_RING_TIP_EXT,
                                 XR_HAND_JOINT_LITTLE_TIP_EXT};

// Clearance of the capsule between two located joints, radii interpolated between theirs, sampled
// at `steps` + 1 points along it, against `distance` (negative inside).
inline float capsuleClearance(const XrHandJointLocationEXT& a, const XrHandJointLocationEXT& b,
                              int steps, const std::function<float(const XrVector3f&)>& distance) {
  float best = std::numeric_limits<float>::infinity();
  for (int s = 0; s <= steps; ++s) {
    const float t = float(s) / float(steps);
    const XrVector3f p{a.pose.position.x + t * (b.pose.position.x - a.pose.position.x),
                       a.pose.position.y + t * (b.pose.position.y - a.pose.position.y),
                       a.pose.position.z + t * (b.pose.position.z - a.pose.position.z)};
    best = std::min(best, distance(p) - (a.radius + t * (b.radius - a.radius)));
  }
  return best;
}

// Smallest clearance of the located hand's surface model: the palm's sphere and every capsule
// between consecutive joints of each finger, metacarpal to tip, against `distance` (negative
// inside). Negative when any part is inside.
inline float wholeHandClearance(const Joints& j,
                                const std::function<float(const XrVector3f&)>& distance) {
  const XrHandJointLocationEXT& palm = j.joints[XR_HAND_JOINT_PALM_EXT];
  float best = distance(palm.pose.position) - palm.radius;
  for (int f = 0; f < 5; ++f) {
    const int first = f == 0 ? XR_HAND_JOINT_THUMB_METACARPAL_EXT : kTips[f] - 4;
    for (int k = first; k < kTips[f]; ++k)
      best = std::min(best, capsuleClearance(j.joints[k], j.joints[k + 1], 16, distance));
  }
  return best;
}

// What a grasp scene ends with: the located joints and the grasp state of the hand.
struct GraspOutcome {
  Joints joints;
  XrGraspStateSDFG state{XR_TYPE_GRASP_STATE_SDFG};
  int contacts = 0;
};

// Clearance of a finger's surface model: the capsules between its located joints, from the
// proximal joint to the tip, radii interpolated between the joints' radii. Negative inside.
inline float fingerClearance(const GraspOutcome& out, int finger,
                             const std::function<float(const XrVector3f&)>& distance) {
  const int first = finger == 0 ? XR_HAND_JOINT_THUMB_PROXIMAL_EXT : kTips[finger] - 3;
  float best = std::numeric_limits<float>::infinity();
  for (int j = first; j < kTips[finger]; ++j)
    best = std::min(best,
                    capsuleClearance(out.joints.joints[j], out.joints.joints[j + 1], 8, distance));
  return best;
}

inline void checkContacts(const GraspOutcome& out,
                          const std::function<float(const XrVector3f&)>& distance,
                          int minContacts = 3) {
  REQUIRE(out.joints.locations.isActive);
  REQUIRE(out.state.isGrasping);
  int contacts = 0;
  for (int f = 0; f < 5; ++f) {
    const XrHandJointLocationEXT& tip = out.joints.joints[kTips[f]];
    const float d = distance(tip.pose.position);
    const float clearance = fingerClearance(out, f, distance);
    CAPTURE(f, d, tip.radius, clearance, out.state.fingers[f].curl);
    // No tip inside the object, in contact or not.
    CHECK(d > 0.0f);
    if (!out.state.fingers[f].inContact) continue;
    ++contacts;
    // The finger touches the surface (with its tip, or its pad for whole-finger strategies):
    // its closest part ends within 2 mm of it, on either side.
    CHECK(std::abs(clearance) <= 0.002f);
  }
  CHECK(contacts >= minContacts);
}

// A controller-only hand at `grip` squeezes (from frame 6) on `mesh` at `objectPose`, until it
// grasps; `resolution`: a grab-box resolution asked through the options (0: the default);
// `sessionNext`: chained into xrCreateSession (a graphics binding the mock runtime ignores).
inline GraspOutcome graspScene(const TestMesh& mesh, const XrPosef& objectPose, const XrPosef& grip,
                               const char* hand = "right", uint32_t resolution = 0,
                               const void* sessionNext = nullptr) {
  XrEnv env;
  env.handTracking = "absent";
  env.script = gripLine(0, hand, grip) + squeezeLine(0, hand, 0.0f) + squeezeLine(4, hand, 0.0f) +
               squeezeLine(6, hand, 1.0f);
  applyEnv(env);
  GraspOutcome out;
  AppOptions options{{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}};
  options.sessionNext = sessionNext;
  App app(options);
  REQUIRE(app.ok());
  Ext ext(app);
  const XrHandEXT xrHand = std::string(hand) == "left" ? XR_HAND_LEFT_EXT : XR_HAND_RIGHT_EXT;
  XrHandTrackerEXT tracker = makeTracker(app, ext, xrHand);
  if (resolution != 0) {
    auto setOptions = app.fn<PFN_xrSetGraspOptionsSDFG>("xrSetGraspOptionsSDFG");
    XrGraspOptionsSDFG o{XR_TYPE_GRASP_OPTIONS_SDFG};
    o.resolution = resolution;
    REQUIRE(setOptions(app.session, &o) == XR_SUCCESS);
  }
  makeTarget(app, ext, mesh, objectPose);
  // The squeeze starts with the target set up: one set up later appears in a half-closed hand,
  // which the outer hand then shows pushed out of it, and the grab starts from there (seen under
  // Wine in one run of ten, a finger 24 mm off the bar).
  REQUIRE(untilSetUp(app, ext, [](const auto& setup) { return setup.readyCount == 1; }));
  REQUIRE(framesUntilGrasping(app, ext, xrHand));
  REQUIRE(locateJoints(app, tracker, out.joints) == XR_SUCCESS);
  XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, xrHand};
  REQUIRE(ext.state(app.session, &gi, &out.state) == XR_SUCCESS);
  CHECK(validationLog().empty());
  return out;
}

}  // namespace sdfg::test
