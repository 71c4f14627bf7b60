// The layer on Monado (label monado): a grasp with the runtime's own tracked hands, on a Vulkan
// and on a headless session. Monado (built by build_monado.sh) runs in process with its remote
// driver, which this test scripts over the loopback: two Index controllers that are also hand
// trackers, their squeeze and finger curls set here. The chain is the test harness's: the real
// loader, the layer (implicit), the Khronos core validation layer, then Monado.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cstring>
#include <fstream>
#include <functional>
#include <thread>

#include "grasp_checks.h"
#include "test_scenes.h"
#include "xr_harness.h"

namespace {

using namespace sdfg::test;

// The remote driver's wire format: struct r_remote_data of Monado's
// src/xrt/drivers/remote/r_interface.h (version "mndrmt3"), written here from its field list;
// natural alignment, no packing, as Monado compiles it. Both ends are this machine.
struct RemoteVec3 {
  float x, y, z;
};
struct RemotePose {
  float qx, qy, qz, qw;  // orientation (x, y, z, w)
  RemoteVec3 position;
};
struct RemoteController {
  RemotePose pose;
  RemoteVec3 linearVelocity;
  RemoteVec3 angularVelocity;
  float handCurl[5];  // little, ring, middle, index, thumb
  float trigger;
  float squeeze;
  float squeezeForce;
  float thumbstick[2];
  float trackpadForce;
  float trackpad[2];
  bool handTrackingActive;
  bool active;
  bool clicks[14];  // system, a, b, trigger, thumbstick (click/touch), trackpad touch, padding
};
struct RemoteHead {
  struct View {
    float fov[4];
    RemotePose pose;
    uint32_t pad;
  } views[2];
  RemotePose center;
  bool perViewDataValid;
  bool pad[3];
};
struct RemoteData {
  uint64_t header;
  RemoteHead head;
  RemoteController left, right;
};
static_assert(sizeof(RemoteController) == 120, "r_remote_controller_data is 120 bytes");
static_assert(sizeof(RemoteHead) == 128, "r_head_data is 128 bytes");
static_assert(sizeof(RemoteData) == 376, "r_remote_data is 376 bytes");

// A client of the remote driver on 127.0.0.1:4242. On connecting the driver sends its reset
// state and its latest state; the test edits the latest and sends it back whole.
class RemoteClient {
 public:
  ~RemoteClient() {
    if (fd_ >= 0) close(fd_);
  }
  // Connects within `seconds` (the driver listens once the runtime's system exists).
  bool connect(double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      fd_ = socket(AF_INET, SOCK_STREAM, 0);
      sockaddr_in addr{};
      addr.sin_family = AF_INET;
      addr.sin_port = htons(4242);
      addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      if (::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0) {
        RemoteData reset{};
        return readAll(reset) && readAll(state);
      }
      close(fd_);
      fd_ = -1;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }
  bool send() {
    std::memcpy(&state.header, "mndrmt3", 8);
    const auto* p = reinterpret_cast<const uint8_t*>(&state);
    size_t done = 0;
    while (done < sizeof state) {
      const ssize_t n = write(fd_, p + done, sizeof state - done);
      if (n <= 0) return false;
      done += size_t(n);
    }
    return true;
  }
  RemoteData state{};

 private:
  bool readAll(RemoteData& out) {
    auto* p = reinterpret_cast<uint8_t*>(&out);
    size_t done = 0;
    while (done < sizeof out) {
      const ssize_t n = read(fd_, p + done, sizeof out - done);
      if (n <= 0) return false;
      done += size_t(n);
    }
    return true;
  }
  int fd_ = -1;
};

// The Monado runtime manifest build_monado.sh recorded; empty when there is none.
std::string monadoManifest() {
  std::ifstream in(SDFG_MONADO_STAMP);
  std::string path;
  std::getline(in, path);
  return path;
}

// Frames paced at 90 Hz, as an app's (the layer's worker gets the wall time between them), until
// `done` holds or `seconds` pass.
bool framesUntil(App& app, const std::function<void()>& each, const std::function<bool()>& done,
                 double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  auto next = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() < end) {
    next += std::chrono::microseconds(11111);
    std::this_thread::sleep_until(next);
    each();
    app.frame();
    if (done()) return true;
  }
  return false;
}

int contactsOf(const XrGraspStateSDFG& s) {
  int n = 0;
  for (const auto& f : s.fingers) n += f.inContact ? 1 : 0;
  return n;
}

// An app that loads its level first: its action set made, suggested and attached now, after
// frames ran. Returns the attach's result; app.appSet is synced by every frame after it.
XrResult attachLate(App& app) {
  XrActionSetCreateInfo asci{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::strcpy(asci.actionSetName, "late_app");
  std::strcpy(asci.localizedActionSetName, "Late app");
  XrActionSet set = XR_NULL_HANDLE;
  REQUIRE(xrCreateActionSet(app.instance, &asci, &set) == XR_SUCCESS);
  XrActionCreateInfo aci{XR_TYPE_ACTION_CREATE_INFO};
  aci.actionType = XR_ACTION_TYPE_FLOAT_INPUT;
  std::strcpy(aci.actionName, "grab");
  std::strcpy(aci.localizedActionName, "Grab");
  aci.countSubactionPaths = 2;
  aci.subactionPaths = app.hands.data();
  XrAction squeeze = XR_NULL_HANDLE;
  REQUIRE(xrCreateAction(set, &aci, &squeeze) == XR_SUCCESS);
  XrPath profile = XR_NULL_PATH, right = XR_NULL_PATH;
  xrStringToPath(app.instance, "/interaction_profiles/khr/simple_controller", &profile);
  xrStringToPath(app.instance, "/user/hand/right/input/select/click", &right);
  XrActionSuggestedBinding b{squeeze, right};
  XrInteractionProfileSuggestedBinding sb{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
  sb.interactionProfile = profile;
  sb.countSuggestedBindings = 1;
  sb.suggestedBindings = &b;
  REQUIRE(xrSuggestInteractionProfileBindings(app.instance, &sb) == XR_SUCCESS);
  XrSessionActionSetsAttachInfo at{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  at.countActionSets = 1;
  at.actionSets = &set;
  const XrResult r = xrAttachSessionActionSets(app.session, &at);
  if (r == XR_SUCCESS) {
    app.appSet = set;
    app.appSqueeze = squeeze;
  }
  return r;
}

// One test case per session kind, each skipped (before any assertion) when it cannot run: a
// case that skipped one generated session after the other ran would report its failures as a skip.
// `appActions` false: an app with no action sets until the end (the grab update runs in
// xrWaitFrame and the hand grabs by closing), which then attaches one late.
void grabAndRelease(Graphics graphics, bool appActions = true) {
  const std::string manifest = monadoManifest();
  if (manifest.empty()) SDFG_SKIP("no Monado build (../shared/monado absent)");
  if (graphics != Graphics::headless && !vulkanUnavailable().empty())
    SDFG_SKIP(vulkanUnavailable());
  XrEnv env;
  env.extra = {{"XR_RUNTIME_JSON", manifest},
               {"XRT_COMPOSITOR_NULL", "1"},
               {"P_OVERRIDE_ACTIVE_CONFIG", "remote"},
               {"XRT_LOG", "warning"}};
  applyEnv(env);
  AppOptions options;
  options.extensions = {XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME,
                        XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME};
  options.graphics = graphics;
  options.appActions = appActions;
  App app(options);
  REQUIRE(app.ok());
  RemoteClient remote;
  REQUIRE(remote.connect(20.0));
  Ext ext(app);
  REQUIRE(ext.ok());
  XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);

  // Monado's headless sessions predict a display time of 0: the app locates at the clock's now.
  auto convert = app.fn<PFN_xrConvertTimespecTimeToTimeKHR>("xrConvertTimespecTimeToTimeKHR");
  REQUIRE(convert != nullptr);
  auto now = [&] {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    XrTime t = 0;
    convert(app.instance, &ts, &t);
    return t;
  };
  float closing = 0.0f;  // squeeze and every finger curl
  auto drive = [&] {
    RemoteController& c = remote.state.right;
    c.active = true;
    c.handTrackingActive = true;
    c.squeeze = closing;
    c.squeezeForce = 0.0f;
    for (float& curl : c.handCurl) curl = closing;
    if (!remote.send()) FAIL("the remote driver closed the connection");
  };
  auto frame = [&] { drive(); };

  // The open hand, tracked: its wrist places the sphere in the middle of the grab box.
  Joints open;
  REQUIRE(framesUntil(
      app, frame,
      [&] {
        if (graphics == Graphics::headless) app.lastTime = now();
        return locateJoints(app, tracker, open) == XR_SUCCESS && open.locations.isActive;
      },
      30.0));
  const sdfg::Pose wrist = toPose(open.joints[XR_HAND_JOINT_WRIST_EXT].pose);
  const glm::vec3 c = wrist.transformPoint(sdfg::GridBox::referenceDefault().handFromBox.position);
  const XrVector3f centre{c.x, c.y, c.z};
  const float radius = 0.04f;
  makeTarget(app, ext, makeIcosphere(radius, 4), {{0, 0, 0, 1}, centre});

  // Close over 90 frames (a second at 90 Hz), then hold until the grasp has settled.
  int closed = 0;
  XrGraspStateSDFG state{XR_TYPE_GRASP_STATE_SDFG};
  XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
  const bool held = framesUntil(
      app,
      [&] {
        closing = std::min(1.0f, float(++closed) / 90.0f);
        frame();
      },
      [&] {
        return closing >= 1.0f && ext.state(app.session, &gi, &state) == XR_SUCCESS &&
               state.isGrasping && contactsOf(state) >= 3;
      },
      60.0);
  REQUIRE(held);
  // The runtime's joints are rewritten: no fingertip inside the sphere.
  Joints grasped;
  if (graphics == Graphics::headless) app.lastTime = now();
  REQUIRE(locateJoints(app, tracker, grasped) == XR_SUCCESS);
  REQUIRE(grasped.locations.isActive);
  for (int f = 0; f < 5; ++f) {
    const XrVector3f tip = grasped.joints[kTips[f]].pose.position;
    CAPTURE(f);
    CHECK(length(sub(tip, centre)) - radius > -0.001f);
  }

  // Letting go ends the grasp.
  closing = 0.0f;
  CHECK(framesUntil(
      app, frame,
      [&] { return ext.state(app.session, &gi, &state) == XR_SUCCESS && !state.isGrasping; },
      30.0));
  if (!appActions) {
    // Its attach after all those frames is answered as without the layer, and so are its syncs.
    CHECK(attachLate(app) == XR_SUCCESS);
    int frames = 0;
    CHECK(framesUntil(
        app, frame, [&] { return ++frames >= 10; }, 30.0));
    CHECK(app.lastSync == XR_SUCCESS);
  }
  CHECK(validationLog().empty());
}

}  // namespace

TEST_CASE("On Monado a squeezed tracked hand grasps a sphere and lets go (Vulkan2 session)",
          "[monado][grasp]") {
  grabAndRelease(Graphics::vulkan2);
}

TEST_CASE("On Monado a squeezed tracked hand grasps a sphere and lets go (headless session)",
          "[monado][grasp]") {
  grabAndRelease(Graphics::headless);
}

TEST_CASE(
    "On Monado an app with no action sets grasps by closing its tracked hand, then attaches "
    "late",
    "[monado][grasp]") {
  grabAndRelease(Graphics::headless, /*appActions=*/false);
}
