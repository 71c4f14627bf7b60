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
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <future>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

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
  // Waits until the frame handed last is ended (finish()), at most `limit`; returns whether it
  // was.
  bool drain(std::chrono::milliseconds limit) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, limit, [&] { return !busy_; });
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
  // Opens the gate without asserting: for a scope left by a failed assertion, whose exception
  // another one would turn into std::terminate.
  void release() const noexcept {
    if (auto f = app.fn<PFN_xrMockRuntimeGateCallsSDFG>("xrMockRuntimeGateCallsSDFG"))
      f(app.instance, command, XR_FALSE, 0);
  }
  uint32_t waiting() const {
    auto f = app.fn<PFN_xrMockRuntimeGateStatsSDFG>("xrMockRuntimeGateStatsSDFG");
    uint32_t waiting = 0;
    uint64_t passed = 0;
    REQUIRE(f(app.instance, command, &waiting, &passed) == XR_SUCCESS);
    return waiting;
  }
};

// What went wrong on either thread, kept for the main thread to assert once the other has
// ended: Catch2's assertions are for the thread that runs the test only.
class Failures {
 public:
  void add(std::string what) {
    std::lock_guard lock(mutex_);
    if (list_.size() < 20) list_.push_back(std::move(what));
    any_ = true;
  }
  bool any() const { return any_; }
  std::vector<std::string> list() const {
    std::lock_guard lock(mutex_);
    return list_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<std::string> list_;
  std::atomic<bool> any_{false};
};

// A thread of the test still inside a layer call `limit` after it should have returned: the hang
// these tests exist to catch, which no join would end. The process exits with the reason, so the
// run fails now rather than at ctest's timeout.
[[noreturn]] void exitStuck(std::chrono::seconds limit) {
  std::fprintf(stderr, "FAIL: a thread is stuck in a layer call (no return in %lld s)\n",
               static_cast<long long>(limit.count()));
  std::fflush(stderr);
  std::_Exit(1);
}

// Joins `thread` once it has said it ended, waiting at most `limit` (exitStuck()).
void joinOrExit(std::thread& thread, const std::atomic<bool>& ended, std::chrono::seconds limit) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (!ended && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(1ms);
  if (!ended) exitStuck(limit);
  thread.join();
}

std::string callFailed(uint64_t frame, const char* call, XrResult result) {
  return "frame " + std::to_string(frame) + ": " + call + " returned " + std::to_string(result);
}

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
  Failures failures;
  std::atomic<int> framesRendered{0}, framesGrasping{0}, framesOpen{0};
  std::atomic<bool> renderEnded{false};
  std::thread render([&] {
    // Nothing may leave the thread (an exception would end the process); a failure stops both.
    try {
      while (const std::optional<XrTime> time = frames.pop()) {
        const RenderCalls r = renderFrame(app, ext, left, right, *time);
        const uint64_t frame = uint64_t(framesRendered.load());
        const std::pair<const char*, XrResult> calls[] = {
            {"xrBeginFrame", r.begin},
            {"xrLocateHandJointsEXT (left)", r.left},
            {"xrLocateHandJointsEXT (right)", r.right},
            {"xrGetGraspStateSDFG", r.state},
            {"xrEndFrame", r.end}};
        for (const auto& [call, result] : calls)
          if (result != XR_SUCCESS) failures.add(callFailed(frame, call, result));
        if (r.right == XR_SUCCESS && !r.jointsValid)
          failures.add("frame " + std::to_string(frame) + ": the right hand is not active");
        ++(r.grasping ? framesGrasping : framesOpen);
        ++framesRendered;
        frames.finish();
      }
    } catch (const std::exception& e) {
      failures.add(std::string("the render thread threw: ") + e.what());
      frames.finish();
    }
    renderEnded = true;
  });
  // Paced at 90 Hz, as an app's frames are: two threads in unpaced loops take both cores of a
  // 2-core machine, and the layer's worker (which an app leaves time for) then finished one grab
  // in a thousand frames.
  auto next = std::chrono::steady_clock::now();
  for (uint64_t i = 0; i < kFrames && !failures.any(); ++i) {
    next += std::chrono::microseconds(11111);
    std::this_thread::sleep_until(next);
    XrEventDataBuffer e{XR_TYPE_EVENT_DATA_BUFFER};
    while (xrPollEvent(app.instance, &e) == XR_SUCCESS)
      e = XrEventDataBuffer{XR_TYPE_EVENT_DATA_BUFFER};
    if (!frames.drain(60s)) {
      failures.add("frame " + std::to_string(i) + ": the render thread did not end its frame");
      break;
    }
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    XrFrameWaitInfo wi{XR_TYPE_FRAME_WAIT_INFO};
    if (const XrResult r = xrWaitFrame(app.session, &wi, &fs); r != XR_SUCCESS) {
      failures.add(callFailed(i, "xrWaitFrame", r));
      break;  // no frame to hand over
    }
    frames.push(fs.predictedDisplayTime);
    // The main thread also moves the target a little, as a physics step would.
    const float shift = 0.0005f * float(i % 20);
    XrGraspTargetPlacementSDFG placement{XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG,
                                         nullptr,
                                         app.local,
                                         {{0, 0, 0, 1}, {centre.x + shift, centre.y, centre.z}}};
    if (const XrResult r = ext.place(target, &placement); r != XR_SUCCESS)
      failures.add(callFailed(i, "xrSetGraspTargetPlacementSDFG", r));
    if (const XrResult r = syncApp(app); r != XR_SUCCESS)
      failures.add(callFailed(i, "xrSyncActions", r));
  }
  if (!frames.drain(60s)) failures.add("the render thread did not end the last frame");
  frames.close();
  joinOrExit(render, renderEnded, 60s);
  const std::vector<std::string> failed = failures.list();
  CAPTURE(failed);
  CHECK(failed.empty());
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
  // The calls on the other threads, and the gate's opening on any way out of this scope: a
  // failed REQUIRE below unwinds through the futures, whose destructors wait for their calls,
  // and the main thread's sync returns only once the gate is open. (Declared in this order,
  // the gate opens before either future is waited for.)
  std::future<XrResult> mainSync;
  std::future<RenderCalls> renderFrameCalls;
  struct OpenOnExit {
    const Gate& gate;
    ~OpenOnExit() { gate.release(); }
  } openOnExit{gate};
  gate.set(true);
  mainSync = std::async(std::launch::async, [&] { return syncApp(app); });
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (gate.waiting() == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(1ms);
  REQUIRE(gate.waiting() == 1);

  // The render thread's frame, with the main thread held: every call returns. (Before the layer
  // stopped holding its session lock across runtime calls, the locates waited for the sync: this
  // wait then ran out.)
  renderFrameCalls = std::async(std::launch::async, [&] {
    return renderFrame(app, ext, left, right, fs.predictedDisplayTime);
  });
  const bool done = renderFrameCalls.wait_for(60s) == std::future_status::ready;
  // The main thread was held the whole time.
  CHECK(gate.waiting() == 1);
  CHECK(mainSync.wait_for(0s) == std::future_status::timeout);
  gate.set(false);
  // Open, nothing holds the render thread's calls: one still running is a hang of the layer.
  if (!done && renderFrameCalls.wait_for(60s) != std::future_status::ready) exitStuck(60s);
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
