// The outer hand through the loader (XrGraspOuterHandOptionsSDFG): a hand the controller drives
// into a table top or through a thin plate, squeeze 0, frames paced at 90 Hz. Each scripted
// trajectory runs twice in one process, the outer hand on (the layer's default) and switched off
// through the options: the run with it off is the tracked hand, the one with it on the shown hand.
#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "grasp_v2.h"
#include "scene/analytic_shape.h"

namespace {

using namespace sdfg;
using namespace sdfg::test;

const XrPosef kGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};

XrPosef shifted(XrPosef p, const glm::vec3& d) {
  p.position = {p.position.x + d.x, p.position.y + d.y, p.position.z + d.z};
  return p;
}

// A slab of half extents `half` whose +Y face is 3 mm under the open right hand at kGrip, its
// faces parallel to the palm.
struct Slab {
  XrPosef pose;
  XrVector3f half;
  AnalyticShape shape() const {
    return AnalyticShape{ShapeKind::box, glm::vec3(half.x, half.y, half.z)};
  }
};

Slab slabUnderPalm(const XrVector3f& half) {
  return {boxUnderPalm(kGrip, half), half};
}

// The deepest any joint sphere is inside the slab (negative: the smallest clearance), metres.
float depthIn(const Joints& j, const Slab& slab) {
  return depthInBox(j, slab.shape(), slab.pose);
}

float largestMotion(const Joints& a, const Joints& b) {
  float m = 0.0f;
  for (size_t i = 0; i < a.joints.size(); ++i)
    m = std::max(m, length(sub(a.joints[i].pose.position, b.joints[i].pose.position)));
  return m;
}

bool sameJoints(const Joints& a, const Joints& b) {
  for (size_t i = 0; i < a.joints.size(); ++i) {
    const XrPosef& p = a.joints[i].pose;
    const XrPosef& q = b.joints[i].pose;
    if (p.position.x != q.position.x || p.position.y != q.position.y ||
        p.position.z != q.position.z || p.orientation.x != q.orientation.x ||
        p.orientation.y != q.orientation.y || p.orientation.z != q.orientation.z ||
        p.orientation.w != q.orientation.w)
      return false;
  }
  return true;
}

struct Frame {
  Joints joints;
  XrGraspHandOffsetSDFG offset{XR_TYPE_GRASP_HAND_OFFSET_SDFG};
};

XrResult setOuter(const App& app, const Ext& ext, XrGraspSwitchSDFG on,
                  float releaseDistance = 0.0f, float blendTime = 0.0f) {
  XrGraspOuterHandOptionsSDFG outer{XR_TYPE_GRASP_OUTER_HAND_OPTIONS_SDFG, nullptr, on,
                                    releaseDistance, blendTime};
  XrGraspOptionsSDFG o{XR_TYPE_GRASP_OPTIONS_SDFG, &outer};
  return ext.options(app.session, &o);
}

// One app: a controller-only right hand at `grip`, squeeze 0, a tracker on it and one box target
// of `role` (half extents `half`, at `pose`), run until `frames` frames have ended.
struct StillHandApp {
  std::unique_ptr<App> app;
  std::unique_ptr<Ext> ext;
  XrHandTrackerEXT tracker = XR_NULL_HANDLE;
  XrGraspTargetSDFG target = XR_NULL_HANDLE;

  StillHandApp(const XrPosef& grip, const XrVector3f& half, const XrPosef& pose,
               XrGraspTargetRoleSDFG role, uint64_t frames = 3,
               std::vector<std::pair<std::string, std::string>> extraEnv = {}) {
    XrEnv env;
    env.handTracking = "absent";
    env.extra = std::move(extraEnv);
    env.script = gripLine(0, "right", grip) + squeezeLine(0, "right", 0.0f);
    applyEnv(env);
    app = std::make_unique<App>(
        AppOptions{{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
    REQUIRE(app->ok());
    ext = std::make_unique<Ext>(*app);
    tracker = makeTracker(*app, *ext, XR_HAND_RIGHT_EXT);
    target = makeShapeTarget(*app, *ext, XR_GRASP_SHAPE_TYPE_BOX_SDFG, half, pose, role);
    REQUIRE(app->framesUntil([&] { return app->framesEnded >= frames; }));
  }
};

// One app: a controller-only right hand, a slab target of `role`, the grip following `grips`
// (one pose per frame from the first scripted frame on), frames 11 ms apart; the joints and the
// reported offset per scripted frame. `prepare` runs once the session is running. With `settled`,
// frames go on at the last grip until it holds for the located joints (the worker's late answers
// in, on a loaded machine), and the frame where it did is appended.
template <class Prepare>
std::vector<Frame> drive(const Slab& slab, const std::vector<XrPosef>& grips, Prepare prepare,
                         std::vector<std::pair<std::string, std::string>> extraEnv = {},
                         const std::function<bool(const Joints&)>& settled = {}) {
  StillHandApp still(grips.front(), slab.half, slab.pose, XR_GRASP_TARGET_ROLE_SCENE_SDFG, 3,
                     std::move(extraEnv));
  App& app = *still.app;
  Ext& ext = *still.ext;
  const XrHandTrackerEXT tracker = still.tracker;
  prepare(app, ext);
  std::string script;
  const uint64_t first = app.framesEnded + 1;
  for (size_t k = 0; k < grips.size(); ++k) script += gripLine(first + k, "right", grips[k]);
  REQUIRE(app.setScript(script + squeezeLine(0, "right", 0.0f)) == XR_SUCCESS);
  std::vector<Frame> out(grips.size());
  auto next = std::chrono::steady_clock::now();
  for (Frame& f : out) {
    next += std::chrono::microseconds(11111);
    std::this_thread::sleep_until(next);
    // As an app does: the hand located after the sync, before the frame ends.
    XrResult located = XR_ERROR_RUNTIME_FAILURE, state = XR_ERROR_RUNTIME_FAILURE;
    const uint64_t ended = app.framesEnded;
    app.frame([&] {
      located = locateJoints(app, tracker, f.joints);
      XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG, &f.offset};
      XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
      state = ext.state(app.session, &gi, &st);
    });
    REQUIRE(app.framesEnded == ended + 1);
    REQUIRE(located == XR_SUCCESS);
    REQUIRE(state == XR_SUCCESS);
  }
  if (settled) {
    // Located as above, between the sync and the frame's end.
    Frame last = out.back();
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    bool done = settled(last.joints);
    while (!done && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::microseconds(11111));
      app.frame([&] {
        done = locateJoints(app, tracker, last.joints) == XR_SUCCESS && settled(last.joints);
      });
    }
    CHECK(done);
    out.push_back(last);
  }
  CHECK(validationLog().empty());
  return out;
}

// Down from 3 cm above where the hand touches to 2.7 cm into the table, 2 mm a frame; 10 cm across
// it, 5 mm a frame; still for 20 frames; back up 2 mm a frame.
std::vector<XrPosef> reachIntoTable() {
  const OpenRightHand hand = openRightHand(kGrip);
  std::vector<XrPosef> g;
  for (int k = 0; k <= 30; ++k) g.push_back(shifted(kGrip, hand.down * (-0.03f + 0.002f * k)));
  const XrPosef in = g.back();
  for (int k = 1; k <= 20; ++k) g.push_back(shifted(in, hand.across * (0.005f * k)));
  const XrPosef slid = g.back();
  for (int k = 0; k < 20; ++k) g.push_back(slid);
  for (int k = 1; k <= 30; ++k) g.push_back(shifted(slid, hand.down * (-0.002f * k)));
  return g;
}

auto switchTo(XrGraspSwitchSDFG on) {
  return [on](const App& app, const Ext& ext) { REQUIRE(setOuter(app, ext, on) == XR_SUCCESS); };
}

}  // namespace

TEST_CASE(
    "Outer hand: a hand reaching into a table is shown on it, sliding, and as tracked "
    "while clear",
    "[layer][outer_hand]") {
  const Slab table = slabUnderPalm({0.3f, 0.02f, 0.3f});
  const std::vector<XrPosef> grips = reachIntoTable();
  const std::vector<Frame> tracked = drive(table, grips, switchTo(XR_GRASP_SWITCH_OFF_SDFG));
  const std::vector<Frame> shown = drive(
      table, grips, [](const App&, const Ext&) {}, {},
      [&](const Joints& j) { return sameJoints(j, tracked.back().joints); });
  float trackedDeepest = -1.0f, shownDeepest = -1.0f, jitter = 0.0f;
  int clearFrames = 0, offTracking = 0, late = 0;
  for (size_t k = 0; k < grips.size(); ++k) {
    CAPTURE(k);
    const float trackedDepth = depthIn(tracked[k].joints, table);
    trackedDeepest = std::max(trackedDeepest, trackedDepth);
    shownDeepest = std::max(shownDeepest, depthIn(shown[k].joints, table));
    // Switched off, the hand is tracked and no offset is reported.
    CHECK(tracked[k].offset.offset.position.y == 0.0f);
    // Clear by more than two frames' motion: the shown hand is the tracked hand, exactly. Where the
    // worker answers late (a loaded machine) it is where the last answer put it instead: as shown
    // in the frame before, as tracked in an earlier frame, or, within the three frames of catching
    // up the jitter check below allows too, as answered for a frame that touched.
    if (trackedDepth < -0.005f) {
      ++clearFrames;
      if (!sameJoints(shown[k].joints, tracked[k].joints)) {
        bool earlier = k > 0 && sameJoints(shown[k].joints, shown[k - 1].joints);
        for (size_t j = 0; j < k && !earlier; ++j)
          earlier = sameJoints(shown[k].joints, tracked[j].joints);
        for (size_t j = k > 3 ? k - 3 : 0; j < k && !earlier; ++j)
          earlier = depthIn(tracked[j].joints, table) >= -0.005f;
        ++(earlier ? late : offTracking);
      }
    }
    // The reported offset moves the tracked wrist to the shown one.
    const Pose wrist = toPose(tracked[k].joints.joints[XR_HAND_JOINT_WRIST_EXT].pose) *
                       toPose(shown[k].offset.offset);
    const XrVector3f& shownWrist = shown[k].joints.joints[XR_HAND_JOINT_WRIST_EXT].pose.position;
    CHECK(glm::length(wrist.position - glm::vec3(shownWrist.x, shownWrist.y, shownWrist.z)) <
          1e-4f);
    // Still from frame 51 on; a frame or two to catch up (the shown hand is drawn from the last
    // frame's result until this frame's is in: docs/layer.md, "The outer hand").
    if (k > 53 && k < 71)
      jitter = std::max(jitter, largestMotion(shown[k].joints, shown[k - 1].joints));
  }
  CHECK(trackedDeepest > 0.02f);  // the tracked hand went 2 cm in
  CHECK(shownDeepest <= 0.001f);
  CHECK(clearFrames > 20);
  CAPTURE(late);
  CHECK(offTracking == 0);
  CHECK(jitter <= 0.0001f);
  // It slid along: 10 cm across while inside (frame 30 inside, still up to frame 70).
  const glm::vec3 across = openRightHand(kGrip).across;
  const XrVector3f a = shown[30].joints.joints[XR_HAND_JOINT_PALM_EXT].pose.position;
  const XrVector3f b = shown[70].joints.joints[XR_HAND_JOINT_PALM_EXT].pose.position;
  CHECK(glm::dot(glm::vec3(b.x - a.x, b.y - a.y, b.z - a.z), across) ==
        Approx(0.1f).margin(0.005f));
  // Out again at the end: the tracked hand (drive() waited for it; the frame it saw is last).
  CHECK(sameJoints(shown.back().joints, tracked.back().joints));
}

TEST_CASE("Outer hand: a hand swiped at 2 m/s through a 3 mm plate stays on its side",
          "[layer][outer_hand]") {
  const Slab plate = slabUnderPalm({0.2f, 0.0015f, 0.2f});
  const glm::vec3 down = openRightHand(kGrip).down;
  std::vector<XrPosef> grips;
  // 22 mm a frame, from 1 cm above to 7 cm past the plate (within the 10 cm release distance,
  // past which the hand returns to tracking on purpose), then held there.
  for (int k = 0; k <= 20; ++k)
    grips.push_back(shifted(kGrip, down * (-0.01f + 0.022f * float(std::min(k, 4)))));
  const std::vector<Frame> tracked = drive(plate, grips, switchTo(XR_GRASP_SWITCH_OFF_SDFG));
  const std::vector<Frame> shown = drive(plate, grips, [](const App&, const Ext&) {});
  const Pose plateFromLocal = toPose(plate.pose).inverse();
  float deepest = -1.0f, lowestPalm = 1.0f, trackedLowest = 1.0f;
  for (size_t k = 0; k < grips.size(); ++k) {
    deepest = std::max(deepest, depthIn(shown[k].joints, plate));
    auto height = [&](const Joints& j) {
      const XrVector3f p = j.joints[XR_HAND_JOINT_PALM_EXT].pose.position;
      return plateFromLocal.transformPoint(glm::vec3(p.x, p.y, p.z)).y;
    };
    lowestPalm = std::min(lowestPalm, height(shown[k].joints));
    trackedLowest = std::min(trackedLowest, height(tracked[k].joints));
  }
  CHECK(trackedLowest < -0.03f);  // the tracked palm went through
  CHECK(deepest <= 0.001f);
  CHECK(lowestPalm > 0.0015f);  // the shown one stayed on the near side
}

TEST_CASE("Outer hand: the configuration key and the options switch turn it off",
          "[layer][outer_hand]") {
  const Slab table = slabUnderPalm({0.3f, 0.02f, 0.3f});
  const glm::vec3 down = openRightHand(kGrip).down;
  std::vector<XrPosef> grips;
  for (int k = 0; k <= 15; ++k) grips.push_back(shifted(kGrip, down * (0.002f * float(k))));
  SECTION("outer_hand = false in the configuration") {
    // The environment form of the key (docs/layer.md, "Configuration").
    const std::vector<Frame> off = drive(table, grips, [](const App&, const Ext&) {},
                                         {{"SDFG_AUTOGRASP_OUTER_HAND", "false"}});
    CHECK(depthIn(off.back().joints, table) > 0.02f);
    // ... and the app turns it back on.
    const std::vector<Frame> on = drive(table, grips, switchTo(XR_GRASP_SWITCH_ON_SDFG));
    CHECK(depthIn(on.back().joints, table) <= 0.001f);
  }
  SECTION("a later call without the outer hand's options keeps it off") {
    const std::vector<Frame> off = drive(table, grips, [](const App& app, const Ext& ext) {
      REQUIRE(setOuter(app, ext, XR_GRASP_SWITCH_OFF_SDFG) == XR_SUCCESS);
      XrGraspOptionsSDFG o{XR_TYPE_GRASP_OPTIONS_SDFG};
      o.grabThreshold = 0.7f;
      REQUIRE(ext.options(app.session, &o) == XR_SUCCESS);
    });
    CHECK(depthIn(off.back().joints, table) > 0.02f);
  }
  SECTION("refused options change nothing") {
    const std::vector<Frame> shown = drive(table, grips, [](const App& app, const Ext& ext) {
      // Off together with a bad value: refused, so the outer hand stays on.
      CHECK(setOuter(app, ext, XR_GRASP_SWITCH_OFF_SDFG, -1.0f) == XR_ERROR_VALIDATION_FAILURE);
      CHECK(setOuter(app, ext, XR_GRASP_SWITCH_OFF_SDFG, 0.0f, 3.0f) ==
            XR_ERROR_VALIDATION_FAILURE);
      CHECK(setOuter(app, ext, XR_GRASP_SWITCH_OFF_SDFG, std::nanf("")) ==
            XR_ERROR_VALIDATION_FAILURE);
      CHECK(setOuter(app, ext, XrGraspSwitchSDFG(7)) == XR_ERROR_VALIDATION_FAILURE);
    });
    CHECK(depthIn(shown.back().joints, table) <= 0.001f);
  }
}

TEST_CASE("Outer hand: a table rising into a still open hand pushes it out of its way",
          "[layer][outer_hand]") {
  // The world moves, not the hand (smooth locomotion down a slope, a lift, an object brought to
  // the hand): the app moves the table 3.3 mm a frame (0.3 m/s at 90 Hz) toward the palm, from
  // 3 mm under it to 4.6 cm past where the hand is, then holds it there.
  const Slab start = slabUnderPalm({0.3f, 0.02f, 0.3f});
  const glm::vec3 up = -openRightHand(kGrip).down;
  StillHandApp still(kGrip, start.half, start.pose, XR_GRASP_TARGET_ROLE_SCENE_SDFG);
  App& app = *still.app;
  Ext& ext = *still.ext;
  const XrHandTrackerEXT tracker = still.tracker;
  const XrGraspTargetSDFG table = still.target;
  Slab now = start;
  float deepest = -1.0f;
  auto next = std::chrono::steady_clock::now();
  Joints joints;
  for (int k = 0; k < 30; ++k) {
    next += std::chrono::microseconds(11111);
    std::this_thread::sleep_until(next);
    if (k < 15) {
      now.pose = shifted(start.pose, up * (0.0033f * float(k + 1)));
      XrGraspTargetPlacementSDFG p{XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, app.local,
                                   now.pose};
      REQUIRE(ext.place(table, &p) == XR_SUCCESS);
    }
    XrResult located = XR_ERROR_RUNTIME_FAILURE;
    app.frame([&] { located = locateJoints(app, tracker, joints); });
    REQUIRE(located == XR_SUCCESS);
    deepest = std::max(deepest, depthIn(joints, now));
  }
  // While it moves, the hand is drawn from the worker's last answer: on time, the answer to the
  // frame before (one frame of the table's motion, 3.3 mm); a loaded machine or a sanitizer
  // answers a frame or two later still (5.4 mm seen under ThreadSanitizer). Without the push the
  // hand stays where it was and ends 38 mm in.
  CHECK(deepest <= 0.010f);
  // Once it stops, the hand is out of it (waited for: the worker may answer late).
  bool out = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!out && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::microseconds(11111));
    app.frame([&] {
      out = locateJoints(app, tracker, joints) == XR_SUCCESS && depthIn(joints, now) <= 0.001f;
    });
  }
  CHECK(out);
  CHECK(validationLog().empty());
}

TEST_CASE(
    "Outer hand: a hand that jumps 50 cm is shown at once on a clear pose, and never inside "
    "the table it lands in",
    "[layer][outer_hand]") {
  // A controller-driven hand held 5 cm over a table, then in one frame 50 cm along it (tracking
  // lost and found elsewhere, or the app teleporting the user): onto a pose 5 cm over it, or 1 cm
  // into it. Located as apps do, right after the sync, paced at 90 Hz.
  const Slab table = slabUnderPalm({0.4f, 0.02f, 0.4f});
  const OpenRightHand hand = openRightHand(kGrip);
  const XrPosef from = shifted(kGrip, hand.across * -0.25f - hand.down * 0.05f);
  const bool inside = GENERATE(false, true);
  const XrPosef landing =
      shifted(kGrip, hand.across * 0.25f + hand.down * (inside ? 0.013f : -0.05f));
  StillHandApp still(from, table.half, table.pose, XR_GRASP_TARGET_ROLE_SCENE_SDFG, 10);
  App& app = *still.app;
  const XrHandTrackerEXT tracker = still.tracker;
  REQUIRE(app.setScript(gripLine(app.framesEnded + 1, "right", landing) +
                        squeezeLine(0, "right", 0.0f)) == XR_SUCCESS);
  auto next = std::chrono::steady_clock::now();
  std::vector<Joints> located(60);
  for (Joints& j : located) {
    next += std::chrono::microseconds(11111);
    std::this_thread::sleep_until(next);
    XrResult r = XR_ERROR_RUNTIME_FAILURE;
    app.frame([&] { r = locateJoints(app, tracker, j); });
    REQUIRE(r == XR_SUCCESS);
  }
  int withheld = 0;
  float deepest = -1.0f;
  for (const Joints& j : located) {
    if (!j.locations.isActive) {
      ++withheld;
      // Not tracked this frame: no joint is valid either.
      CHECK(std::all_of(j.joints.begin(), j.joints.end(),
                        [](const XrHandJointLocationEXT& l) { return l.locationFlags == 0; }));
      continue;
    }
    deepest = std::max(deepest, depthIn(j, table));
  }
  std::printf("jump of 50 cm %s: %d of 60 frames withheld, shown at most %.2f mm inside\n",
              inside ? "into the table" : "onto a clear pose", withheld, 1000.0f * deepest);
  CHECK(deepest <= 0.001f);
  CHECK(located.back().locations.isActive);  // the worker placed it within 60 frames
  if (!inside) {
    // The first frame after the jump has no hand but the new one, as the runtime gives it.
    CHECK(withheld == 0);
    CHECK(sameJoints(located.front(), located.back()));
  } else {
    // Where it landed, clear of the table: not back where it jumped from.
    const glm::vec3 wrist = toPose(located.back().joints[XR_HAND_JOINT_WRIST_EXT].pose).position;
    const glm::vec3 want =
        toPose(landing).position;  // the grip; the wrist is a few cm from it, not 50
    CHECK(glm::length(wrist - want) < 0.15f);
  }
  CHECK(validationLog().empty());
}

TEST_CASE(
    "Outer hand: a box brought into a still open hand at 1 m/s pushes it out, and the hand "
    "is the tracked one again once the box is gone",
    "[layer][outer_hand]") {
  // What the other hand carries into this one, or anything the app animates: the app places an
  // 8 cm box each frame, from 20 cm beside the palm to 3 cm past where it meets the hand, 11 mm
  // a frame (1 m/s at 90 Hz), holds it there for 30 frames and takes it away again.
  const OpenRightHand hand = openRightHand(kGrip);
  const XrVector3f half{0.04f, 0.04f, 0.04f};
  const AnalyticShape shape{ShapeKind::box, glm::vec3(0.04f)};
  // Beside the palm along the axis across the fingers (the little finger's side), palm height.
  const Slab under = slabUnderPalm(half);
  const glm::vec3 side = hand.across;
  const glm::vec3 palmLevel = hand.palm - toPose(under.pose).position;
  const XrPosef far = shifted(under.pose, palmLevel + side * 0.20f);
  StillHandApp still(kGrip, half, far, XR_GRASP_TARGET_ROLE_GRASPABLE_SDFG);
  App& app = *still.app;
  Ext& ext = *still.ext;
  const XrHandTrackerEXT tracker = still.tracker;
  const XrGraspTargetSDFG box = still.target;
  Joints before;
  app.frame([&] { REQUIRE(locateJoints(app, tracker, before) == XR_SUCCESS); });
  // Where the box meets the hand: the first offset along -side at which a joint sphere enters it.
  float touch = 0.0f;
  while (touch < 0.2f && depthInBox(before, shape, shifted(far, side * -touch)) < 0.0f)
    touch += 0.0005f;
  REQUIRE(touch < 0.2f);
  std::vector<XrPosef> path;
  for (float d = 0.0f; d < touch + 0.03f; d += 0.011f) path.push_back(shifted(far, side * -d));
  path.push_back(shifted(far, side * -(touch + 0.03f)));
  // The tracked hand (still where `before` was located) is over 2 cm inside the box there.
  REQUIRE(depthInBox(before, shape, path.back()) > 0.02f);
  for (int k = 0; k < 30; ++k) path.push_back(path.back());
  for (int k = int(path.size()) - 31; k >= 0; --k) path.push_back(path[size_t(k)]);
  float deepest = -1.0f, deepestStill = -1.0f;
  auto next = std::chrono::steady_clock::now();
  Joints j;
  for (size_t k = 0; k < path.size(); ++k) {
    next += std::chrono::microseconds(11111);
    std::this_thread::sleep_until(next);
    XrGraspTargetPlacementSDFG p{XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, app.local, path[k]};
    REQUIRE(ext.place(box, &p) == XR_SUCCESS);
    XrResult located = XR_ERROR_RUNTIME_FAILURE;
    app.frame([&] { located = locateJoints(app, tracker, j); });
    REQUIRE(located == XR_SUCCESS);
    if (!j.locations.isActive) continue;
    const float depth = depthInBox(j, shape, path[k]);
    deepest = std::max(deepest, depth);
    // The last 20 frames of the hold: the answers have caught up with a box that stopped.
    const size_t holdEnd = path.size() - (path.size() - 30) / 2;
    if (k + 20 >= holdEnd && k < holdEnd) deepestStill = std::max(deepestStill, depth);
  }
  std::printf("box brought at 1 m/s: shown hand at most %.2f mm inside, %.2f mm once it stopped\n",
              1000.0f * deepest, 1000.0f * deepestStill);
  // Drawn from the worker's last answer, a frame late on time (the box's motion since is
  // predicted); a loaded machine or a sanitizer answers later still. Without the push the joints
  // end over 2 cm inside.
  CHECK(deepest <= 0.010f);
  CHECK(deepestStill <= 0.001f);
  // The box back where it came from, the hand is the tracked hand again (waited for).
  bool tracked = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!tracked && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::microseconds(11111));
    app.frame(
        [&] { tracked = locateJoints(app, tracker, j) == XR_SUCCESS && sameJoints(j, before); });
  }
  CHECK(tracked);
  CHECK(validationLog().empty());
}
