// The depth scene through the layer (docs/depth.md): an app that never heard of the layer (no
// XR_SDFG_auto_grasp, hands synthesized from its controllers) submits its depth with
// XR_KHR_composition_layer_depth on a Vulkan session, and the hand it locates closes onto what it
// draws. Ground truth: the app's own meshes. Frames are paced as an app's (11 ms).
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <optional>
#include <thread>

#include "depth_render.h"
#include "depth_submitter.h"
#include "grasp_checks.h"
#include "test_scenes.h"
#include "xr_harness.h"

using namespace sdfg;
using namespace sdfg::test;

namespace {

namespace dt = sdfg::depth_test;

constexpr auto kFramePeriod = std::chrono::milliseconds(11);

// The right controller's grip (LOCAL); the head is at the origin looking down -Z, so the hand is
// 54 cm away, 37 degrees below the view axis.
const XrPosef kRightGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};

// What the app draws: the embedded sphere (4 cm) in the right hand's grab box.
struct Drawn {
  TriangleMesh mesh = makeSphere(0.04f, 4);
  Pose pose;
  Drawn() {
    const XrVector3f c = boxCentreInLocal(kRightGrip, true);
    pose = Pose{glm::quat(1, 0, 0, 0), glm::vec3(c.x, c.y, c.z)};
  }
  float distance(const XrVector3f& p) const {
    return glm::length(glm::vec3(p.x, p.y, p.z) - pose.position) - 0.04f;
  }
  std::vector<float> render(const XrView& v, uint32_t w, uint32_t h,
                            const std::vector<TriangleMesh>& more = {}) const {
    DepthView view;
    view.worldFromView = sdfg::test::toPose(v.pose);
    view.fov = {v.fov.angleLeft, v.fov.angleRight, v.fov.angleUp, v.fov.angleDown};
    view.width = w;
    view.height = h;
    view.nearZ = 0.05f;
    view.farZ = 100.0f;
    std::vector<dt::Placed> placed{{&mesh, pose}};
    for (const TriangleMesh& m : more) placed.push_back({&m, Pose{}});
    return dt::renderDistances(view, placed);
  }
};

// The app's tracker of its right hand (synthesized from the controller: hand tracking absent).
XrHandTrackerEXT rightTracker(const App& app) {
  auto create = app.fn<PFN_xrCreateHandTrackerEXT>("xrCreateHandTrackerEXT");
  REQUIRE(create != nullptr);
  XrHandTrackerCreateInfoEXT ci{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
  ci.hand = XR_HAND_RIGHT_EXT;
  ci.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
  XrHandTrackerEXT tracker = XR_NULL_HANDLE;
  REQUIRE(create(app.session, &ci, &tracker) == XR_SUCCESS);
  return tracker;
}

// The right hand's grasp state with `out` chained on it (apps that enabled the extension).
template <class Out>
Out rightHandOutput(const App& app, Out out) {
  auto getState = app.fn<PFN_xrGetGraspStateSDFG>("xrGetGraspStateSDFG");
  REQUIRE(getState != nullptr);
  XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG, &out};
  XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
  REQUIRE(getState(app.session, &gi, &st) == XR_SUCCESS);
  return out;
}

// Whether the layer reads the app's depth and it is fused around the right hand.
bool depthReady(const App& app) {
  const auto info =
      rightHandOutput(app, XrGraspDepthSceneInfoSDFG{XR_TYPE_GRASP_DEPTH_SCENE_INFO_SDFG});
  CHECK(info.enabled == XR_TRUE);
  return info.ready == XR_TRUE;
}

// What the right hand's fingers touch, and whether it rests on a solve (isClosed).
XrGraspTouchesSDFG rightTouches(const App& app) {
  return rightHandOutput(app, XrGraspTouchesSDFG{XR_TYPE_GRASP_TOUCHES_SDFG});
}

struct Run {
  Joints closed;                    // the hand once it stopped moving with the squeeze held
  uint64_t depthFrames;             // frames the app submitted depth in
  std::vector<XrResult> endFrames;  // what each xrEndFrame returned
  int onDepthScene = 0;             // observed apps: fingers whose touch names the depth scene
  int grabs = 0;                    // squeezes it took
  bool observed = false;            // AppCase::observe
};

// How the app submits its depth, beyond the submitter's options.
struct AppCase {
  bool submit = true;          // false: no depth at all (a colour-only app)
  DepthSubmitOptions options;  // format, layout, convention, size
  bool drawHand = false;       // the app draws the hand it locates into its depth, as apps do
  // Called between the submitter's structs and xrEndFrame, on the app's n-th depth frame: a test
  // may break what the app submits.
  std::function<void(DepthSubmitter&, uint64_t)> tamper;
  std::vector<std::pair<std::string, std::string>> extra;  // config of the layer, the mock's fault
  // The app also enables XR_SDFG_auto_grasp, registers nothing and asks for the depth scene
  // (depth_scene = on) so that the test can wait until the layer says the scene is ready
  // (XrGraspDepthSceneInfoSDFG) before the squeeze. False: an app that never heard of the layer
  // (depth_scene = auto), which grabs again while a grab closed before the scene was ready.
  bool observe = true;
  bool expectDepth = true;  // the layer will read the depth (false: it must not, or cannot)
};

// The hand the app locates, drawn as it would draw it: a sphere at every joint of its radius.
void addHand(const Joints& j, std::vector<TriangleMesh>& meshes) {
  if (!j.locations.isActive) return;
  for (const XrHandJointLocationEXT& l : j.joints) {
    TriangleMesh m = makeSphere(l.radius, 1);
    for (glm::vec3& p : m.positions)
      p += glm::vec3(l.pose.position.x, l.pose.position.y, l.pose.position.z);
    meshes.push_back(std::move(m));
  }
}

// Each finger's clearance to the drawn sphere (its capsules, proximal joint to tip).
std::array<float, 5> clearances(const Joints& j, const Drawn& drawn) {
  GraspOutcome out;
  out.joints = j;
  std::array<float, 5> c{};
  for (int f = 0; f < 5; ++f)
    c[size_t(f)] = fingerClearance(out, f, [&](const XrVector3f& p) { return drawn.distance(p); });
  return c;
}

// The app: a Vulkan session with synthesized hands; submits depth as `c` says, squeezes once 30
// frames of depth went down (or at once without depth), and runs until the closed hand has not
// moved for 20 frames.
Run runApp(const AppCase& c) {
  XrEnv env;
  env.handTracking = "absent";
  env.script = gripLine(0, "right", kRightGrip) + squeezeLine(0, "right", 0.0f);
  env.extra = c.extra;
  const bool configured = std::any_of(c.extra.begin(), c.extra.end(), [](const auto& kv) {
    return kv.first == "SDFG_AUTOGRASP_DEPTH_SCENE";
  });
  if (c.observe && !configured) env.extra.push_back({"SDFG_AUTOGRASP_DEPTH_SCENE", "on"});
  applyEnv(env);
  AppOptions ao{
      {XR_EXT_HAND_TRACKING_EXTENSION_NAME, XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME}};
  if (c.observe) ao.extensions.push_back(XR_SDFG_AUTO_GRASP_EXTENSION_NAME);
  ao.graphics = Graphics::vulkan2;
  App app(ao);
  REQUIRE(app.ok());
  REQUIRE((app.fn<PFN_xrGetGraspStateSDFG>("xrGetGraspStateSDFG") != nullptr) == c.observe);
  const XrHandTrackerEXT tracker = rightTracker(app);

  const Drawn drawn;
  std::optional<DepthSubmitter> depth;
  if (c.submit) {
    depth.emplace(app, c.options);
    REQUIRE(depth->ok());
  }
  Run run{};
  run.observed = c.observe;
  Joints last;
  const auto frame = [&] {
    app.frame([&] {
      if (!depth) return;
      std::vector<TriangleMesh> hand;
      if (c.drawHand) addHand(last, hand);
      REQUIRE(depth->submit(
          [&](const XrView& v, uint32_t w, uint32_t h) { return drawn.render(v, w, h, hand); }));
      if (c.tamper) c.tamper(*depth, depth->submitted());
    });
    run.endFrames.push_back(app.lastEndFrame);
    std::this_thread::sleep_for(kFramePeriod);
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  // Before the squeeze: the scene is ready (observed apps), or 30 frames of depth went down.
  while (depth && (c.observe && c.expectDepth ? !depthReady(app) : depth->submitted() < 30)) {
    REQUIRE(std::chrono::steady_clock::now() < deadline);
    frame();
    REQUIRE(locateJoints(app, tracker, last) == XR_SUCCESS);
  }
  // Runs frames until the hand has not moved for 20 of them and 1.5 s: the frames before the
  // worker's answer show the hand closing by the squeeze alone, as many as the worker is late.
  const auto untilStill = [&](bool answered) {
    int still = 0;
    auto since = std::chrono::steady_clock::now();
    while (still < 20 ||
           std::chrono::steady_clock::now() - since < std::chrono::milliseconds(1500) ||
           (answered && rightTouches(app).isClosed != XR_TRUE)) {
      REQUIRE(std::chrono::steady_clock::now() < deadline);
      frame();
      Joints now;
      REQUIRE(locateJoints(app, tracker, now) == XR_SUCCESS);
      REQUIRE(now.locations.isActive);
      bool same = true;
      for (int j = 0; j < XR_HAND_JOINT_COUNT_EXT; ++j) {
        const XrVector3f a = now.joints[j].pose.position, b = last.joints[j].pose.position;
        same = same && a.x == b.x && a.y == b.y && a.z == b.z;
      }
      if (!same) since = std::chrono::steady_clock::now();
      still = same ? still + 1 : 0;
      last = now;
    }
  };
  // The timeline is replaced whole: the grip stays where it was.
  const auto squeeze = [&](float value) {
    const uint64_t next = app.framesEnded + 1;
    REQUIRE(app.setScript(gripLine(next, "right", kRightGrip) +
                          squeezeLine(next, "right", value)) == XR_SUCCESS);
  };
  for (;;) {
    squeeze(1.0f);
    ++run.grabs;
    // An observed app waits for the answer when the layer reads its depth (with none, no solve
    // comes: nothing is in the box).
    untilStill(c.observe && c.expectDepth && depth.has_value());
    // An app that never heard of the layer cannot tell when the scene is ready; its user grabs
    // again when the hand closed through what it sees (at most 5 times, within the bound).
    const std::array<float, 5> cl = clearances(last, drawn);
    const bool through = *std::min_element(cl.begin(), cl.end()) < -0.01f;
    if (c.observe || !c.expectDepth || !through || run.grabs >= 5) break;
    squeeze(0.0f);
    untilStill(false);
  }
  if (c.observe) {
    for (XrGraspTargetSDFG t : rightTouches(app).touched)
      run.onDepthScene += t == XR_GRASP_TARGET_DEPTH_SCENE_SDFG ? 1 : 0;
  }
  run.closed = last;
  run.depthFrames = depth ? depth->submitted() : 0;
  depth.reset();  // its swapchains go before the session
  CHECK(validationLog().empty());
  CHECK(vulkanMessages().empty());
  return run;
}

// The grasp on what the app drew: every finger outside the true sphere by more than -3 mm (the
// issue's 2 mm bound and a pixel), three at least touching it (within 4 mm).
void checkClosedOn(const Run& run, const char* what) {
  const std::array<float, 5> c = clearances(run.closed, Drawn());
  int touching = 0;
  for (int f = 0; f < 5; ++f) {
    CAPTURE(what, f, c[size_t(f)]);
    CHECK(c[size_t(f)] >= -0.003f);
    touching += c[size_t(f)] <= 0.004f ? 1 : 0;
  }
  CHECK(touching >= 3);
  // An app that asked for the depth scene through the extension reads where its fingers rest.
  if (run.observed) CHECK(run.onDepthScene >= 3);
  WARN(what << ": finger clearances (mm) " << c[0] * 1e3f << " " << c[1] * 1e3f << " "
            << c[2] * 1e3f << " " << c[3] * 1e3f << " " << c[4] * 1e3f << " after "
            << run.depthFrames << " frames of depth, " << run.grabs << " grab(s)");
}

// The hand closed through the sphere: the depth was not read.
void checkClosedThrough(const Run& run) {
  const std::array<float, 5> c = clearances(run.closed, Drawn());
  CHECK(*std::min_element(c.begin(), c.end()) < -0.01f);
}

const char* formatName(VkFormat f) {
  switch (f) {
    case VK_FORMAT_D16_UNORM:
      return "D16";
    case VK_FORMAT_D24_UNORM_S8_UINT:
      return "D24S8";
    case VK_FORMAT_D32_SFLOAT:
      return "D32";
    case VK_FORMAT_D32_SFLOAT_S8_UINT:
      return "D32S8";
    default:
      return "?";
  }
}

}  // namespace

TEST_CASE("A hand closes onto a sphere an app only draws, seen through the depth it submits",
          "[layer][depth]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  AppCase c;
  c.options.format = GENERATE(VK_FORMAT_D32_SFLOAT, VK_FORMAT_D16_UNORM,
                              VK_FORMAT_D24_UNORM_S8_UINT, VK_FORMAT_D32_SFLOAT_S8_UINT);
  c.options.arraySwapchain = GENERATE(false, true);
  c.options.width = c.options.height = 320;
  const std::string what = std::string(formatName(c.options.format)) +
                           (c.options.arraySwapchain ? ", array" : ", per view");
  checkClosedOn(runApp(c), what.c_str());
}

TEST_CASE("An app that never heard of the layer grasps what it draws (depth_scene = auto)",
          "[layer][depth]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  AppCase c;
  c.observe = false;
  c.options.width = c.options.height = 320;
  checkClosedOn(runApp(c), "an app with no extension");
}

TEST_CASE("Reversed, infinite-far and lower-resolution depth are read as the app meant them",
          "[layer][depth]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  AppCase c;
  c.options.width = c.options.height = 320;
  SECTION("reversed") {
    c.options.reversed = true;
  }
  SECTION("infinite far") {
    c.options.infiniteFar = true;
  }
  SECTION("reversed, infinite far") {
    c.options.reversed = true;
    c.options.infiniteFar = true;
  }
  SECTION("depth at half the resolution, D16") {
    c.options.width = c.options.height = 160;
    c.options.format = VK_FORMAT_D16_UNORM;
  }
  SECTION("depth larger than the layer reads (640 pixels: the hand's part whole)") {
    c.options.width = c.options.height = 640;
  }
  SECTION("a headset's depth (1280 pixels: the hand's part read every other)") {
    c.options.width = c.options.height = 1280;
  }
  checkClosedOn(runApp(c), "convention");
}

TEST_CASE("The hand the app draws into its depth is not grasped", "[layer][depth]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  AppCase c;
  c.options.width = c.options.height = 320;
  c.drawHand = true;
  checkClosedOn(runApp(c), "the hand drawn too");
}

TEST_CASE("A runtime that refuses the layer's read of depth gets the swapchain the app asked for",
          "[layer][depth]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  AppCase c;
  c.options.width = c.options.height = 320;
  c.extra = {{"SDFG_MOCK_FAULT", "refuse_depth_readback"}};
  c.expectDepth = false;
  const Run run = runApp(c);  // every create and frame of the app succeeds (the submitter checks)
  CHECK(std::count(run.endFrames.begin(), run.endFrames.end(), XR_SUCCESS) ==
        std::ptrdiff_t(run.endFrames.size()));
  checkClosedThrough(run);
}

TEST_CASE("Depth info that cannot be right is skipped, and the runtime's answer comes back",
          "[layer][depth]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  AppCase c;
  c.options.width = c.options.height = 320;
  XrResult expected = XR_SUCCESS;
  SECTION("a rect outside the image") {
    c.tamper = [](DepthSubmitter& d, uint64_t n) {
      if (n % 3 == 0) d.depthInfo(1).subImage.imageRect.offset.x = 100;
    };
    expected = XR_ERROR_SWAPCHAIN_RECT_INVALID;
  }
  SECTION("minDepth above maxDepth") {
    c.tamper = [](DepthSubmitter& d, uint64_t n) {
      if (n % 3 == 0) d.depthInfo(0).minDepth = 2.0f;
    };
    expected = XR_ERROR_VALIDATION_FAILURE;
  }
  SECTION("nearZ equal to farZ") {
    c.tamper = [](DepthSubmitter& d, uint64_t n) {
      if (n % 3 == 0) d.depthInfo(0).farZ = d.depthInfo(0).nearZ;
    };
    expected = XR_ERROR_VALIDATION_FAILURE;
  }
  const Run run = runApp(c);
  // The runtime refused the broken frames (as without the layer), and the good frames between
  // them still made the scene.
  CHECK(std::count(run.endFrames.begin(), run.endFrames.end(), expected) >= 10);
  checkClosedOn(run, "a third of the frames broken");
}

TEST_CASE("An app that submits no depth gets the hand it got before the depth scene",
          "[layer][depth]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  AppCase none;
  none.submit = false;
  none.observe = false;
  none.expectDepth = false;
  AppCase off = none;
  off.extra = {{"SDFG_AUTOGRASP_DEPTH_SCENE", "off"}};
  const Run a = runApp(none), b = runApp(off);
  for (int j = 0; j < XR_HAND_JOINT_COUNT_EXT; ++j) {
    CAPTURE(j);
    const XrPosef pa = a.closed.joints[j].pose, pb = b.closed.joints[j].pose;
    CHECK(std::memcmp(&pa, &pb, sizeof pa) == 0);
  }
  checkClosedThrough(a);
}

TEST_CASE("depth_scene = off reads no depth", "[layer][depth]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  AppCase c;
  c.options.width = c.options.height = 320;
  c.extra = {{"SDFG_AUTOGRASP_DEPTH_SCENE", "off"}};
  c.expectDepth = false;
  checkClosedThrough(runApp(c));
}

// The layer copies only the pixels that can see a hand's fusion box (docs/depth.md): a hand
// behind the head costs no copy at all after the first frame, and the first frames with it in
// sight are read again.
TEST_CASE("Depth is read only where a hand is in sight", "[layer][depth]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  XrEnv env;
  env.handTracking = "absent";
  // Both hands behind the head (the left one too: its controller's default is in sight).
  const XrPosef behind{{0, 0, 0, 1}, {0.2f, -0.3f, 0.4f}};
  const XrPosef leftBehind{{0, 0, 0, 1}, {-0.2f, -0.3f, 0.4f}};
  env.script = gripLine(0, "right", behind) + squeezeLine(0, "right", 0.0f) +
               gripLine(0, "left", leftBehind);
  env.extra = {{"SDFG_AUTOGRASP_DEPTH_SCENE", "on"}};
  applyEnv(env);
  AppOptions ao{{XR_EXT_HAND_TRACKING_EXTENSION_NAME, XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME,
                 XR_SDFG_AUTO_GRASP_EXTENSION_NAME}};
  ao.graphics = Graphics::vulkan2;
  App app(ao);
  REQUIRE(app.ok());
  const XrHandTrackerEXT tracker = rightTracker(app);
  DepthSubmitOptions options;
  options.width = options.height = 320;
  DepthSubmitter depth(app, options);
  REQUIRE(depth.ok());
  const Drawn drawn;
  const auto framesRead = [&] {
    return rightHandOutput(app, XrGraspDepthSceneInfoSDFG{XR_TYPE_GRASP_DEPTH_SCENE_INFO_SDFG})
        .framesRead;
  };
  const auto frame = [&] {
    app.frame([&] {
      REQUIRE(depth.submit(
          [&](const XrView& v, uint32_t w, uint32_t h) { return drawn.render(v, w, h); }));
    });
    Joints j;
    REQUIRE(locateJoints(app, tracker, j) == XR_SUCCESS);
    std::this_thread::sleep_for(kFramePeriod);
  };
  // Until the layer has seen the views and the hand (its first copies are whole: no view placed
  // them yet), then 60 frames and a second more.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (depth.submitted() < 10) frame();
  const uint32_t before = framesRead();
  CHECK(before <= 6);
  const auto since = std::chrono::steady_clock::now();
  for (int n = 0; n < 60 || std::chrono::steady_clock::now() - since < std::chrono::seconds(1);
       ++n) {
    REQUIRE(std::chrono::steady_clock::now() < deadline);
    frame();
  }
  CHECK(framesRead() == before);
  // The hand comes into sight: its depth is read and fused.
  const uint64_t next = app.framesEnded + 1;
  REQUIRE(app.setScript(gripLine(next, "right", kRightGrip) + squeezeLine(next, "right", 0.0f) +
                        gripLine(next, "left", leftBehind)) == XR_SUCCESS);
  while (!depthReady(app) || framesRead() < before + 10) {
    REQUIRE(std::chrono::steady_clock::now() < deadline);
    frame();
  }
  CHECK(validationLog().empty());
  CHECK(vulkanMessages().empty());
}

// The outer hand on depth: an open hand the user lowers 3 cm into a table the app draws (and
// submits as depth) is drawn on the table, not in it, with no squeeze and no extension.
TEST_CASE("An open hand lowered into a table the app only draws is shown on it", "[layer][depth]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  XrEnv env;
  env.handTracking = "absent";
  env.script = gripLine(0, "right", kRightGrip) + squeezeLine(0, "right", 0.0f);
  // Through the extension (registering nothing) only to know when the scene is ready.
  env.extra = {{"SDFG_AUTOGRASP_DEPTH_SCENE", "on"}};
  applyEnv(env);
  AppOptions ao{
      {XR_EXT_HAND_TRACKING_EXTENSION_NAME, XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME}};
  ao.extensions.push_back(XR_SDFG_AUTO_GRASP_EXTENSION_NAME);
  ao.graphics = Graphics::vulkan2;
  App app(ao);
  REQUIRE(app.ok());
  const XrHandTrackerEXT tracker = rightTracker(app);
  // The open hand as tracked, before anything is near it: the table's top goes 1 cm below it.
  Joints open;
  for (int k = 0; k < 10 || !open.locations.isActive; ++k) {
    REQUIRE(k < 1000);
    app.frame();
    REQUIRE(locateJoints(app, tracker, open) == XR_SUCCESS);
  }
  const float bottom = wholeHandClearance(open, [](const XrVector3f& p) { return p.y; });
  const float top = bottom - 0.01f;
  const TriangleMesh table = makeBox(glm::vec3(0.6f, 0.04f, 0.6f));
  const Pose tablePose{glm::quat(1, 0, 0, 0), glm::vec3(0.2f, top - 0.02f, -0.4f)};
  const auto tableDistance = [&](const XrVector3f& p) { return p.y - top; };  // near its top

  DepthSubmitOptions o;
  o.width = o.height = 320;
  std::optional<DepthSubmitter> depth(std::in_place, app, o);
  REQUIRE(depth->ok());
  const auto render = [&](const XrView& v, uint32_t w, uint32_t h) {
    DepthView view;
    view.worldFromView = sdfg::test::toPose(v.pose);
    view.fov = {v.fov.angleLeft, v.fov.angleRight, v.fov.angleUp, v.fov.angleDown};
    view.width = w;
    view.height = h;
    const dt::Placed placed[] = {{&table, tablePose}};
    return dt::renderDistances(view, placed);
  };
  const auto frame = [&] {
    app.frame([&] { REQUIRE(depth->submit(render)); });
    std::this_thread::sleep_for(kFramePeriod);
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!depthReady(app)) {
    REQUIRE(std::chrono::steady_clock::now() < deadline);
    frame();
  }
  // Down 1 mm a frame, 40 frames: the tracked hand ends 3 cm into the table.
  const uint64_t first = app.framesEnded + 1;
  std::string script = squeezeLine(first, "right", 0.0f);
  for (int k = 0; k <= 40; ++k) {
    XrPosef g = kRightGrip;
    g.position.y -= 0.001f * float(k);
    script += gripLine(first + uint64_t(k), "right", g);
  }
  REQUIRE(app.setScript(script) == XR_SUCCESS);
  // On the way down, then until the shown hand rests (20 frames unmoved after the last step).
  float worst = std::numeric_limits<float>::infinity(), resting = 0.0f;
  Joints last;
  auto since = std::chrono::steady_clock::now();
  // 20 frames unmoved, 1.5 s after the last step at least: the outer hand's late answers come in
  // between.
  for (int still = 0; still < 20;) {
    REQUIRE(std::chrono::steady_clock::now() < deadline);
    frame();
    Joints now;
    REQUIRE(locateJoints(app, tracker, now) == XR_SUCCESS);
    resting = wholeHandClearance(now, tableDistance);
    worst = std::min(worst, resting);
    bool same = app.framesEnded > first + 40;
    for (int j = 0; j < XR_HAND_JOINT_COUNT_EXT && same; ++j)
      same = std::memcmp(&now.joints[j].pose, &last.joints[j].pose, sizeof(XrPosef)) == 0;
    if (app.framesEnded <= first + 40) since = std::chrono::steady_clock::now();
    still = same ? still + 1 : 0;
    if (std::chrono::steady_clock::now() - since < std::chrono::milliseconds(1500)) still = 0;
    last = now;
  }
  Joints tracked = open;
  for (auto& l : tracked.joints) l.pose.position.y -= 0.04f;
  WARN("drawn " << -resting * 1e3f << " mm into the table at rest, " << -worst * 1e3f
                << " mm at worst on the way (tracked: "
                << -wholeHandClearance(tracked, tableDistance) * 1e3f << " mm)");
  // The issue asks 2 mm (p99 over many reaches). At rest this reach is 2.8 mm in, where a
  // registered table at the same place keeps it 0.1 mm out (docs/depth.md, "What it measures"):
  // bounded so that a change that lets the hand deeper fails. On the way, the frames before each
  // of the outer hand's late answers show the tracked hand going on down, as many as the worker
  // is late (3 to 11 mm here, 30 under AddressSanitizer): reported, not bounded (issue 36).
  CHECK(resting >= -0.004f);
  depth.reset();
  CHECK(validationLog().empty());
  CHECK(vulkanMessages().empty());
}
