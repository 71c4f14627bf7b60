// Session lifecycle: creation with a Vulkan binding or headless (XR_MND_headless), the
// state sequence of notes/mock-runtime-and-hello_xr.md section 7, teardown of children, and
// the report and capture files written when a session ends.
#include <algorithm>
#include <cstdio>
#include <set>

#include "entry_points.h"
#include "system_constants.h"

namespace sdfg::mock {
namespace {

const void* findInChain(const void* next, XrStructureType type) {
  for (auto* p = static_cast<const XrBaseInStructure*>(next); p != nullptr; p = p->next) {
    if (p->type == type) return p;
  }
  return nullptr;
}

void writePpm(const std::string& path, const CapturedImage& image) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return;
  std::fprintf(f, "P6\n%u %u\n255\n", image.width, image.height);
  for (size_t i = 0; i + 3 < image.rgba.size(); i += 4) std::fwrite(&image.rgba[i], 1, 3, f);
  std::fclose(f);
}

}  // namespace

// Queues the states that take a running session down to STOPPING (from FOCUSED: VISIBLE,
// SYNCHRONIZED, STOPPING); xrEndSession then finishes with IDLE and EXITING.
void beginStopping(Session& session) {
  if (session.stopping) return;
  session.stopping = true;
  if (session.state == XR_SESSION_STATE_FOCUSED) queueState(session, XR_SESSION_STATE_VISIBLE);
  if (session.state == XR_SESSION_STATE_VISIBLE) queueState(session, XR_SESSION_STATE_SYNCHRONIZED);
  // STOPPING is only entered from SYNCHRONIZED (spec 9.3): a session asked to stop before its
  // first frame passes through it (the CTS's conformance layer checks every transition).
  if (session.state == XR_SESSION_STATE_READY) queueState(session, XR_SESSION_STATE_SYNCHRONIZED);
  queueState(session, XR_SESSION_STATE_STOPPING);
}

void writeSessionFiles(Session& session) {
  const Options& o = session.instance->options;
  const CapturedImage& image = session.captures[0];
  if (!o.capturePath.empty() && !image.rgba.empty()) writePpm(o.capturePath, image);
  if (o.reportPath.empty()) return;
  std::FILE* f = std::fopen(o.reportPath.c_str(), "w");
  if (f == nullptr) return;
  const XrMockRuntimeStatsSDFG& s = session.stats;
  std::fprintf(f, "frames_waited %llu\nframes_begun %llu\nframes_ended %llu\n",
               (unsigned long long)s.framesWaited, (unsigned long long)s.framesBegun,
               (unsigned long long)s.framesEnded);
  std::fprintf(f, "frames_with_layers %llu\nframes_captured %llu\nfinal_state %d\n",
               (unsigned long long)s.framesWithLayers, (unsigned long long)s.framesCaptured,
               int(session.state));
  if (!image.rgba.empty()) {
    auto pixel = [&](uint32_t x, uint32_t y) {
      const uint8_t* p = &image.rgba[(size_t(y) * image.width + x) * 4];
      return std::array<unsigned, 4>{p[0], p[1], p[2], p[3]};
    };
    const auto corner = pixel(0, 0);
    const auto centre = pixel(image.width / 2, image.height / 2);
    std::set<uint32_t> colours;
    for (size_t i = 0; i + 3 < image.rgba.size(); i += 4) {
      colours.insert(uint32_t(image.rgba[i]) | uint32_t(image.rgba[i + 1]) << 8 |
                     uint32_t(image.rgba[i + 2]) << 16 | uint32_t(image.rgba[i + 3]) << 24);
    }
    std::fprintf(f, "capture_width %u\ncapture_height %u\n", image.width, image.height);
    std::fprintf(f, "capture_corner %u %u %u %u\n", corner[0], corner[1], corner[2], corner[3]);
    std::fprintf(f, "capture_centre %u %u %u %u\n", centre[0], centre[1], centre[2], centre[3]);
    std::fprintf(f, "capture_distinct_colours %zu\n", colours.size());
  }
  std::fclose(f);
}

Session::~Session() = default;

void destroySession(Session* session) {
  Instance& instance = *session->instance;
  writeSessionFiles(*session);
  while (!session->swapchains.empty()) destroySwapchain(session->swapchains.back().get());
  for (auto& space : session->spaces) unregisterHandle(space.get());
  session->spaces.clear();
  for (auto& tracker : session->handTrackers) unregisterHandle(tracker.get());
  session->handTrackers.clear();
  session->vulkan.reset();
  // Events of a destroyed session would carry a dead handle.
  const XrSession handle = toHandle<XrSession>(session);
  std::erase_if(instance.events, [&](const XrEventDataBuffer& e) {
    if (e.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED)
      return reinterpret_cast<const XrEventDataSessionStateChanged&>(e).session == handle;
    if (e.type == XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED)
      return reinterpret_cast<const XrEventDataInteractionProfileChanged&>(e).session == handle;
    return false;
  });
  unregisterHandle(session);
  std::erase_if(instance.sessions, [&](const auto& s) { return s.get() == session; });
}

XrResult createSession(XrInstance handle, const XrSessionCreateInfo* info, XrSession* out) {
  constexpr const char* cmd = "xrCreateSession";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_SESSION_CREATE_INFO);
  MOCK_VERIFY_NOT_NULL(cmd, out);
  if (info->createFlags != 0)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "createFlags must be 0");
  if (info->systemId != kSystemId || !instance->systemFetched)
    return fail(cmd, XR_ERROR_SYSTEM_INVALID, "systemId %llu", (unsigned long long)info->systemId);
  if (!instance->sessions.empty())
    return fail(cmd, XR_ERROR_LIMIT_REACHED, "one session at a time");

  auto session = std::make_unique<Session>();
  session->instance = instance;
  const auto* binding = static_cast<const XrGraphicsBindingVulkanKHR*>(
      findInChain(info->next, XR_TYPE_GRAPHICS_BINDING_VULKAN_KHR));
  if (binding != nullptr) {
    if (!instance->extVulkan && !instance->extVulkan2)
      return fail(cmd, XR_ERROR_GRAPHICS_DEVICE_INVALID, "no Vulkan extension enabled");
    if (!instance->graphicsRequirementsQueried)
      return fail(cmd, XR_ERROR_GRAPHICS_REQUIREMENTS_CALL_MISSING,
                  "xrGetVulkanGraphicsRequirements(2)KHR was not called");
    if (XrResult r = createVulkanContext(cmd, *instance, *binding, session->vulkan);
        r != XR_SUCCESS)
      return r;
  } else if (!instance->extHeadless) {
    return fail(cmd, XR_ERROR_GRAPHICS_DEVICE_INVALID,
                "no graphics binding, and XR_MND_headless is not enabled");
  }

  Session* s = session.get();
  registerHandle(s);
  instance->sessions.push_back(std::move(session));
  queueState(*s, XR_SESSION_STATE_IDLE);
  queueState(*s, XR_SESSION_STATE_READY);
  *out = toHandle<XrSession>(s);
  return XR_SUCCESS;
}

XrResult destroySessionEntry(XrSession handle) {
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail("xrDestroySession", XR_ERROR_HANDLE_INVALID, "session");
  destroySession(session);
  return XR_SUCCESS;
}

XrResult beginSession(XrSession handle, const XrSessionBeginInfo* info) {
  constexpr const char* cmd = "xrBeginSession";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_SESSION_BEGIN_INFO);
  if (session->running) return fail(cmd, XR_ERROR_SESSION_RUNNING, "already running");
  if (session->state != XR_SESSION_STATE_READY)
    return fail(cmd, XR_ERROR_SESSION_NOT_READY, "state is %d, not READY", int(session->state));
  if (info->primaryViewConfigurationType != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO) {
    const bool known =
        info->primaryViewConfigurationType == XR_VIEW_CONFIGURATION_TYPE_PRIMARY_MONO ||
        info->primaryViewConfigurationType == XR_VIEW_CONFIGURATION_TYPE_PRIMARY_QUAD_VARJO;
    return fail(cmd,
                known ? XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED : XR_ERROR_VALIDATION_FAILURE,
                "primaryViewConfigurationType %d", int(info->primaryViewConfigurationType));
  }
  session->viewConfiguration = info->primaryViewConfigurationType;
  session->running = true;
  session->stopping = false;
  return XR_SUCCESS;
}

XrResult endSession(XrSession handle) {
  constexpr const char* cmd = "xrEndSession";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  if (!session->running) return fail(cmd, XR_ERROR_SESSION_NOT_RUNNING, "not running");
  if (session->state != XR_SESSION_STATE_STOPPING)
    return fail(cmd, XR_ERROR_SESSION_NOT_STOPPING, "state is %d, not STOPPING",
                int(session->state));
  session->running = false;
  session->framesWaitedPending = 0;
  session->frameBegun = false;
  queueState(*session, XR_SESSION_STATE_IDLE);
  queueState(*session, XR_SESSION_STATE_EXITING);
  return XR_SUCCESS;
}

XrResult requestExitSession(XrSession handle) {
  constexpr const char* cmd = "xrRequestExitSession";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  if (!session->running) return fail(cmd, XR_ERROR_SESSION_NOT_RUNNING, "not running");
  beginStopping(*session);
  return XR_SUCCESS;
}

}  // namespace sdfg::mock
