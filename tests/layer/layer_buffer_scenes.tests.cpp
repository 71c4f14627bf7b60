// Buffer targets (XrGraspTargetVulkanBuffersSDFG) in scenes, through the loader on lavapipe with
// the Khronos Vulkan validation layer: the layer reads their mesh back and sets it up as it does
// a CPU mesh, so a box in the app's buffers lying on a table is taken, named by the touches,
// stopped on exactly, kept out of the table, followed when the app rewrites it, and kept out of
// an open hand that reaches into it (the outer hand).
#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <thread>

#include "buffer_mesh.h"
#include "grasp_checks.h"
#include "grasp_v2.h"
#include "scene/analytic_shape.h"

namespace {

using namespace sdfg;
using namespace sdfg::test;

const XrPosef kGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
// The 6 x 3 x 10 cm box, lying with its 3 cm toward the palm.
const XrVector3f kHalf{0.03f, 0.015f, 0.05f};
const XrVector3f kTableHalf{0.3f, 0.02f, 0.3f};
// How much lower than belowOpenRightPalm() the box lies so that every located joint's sphere of
// the open hand is clear of it (that function clears the model's finger and palm spheres; the
// thumb's metacarpal joint sphere reaches 8 mm farther).
constexpr float kClear = 0.011f;

XrPosef awayFromPalm(XrPosef p, float d) {
  const glm::vec3 down = openRightHand(kGrip).down;
  p.position = {p.position.x + down.x * d, p.position.y + down.y * d, p.position.z + down.z * d};
  return p;
}

AnalyticShape boxShape(const XrVector3f& half, float scale = 1.0f) {
  return AnalyticShape{ShapeKind::box, scale * glm::vec3(half.x, half.y, half.z)};
}

// A Vulkan app (XR_KHR_vulkan_enable2, the GPU path on) with a controller-only right hand at kGrip
// and the box in its buffers lying on a table under the palm (the table an analytic box, or a
// mesh given as arrays, role SCENE).
struct BufferScene {
  std::unique_ptr<App> app;
  std::unique_ptr<Ext> ext;
  XrHandTrackerEXT tracker = XR_NULL_HANDLE;
  TestMesh mesh = toTestMesh(makeBox(2.0f * glm::vec3(kHalf.x, kHalf.y, kHalf.z)));
  BufferMesh buffers;
  XrPosef boxPose{};
  XrPosef tablePose{};
  XrGraspTargetSDFG box = XR_NULL_HANDLE;
  XrGraspTargetSDFG table = XR_NULL_HANDLE;

  // `lower`: the box (and table) that much farther from the palm than where the open hand's
  // model spheres are 3 mm clear of it (the located joints' spheres reach a little farther).
  // `across`: the box that far across the fingers from the palm (metres).
  explicit BufferScene(bool meshTable, bool withTable = true, float lower = 0.0f,
                       float across = 0.0f) {
    XrEnv env;
    env.handTracking = "absent";
    env.extra = {{"SDFG_AUTOGRASP_GPU", "on"}};
    env.script = gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.0f);
    applyEnv(env);
    app = std::make_unique<App>(
        AppOptions{{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME},
                   true,
                   Graphics::vulkan2});
    REQUIRE(app->ok());
    ext = std::make_unique<Ext>(*app);
    tracker = makeTracker(*app, *ext, XR_HAND_RIGHT_EXT);
    boxPose = awayFromPalm(
        belowOpenRightPalm(mesh, kGrip, facingPalm(kGrip), openRightHand(kGrip).across * across),
        lower);
    buffers = uploadMesh(*app, mesh, 1.0f);
    box = addBuffers(buffers, boxPose);
    int targets = 1;
    if (withTable) {
      // The table's top touches the box's underside: the box rests on it.
      tablePose = awayFromPalm(boxPose, kHalf.y + kTableHalf.y);
      if (meshTable) {
        table = makeTarget(*app, *ext, toTestMesh(makeBox(2.0f * glm::vec3(0.3f, 0.02f, 0.3f))),
                           tablePose);
        auto set = app->fn<PFN_xrSetGraspTargetSettingsSDFG>("xrSetGraspTargetSettingsSDFG");
        XrGraspTargetRoleInfoSDFG r{XR_TYPE_GRASP_TARGET_ROLE_SDFG, nullptr,
                                    XR_GRASP_TARGET_ROLE_SCENE_SDFG};
        XrGraspTargetSettingsSDFG s{XR_TYPE_GRASP_TARGET_SETTINGS_SDFG, &r,
                                    XR_GRASP_HAND_LEFT_BIT_SDFG | XR_GRASP_HAND_RIGHT_BIT_SDFG};
        REQUIRE(set(table, &s) == XR_SUCCESS);
      } else {
        table = makeShapeTarget(*app, *ext, XR_GRASP_SHAPE_TYPE_BOX_SDFG, kTableHalf, tablePose,
                                XR_GRASP_TARGET_ROLE_SCENE_SDFG);
      }
      ++targets;
    }
    waitReady(targets);
  }

  XrGraspTargetSDFG addBuffers(const BufferMesh& m, const XrPosef& pose) const {
    XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG, &m.desc};
    ci.placement = {XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, app->local, pose};
    XrGraspTargetSDFG t = XR_NULL_HANDLE;
    REQUIRE(ext->create(app->session, &ci, &t) == XR_SUCCESS);
    return t;
  }

  // A buffer target counts as pending until its mesh is read back and set up.
  void waitReady(int targets) const {
    REQUIRE(runUntil(*app, [&] {
      const XrGraspTargetsSetupInfoSDFG s = setupInfo(*app, *ext);
      return s.readyCount == uint32_t(targets) && s.pendingCount == 0;
    }));
  }

  void squeezeNow() const {
    REQUIRE(app->setScript(gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.0f) +
                           squeezeLine(app->framesEnded + 1, "right", 1.0f)) == XR_SUCCESS);
  }

  struct State {
    XrGraspStateSDFG state{XR_TYPE_GRASP_STATE_SDFG};
    XrGraspTouchesSDFG touches{XR_TYPE_GRASP_TOUCHES_SDFG};
    XrGraspContactsSDFG contacts{XR_TYPE_GRASP_CONTACTS_SDFG};
  };
  State state() const {
    State s;
    s.state.next = &s.touches;
    s.touches.next = &s.contacts;
    XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
    REQUIRE(ext->state(app->session, &gi, &s.state) == XR_SUCCESS);
    return s;
  }
  Joints joints() const {
    Joints j;
    REQUIRE(locateJoints(*app, tracker, j) == XR_SUCCESS);
    return j;
  }
};

// Every finger that touches the box has an exact contact whose distance is the box's (scaled
// by `scale`) signed distance at the contact sphere's centre, within `tolerance`.
bool exactOnBox(const BufferScene::State& s, XrGraspTargetSDFG box, float scale, float tolerance) {
  if (!s.state.isGrasping || s.state.target != box) return false;
  int touching = 0;
  for (int f = 0; f < 5; ++f) {
    if (s.touches.touched[f] != box) continue;
    const XrGraspFingerContactSDFG& c = s.contacts.fingers[f];
    if (!c.isExact) return false;
    const glm::vec3 p(c.sphereCenter.x, c.sphereCenter.y, c.sphereCenter.z);
    if (std::abs(boxShape(kHalf, scale).signedDistance(p) - c.distance) > tolerance) return false;
    ++touching;
  }
  return touching >= 1;
}

// The grip script of a hand that goes `steps` frames down along the open palm's normal from
// kGrip, `step` metres a frame, from the app's next frame on, squeezing `squeeze` throughout.
std::string reachDown(const App& app, int steps, float step, float squeeze) {
  const glm::vec3 down = openRightHand(kGrip).down;
  std::string script = squeezeLine(0, "right", squeeze);
  for (int k = 0; k <= steps; ++k) {
    const glm::vec3 d = down * (step * float(k));
    const XrPosef grip{kGrip.orientation,
                       {kGrip.position.x + d.x, kGrip.position.y + d.y, kGrip.position.z + d.z}};
    script += gripLine(app.framesEnded + 1 + uint64_t(k), "right", grip);
  }
  return script;
}

// Runs `frames` frames 11 ms apart (90 Hz); `inFrame()` runs in each between the sync and the
// frame's end, where an app locates its hands.
template <class F>
void pacedFrames(App& app, int frames, F inFrame) {
  auto next = std::chrono::steady_clock::now();
  for (int k = 0; k < frames; ++k) {
    next += std::chrono::microseconds(11111);
    std::this_thread::sleep_until(next);
    const uint64_t ended = app.framesEnded;
    app.frame(inFrame);
    REQUIRE(app.framesEnded == ended + 1);
  }
}

// Runs `body` with the Vulkan validation layer watching: no message from it, nor from the
// OpenXR core validation layer, while the scene lived.
template <class F>
void validated(F body) {
  const size_t messagesBefore = vulkanMessages().size();
  body();
  CHECK(validationLog().empty());
  CHECK(vulkanMessages().size() == messagesBefore);
}

// Squeezes and waits until the box is held with exact contacts on it.
void graspBox(const BufferScene& scene) {
  scene.squeezeNow();
  REQUIRE(runUntil(*scene.app, [&] { return exactOnBox(scene.state(), scene.box, 1.0f, 1e-4f); }));
}

}  // namespace

TEST_CASE("A box in the app's buffers lying on a table is taken and stopped on as a CPU mesh is",
          "[layer][vulkan][scenes]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  const bool meshTable = GENERATE(false, true);
  CAPTURE(meshTable);
  validated([&] {
    BufferScene scene(meshTable, true, kClear);
    graspBox(scene);
    const BufferScene::State s = scene.state();
    // Taken, and named by the fingers on it (each finger names what it touches).
    CHECK(s.state.target == scene.box);
    std::map<XrGraspTargetSDFG, int> on;
    for (XrGraspTargetSDFG t : s.touches.touched)
      if (t != XR_NULL_HANDLE) ++on[t];
    CHECK(on[scene.box] >= 1);
    for (const auto& [t, n] : on) CHECK((t == scene.box || t == scene.table));
    // No hand part in the table, none in the box past the exact stop's 0.5 mm.
    const Joints j = scene.joints();
    CHECK(depthInBox(j, boxShape(kTableHalf), scene.tablePose) <= 0.001f);
    CHECK(depthInBox(j, boxShape(kHalf), scene.boxPose) <= 0.0005f);
  });
}

TEST_CASE("A box in the app's buffers held on a table follows what the app writes into them",
          "[layer][vulkan][scenes]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  validated([&] {
    BufferScene scene(/*meshTable=*/false, true, kClear);
    graspBox(scene);
    auto update =
        scene.app->fn<PFN_xrUpdateGraspTargetVerticesSDFG>("xrUpdateGraspTargetVerticesSDFG");
    // The box grows about its centre in two steps (a skinned mesh's new poses), into the hand. Each
    // step is written while nothing of the GPU reads the buffers (the hand holds still, and the
    // last readback is in), then said with an update; the held grasp follows once it is read back.
    for (const float scale : {1.05f, 1.1f}) {
      CAPTURE(scale);
      writeVertices(scene.buffers, scene.mesh, scale);
      REQUIRE(update(scene.box, &scene.buffers.desc) == XR_SUCCESS);
      REQUIRE(
          runUntil(*scene.app, [&] { return exactOnBox(scene.state(), scene.box, scale, 1e-4f); }));
      const Joints j = scene.joints();
      CHECK(depthInBox(j, boxShape(kHalf, scale), scene.boxPose) <= 0.0005f);
      CHECK(depthInBox(j, boxShape(kTableHalf), scene.tablePose) <= 0.001f);
    }
  });
}

TEST_CASE("The outer hand keeps an open hand out of a box in the app's buffers it reaches into",
          "[layer][vulkan][outer_hand]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  validated([&] {
    BufferScene scene(/*meshTable=*/false, /*withTable=*/false, /*lower=*/kClear + 0.004f);
    // Down from 7 mm clear of the box to 1.5 cm into it, 2 mm a frame, then still; squeeze 0.
    const int steps = 11;
    REQUIRE(scene.app->setScript(reachDown(*scene.app, steps, 0.002f, 0.0f)) == XR_SUCCESS);
    float deepest = -1.0f, startDepth = 1.0f;
    int k = 0;
    pacedFrames(*scene.app, steps + 21, [&] {
      Joints j;
      REQUIRE(locateJoints(*scene.app, scene.tracker, j) == XR_SUCCESS);
      const float depth = depthInBox(j, boxShape(kHalf), scene.boxPose);
      if (k++ == 0) startDepth = depth;
      deepest = std::max(deepest, depth);
    });
    // Clear at the start; the tracked hand ended 1.5 cm inside, the shown one stayed on the box.
    CHECK(startDepth < 0.0f);
    CHECK(deepest <= 0.001f);
  });
}

TEST_CASE("A box in the app's buffers carried down into the table it lay on stays on the table",
          "[layer][vulkan][outer_hand]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  validated([&] {
    BufferScene scene(/*meshTable=*/false, true, kClear);
    graspBox(scene);
    // The hand, still squeezing, goes 2 cm down into the table, 2 mm a frame.
    const int steps = 10;
    REQUIRE(scene.app->setScript(reachDown(*scene.app, steps, 0.002f, 1.0f)) == XR_SUCCESS);
    // Where the app draws the box it carries: the shown palm times palmFromTarget; its corners
    // against the table's top.
    const Pose tableFromLocal = toPose(scene.tablePose).inverse();
    const AnalyticShape table = boxShape(kTableHalf);
    float deepest = -1.0f;
    int held = 0;
    pacedFrames(*scene.app, steps + 21, [&] {
      Joints j;
      REQUIRE(locateJoints(*scene.app, scene.tracker, j) == XR_SUCCESS);
      XrGraspHeldPoseSDFG pose{XR_TYPE_GRASP_HELD_POSE_SDFG};
      XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG, &pose};
      XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
      REQUIRE(scene.ext->state(scene.app->session, &gi, &st) == XR_SUCCESS);
      if (!pose.isValid) return;
      ++held;
      const Pose localFromBox =
          toPose(j.joints[XR_HAND_JOINT_PALM_EXT].pose) * toPose(pose.palmFromTarget);
      for (int c = 0; c < 8; ++c) {
        const glm::vec3 corner((c & 1 ? 1 : -1) * kHalf.x, (c & 2 ? 1 : -1) * kHalf.y,
                               (c & 4 ? 1 : -1) * kHalf.z);
        const glm::vec3 p = tableFromLocal.transformPoint(localFromBox.transformPoint(corner));
        deepest = std::max(deepest, -table.signedDistance(p));
      }
    });
    CHECK(held > steps);  // held all along
    // The tracked hand carried it 2 cm in; the shown one keeps it on the table.
    CHECK(deepest <= 0.001f);
  });
}

TEST_CASE(
    "A box in the app's buffers beside another in its buffers or on the CPU: one is taken, "
    "neither is entered",
    "[layer][vulkan][scenes]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  const bool otherOnCpu = GENERATE(false, true);
  CAPTURE(otherOnCpu);
  validated([&] {
    // 2 cm apart across the fingers, each 6 cm wide: the palm faces the gap's edge of one.
    BufferScene scene(/*meshTable=*/false, /*withTable=*/false, kClear, -0.04f);
    const XrPosef otherPose = awayFromPalm(belowOpenRightPalm(scene.mesh, kGrip, facingPalm(kGrip),
                                                              openRightHand(kGrip).across * 0.04f),
                                           kClear);
    BufferMesh otherBuffers;
    XrGraspTargetSDFG other = XR_NULL_HANDLE;
    if (otherOnCpu) {
      other = makeTarget(*scene.app, *scene.ext, scene.mesh, otherPose);
    } else {
      otherBuffers = uploadMesh(*scene.app, scene.mesh, 1.0f);
      other = scene.addBuffers(otherBuffers, otherPose);
    }
    scene.waitReady(2);  // both set up (buffers: read back, one readback at a time)
    scene.squeezeNow();
    BufferScene::State s;
    REQUIRE(runUntil(*scene.app, [&] {
      s = scene.state();
      return s.state.isGrasping == XR_TRUE && s.state.target != XR_NULL_HANDLE;
    }));
    CHECK((s.state.target == scene.box || s.state.target == other));
    // Every finger names one of the two boxes or nothing, and a finger on a box is exact.
    int touching = 0;
    for (int f = 0; f < 5; ++f) {
      const XrGraspTargetSDFG t = s.touches.touched[f];
      CHECK((t == XR_NULL_HANDLE || t == scene.box || t == other));
      if (t != XR_NULL_HANDLE) ++touching;
    }
    CHECK(touching >= 1);
    const Joints j = scene.joints();
    CHECK(depthInBox(j, boxShape(kHalf), scene.boxPose) <= 0.0005f);
    CHECK(depthInBox(j, boxShape(kHalf), otherPose) <= 0.0005f);
  });
}

TEST_CASE("A box in the app's buffers that the app grows into a still open hand pushes it out",
          "[layer][vulkan][outer_hand]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  validated([&] {
    // The open hand 3 mm clear of the box, squeeze 0; the app grows the box about its centre,
    // 0.5 mm a frame toward the palm (a skinned mesh's new poses), to 6 mm past where the hand
    // started, each step written and said with an update.
    BufferScene scene(/*meshTable=*/false, /*withTable=*/false, kClear + 0.003f);
    auto update =
        scene.app->fn<PFN_xrUpdateGraspTargetVerticesSDFG>("xrUpdateGraspTargetVerticesSDFG");
    const int steps = 18;
    float scale = 1.0f, startDepth = 1.0f, deepest = -1.0f;
    int k = 0;
    pacedFrames(*scene.app, steps + 30, [&] {
      if (k > 0 && k <= steps) {
        scale = 1.0f + float(k) * 0.0005f / kHalf.y;
        writeVertices(scene.buffers, scene.mesh, scale);
        REQUIRE(update(scene.box, &scene.buffers.desc) == XR_SUCCESS);
      }
      Joints j;
      REQUIRE(locateJoints(*scene.app, scene.tracker, j) == XR_SUCCESS);
      const float depth = depthInBox(j, boxShape(kHalf, scale), scene.boxPose);
      if (k == 0) startDepth = depth;
      deepest = std::max(deepest, depth);
      ++k;
    });
    std::printf("growing buffer box: shown hand at most %.2f mm inside (started %.2f mm clear)\n",
                1000.0f * deepest, -1000.0f * startDepth);
    CHECK(startDepth < 0.0f);
    // The tracked hand ends 3 mm inside the grown box; the shown one is pushed out with it (a
    // readback behind the app's write: up to 1.5 mm while it grows).
    CHECK(deepest <= 0.0015f);
    Joints j;
    REQUIRE(locateJoints(*scene.app, scene.tracker, j) == XR_SUCCESS);
    CHECK(depthInBox(j, boxShape(kHalf, scale), scene.boxPose) <= 0.001f);
  });
}
