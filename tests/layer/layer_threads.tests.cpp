// The layer called from two app threads at once, as engines do: a main thread that polls events,
// waits frames and syncs actions, and a render thread that begins frames, locates both hands,
// reads the grasp state and ends frames. Run under ThreadSanitizer in CI (tsan preset). What is
// asserted is structural, never a time: the render thread's calls complete while the main thread
// is held inside a runtime call the layer makes from xrSyncActions (the mock runtime's call gate,
// which the test closes and opens).
#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <future>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "grasp_checks.h"
#include "mock_runtime_test.h"
#include "test_scenes.h"
#include "xr_harness.h"

namespace {

using namespace sdfg::test;
using namespace std::chrono_literals;

const XrPosef kGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};

// The squeeze of the right hand goes on and off every `period` frames, so the run grabs and
// releases many times.
std::string squeezeOnOff(uint64_t frames, uint64_t period) {
  std::string s = gripLine(0, "right", kGrip) + gripLine(0, "left", kGrip);
  for (uint64_t f = 0; f < frames; f += period) {
    const bool on = (f / period) % 2 == 1;
    s += squeezeLine(f, "right", on ? 1.0f : 0.0f);
    s += squeezeLine(f + period - 1, "right", on ? 1.0f : 0.0f);
  }
  return s;
}

// One frame handed from the main thread to the render thread. The main thread waits the next
// frame only once the render thread has ended this one (xrWaitFrame, xrBeginFrame, xrEndFrame in
// order, as core validation wants); its other calls (events, placement, sync) run meanwhile.
class FrameQueue {
 public:
  void push(XrTime time) {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return !busy_; });
    frame_ = time;
    busy_ = true;
    changed_.notify_all();
  }
  // Blocks until the frame handed last is ended (finish()).
  void drain() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return !busy_; });
  }
  // Nothing once closed.
  std::optional<XrTime> pop() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return frame_.has_value() || closed_; });
    return std::exchange(frame_, std::nullopt);
  }
  void finish() {
    std::lock_guard lock(mutex_);
    busy_ = false;
    changed_.notify_all();
  }
  void close() {
    std::lock_guard lock(mutex_);
    closed_ = true;
    changed_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<XrTime> frame_;
  bool busy_ = false;
  bool closed_ = false;
};

struct RenderCalls {
  XrResult begin = XR_SUCCESS, end = XR_SUCCESS, left = XR_SUCCESS, right = XR_SUCCESS,
           state = XR_SUCCESS;
  bool grasping = false;
  bool jointsValid = false;
};

// The render thread's frame: begin, both hands, the grasp state, end.
RenderCalls renderFrame(const App& app, const Ext& ext, XrHandTrackerEXT left,
                        XrHandTrackerEXT right, XrTime time) {
  RenderCalls r;
  XrFrameBeginInfo bi{XR_TYPE_FRAME_BEGIN_INFO};
  r.begin = xrBeginFrame(app.session, &bi);
  auto locate = app.fn<PFN_xrLocateHandJointsEXT>("xrLocateHandJointsEXT");
  for (XrHandTrackerEXT t : {left, right}) {
    Joints j;
    XrHandJointsLocateInfoEXT info{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
    info.baseSpace = app.local;
    info.time = time;
    j.locations.jointCount = XR_HAND_JOINT_COUNT_EXT;
    j.locations.jointLocations = j.joints.data();
    const XrResult res = locate(t, &info, &j.locations);
    (t == left ? r.left : r.right) = res;
    if (t == right) r.jointsValid = res == XR_SUCCESS && j.locations.isActive;
  }
  XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
  XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG};
  r.state = ext.state(app.session, &gi, &st);
  r.grasping = st.isGrasping == XR_TRUE;
  XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
  ei.displayTime = time;
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  r.end = xrEndFrame(app.session, &ei);
  return r;
}

XrResult syncApp(const App& app) {
  XrActiveActionSet active{app.appSet, XR_NULL_PATH};
  XrActionsSyncInfo si{XR_TYPE_ACTIONS_SYNC_INFO};
  si.countActiveActionSets = 1;
  si.activeActionSets = &active;
  return xrSyncActions(app.session, &si);
}

// The mock runtime's gate of one command (mock_runtime_test.h).
struct Gate {
  const App& app;
  const char* command;
  void set(bool hold, uint32_t delayMicroseconds = 0) const {
    auto f = app.fn<PFN_xrMockRuntimeGateCallsSDFG>("xrMockRuntimeGateCallsSDFG");
    REQUIRE(f != nullptr);
    REQUIRE(f(app.instance, command, hold ? XR_TRUE : XR_FALSE, delayMicroseconds) == XR_SUCCESS);
  }
  uint32_t waiting() const {
    auto f = app.fn<PFN_xrMockRuntimeGateStatsSDFG>("xrMockRuntimeGateStatsSDFG");
    uint32_t waiting = 0;
    uint64_t passed = 0;
    REQUIRE(f(app.instance, command, &waiting, &passed) == XR_SUCCESS);
    return waiting;
  }
};

}  // namespace

TEST_CASE("Two app threads: a main thread syncing and a render thread locating over 2000 frames",
          "[layer][threads]") {
  constexpr uint64_t kFrames = 2000;
  XrEnv env;
  env.handTracking = "absent";  // hands synthesized by the layer: its locate path throughout
  env.script = squeezeOnOff(kFrames + 100, 50);
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  const XrHandTrackerEXT left = makeTracker(app, ext, XR_HAND_LEFT_EXT);
  const XrHandTrackerEXT right = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  const XrVector3f centre = boxCentreInLocal(kGrip, true);
  const XrGraspTargetSDFG target =
      makeTarget(app, ext, makeIcosphere(0.04f, 3), {{0, 0, 0, 1}, centre});
  // Running and focused, with the target set up, before the threads split the frame.
  REQUIRE(app.framesUntil([&] { return app.framesEnded >= 3; }));
  REQUIRE(untilSetUp(app, ext, [](const auto& s) { return s.readyCount == 1; }));

  FrameQueue frames;
  std::atomic<int> renderFailures{0}, framesRendered{0}, framesGrasping{0}, framesOpen{0};
  std::thread render([&] {
    while (const std::optional<XrTime> time = frames.pop()) {
      const RenderCalls r = renderFrame(app, ext, left, right, *time);
      if (r.begin != XR_SUCCESS || r.end != XR_SUCCESS || r.left != XR_SUCCESS ||
          r.right != XR_SUCCESS || r.state != XR_SUCCESS || !r.jointsValid)
        ++renderFailures;
      ++(r.grasping ? framesGrasping : framesOpen);
      ++framesRendered;
      frames.finish();
    }
  });
  int mainFailures = 0;
  // Paced at 90 Hz, as an app's frames are: two threads in unpaced loops take both cores of a
  // 2-core machine, and the layer's worker (which an app leaves time for) then finished one grab
  // in a thousand frames.
  auto next = std::chrono::steady_clock::now();
  for (uint64_t i = 0; i < kFrames; ++i) {
    next += std::chrono::microseconds(11111);
    std::this_thread::sleep_until(next);
    XrEventDataBuffer e{XR_TYPE_EVENT_DATA_BUFFER};
    while (xrPollEvent(app.instance, &e) == XR_SUCCESS)
      e = XrEventDataBuffer{XR_TYPE_EVENT_DATA_BUFFER};
    frames.drain();
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    XrFrameWaitInfo wi{XR_TYPE_FRAME_WAIT_INFO};
    if (xrWaitFrame(app.session, &wi, &fs) != XR_SUCCESS) ++mainFailures;
    frames.push(fs.predictedDisplayTime);
    // The main thread also moves the target a little, as a physics step would.
    const float shift = 0.0005f * float(i % 20);
    XrGraspTargetPlacementSDFG placement{XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG,
                                         nullptr,
                                         app.local,
                                         {{0, 0, 0, 1}, {centre.x + shift, centre.y, centre.z}}};
    if (ext.place(target, &placement) != XR_SUCCESS) ++mainFailures;
    if (syncApp(app) != XR_SUCCESS) ++mainFailures;
  }
  frames.drain();
  frames.close();
  render.join();
  CHECK(mainFailures == 0);
  CHECK(renderFailures == 0);
  CHECK(framesRendered == int(kFrames));
  // The squeeze went on and off: the render thread saw the hand grasp and let go.
  CAPTURE(framesGrasping.load(), framesOpen.load());
  CHECK(framesGrasping > 0);
  CHECK(framesOpen > 0);
  CHECK(validationLog().empty());
}

TEST_CASE(
    "Two app threads: the render thread's frame completes while the main thread's sync is "
    "held in a runtime call",
    "[layer][threads]") {
  XrEnv env;
  env.handTracking = "absent";
  env.script =
      gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.0f) + squeezeLine(3, "right", 1.0f);
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  const XrHandTrackerEXT left = makeTracker(app, ext, XR_HAND_LEFT_EXT);
  const XrHandTrackerEXT right = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  makeTarget(app, ext, makeIcosphere(0.04f, 3), {{0, 0, 0, 1}, boxCentreInLocal(kGrip, true)});
  // A held grasp: the render thread's locate rewrites the fingers from the published grasp.
  REQUIRE(framesUntilGrasping(app, ext, XR_HAND_RIGHT_EXT));

  // The layer reads its squeeze action in every xrSyncActions (the app's thread never does): the
  // gate holds the main thread there, inside the layer's grab update.
  const Gate gate{app, "xrGetActionStateFloat"};
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  XrFrameWaitInfo wi{XR_TYPE_FRAME_WAIT_INFO};
  REQUIRE(xrWaitFrame(app.session, &wi, &fs) == XR_SUCCESS);
  gate.set(true);
  auto mainSync = std::async(std::launch::async, [&] { return syncApp(app); });
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (gate.waiting() == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(1ms);
  REQUIRE(gate.waiting() == 1);

  // The render thread's frame, with the main thread held: every call returns. (Before the layer
  // stopped holding its session lock across runtime calls, the locates waited for the sync: this
  // wait then ran out.)
  auto renderFrameCalls = std::async(std::launch::async, [&] {
    return renderFrame(app, ext, left, right, fs.predictedDisplayTime);
  });
  const bool done = renderFrameCalls.wait_for(60s) == std::future_status::ready;
  // The main thread was held the whole time.
  CHECK(gate.waiting() == 1);
  CHECK(mainSync.wait_for(0s) == std::future_status::timeout);
  gate.set(false);
  REQUIRE(done);
  const RenderCalls r = renderFrameCalls.get();
  CHECK(r.begin == XR_SUCCESS);
  CHECK(r.left == XR_SUCCESS);
  CHECK(r.right == XR_SUCCESS);
  CHECK(r.jointsValid);
  CHECK(r.grasping);
  CHECK(r.state == XR_SUCCESS);
  CHECK(r.end == XR_SUCCESS);
  CHECK(mainSync.get() == XR_SUCCESS);
  app.frames(2);
  CHECK(validationLog().empty());
}
