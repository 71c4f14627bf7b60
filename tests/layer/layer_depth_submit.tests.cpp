// An app that never heard of the layer submits its depth (XR_KHR_composition_layer_depth) on a
// Vulkan session, as Unreal and StereoKit do: every depth format the mock runtime offers, one
// swapchain per view or one array swapchain, standard, reversed and infinite-far depth. These
// hold the path the depth scene reads from (docs/depth.md) to the runtime's rules: every frame is
// accepted, the Vulkan and OpenXR validation layers see nothing wrong, broken depth infos are
// refused, and a runtime that will not let depth images be read (fault refuse_depth_readback)
// refuses exactly the swapchains a reader would ask for.
#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "depth_render.h"
#include "depth_submitter.h"
#include "mock_checks.h"
#include "test_support.h"
#include "xr_harness.h"

namespace {

using namespace sdfg::test;
namespace dt = sdfg::depth_test;

constexpr const char* kDepthExtension = XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME;

const char* formatName(VkFormat f) {
  switch (f) {
    case VK_FORMAT_D16_UNORM:
      return "D16_UNORM";
    case VK_FORMAT_D24_UNORM_S8_UINT:
      return "D24_UNORM_S8_UINT";
    case VK_FORMAT_D32_SFLOAT:
      return "D32_SFLOAT";
    case VK_FORMAT_D32_SFLOAT_S8_UINT:
      return "D32_SFLOAT_S8_UINT";
    default:
      return "?";
  }
}

std::vector<int64_t> swapchainFormats(const App& app) {
  uint32_t n = 0;
  REQUIRE(xrEnumerateSwapchainFormats(app.session, 0, &n, nullptr) == XR_SUCCESS);
  std::vector<int64_t> formats(n);
  REQUIRE(xrEnumerateSwapchainFormats(app.session, n, &n, formats.data()) == XR_SUCCESS);
  return formats;
}

bool offered(const App& app, VkFormat f) {
  const std::vector<int64_t> formats = swapchainFormats(app);
  return std::find(formats.begin(), formats.end(), int64_t(f)) != formats.end();
}

// The embedded mug on its table, the table top 0.4 m in front of and 0.3 m below the LOCAL
// origin, where the mock runtime's head is: what the app draws, seen from the located views.
struct MugScene {
  dt::MugOnTable scene;
  sdfg::Pose localFromTable{glm::quat(1, 0, 0, 0), glm::vec3(0.0f, -0.3f, -0.4f)};
  std::vector<dt::Placed> objects;
  // What the views saw, over every render: pixels with something drawn, and the renders whose
  // pixel towards the mug's centre shows the mug's near side (within 7 cm before the centre).
  size_t renders = 0, finite = 0, pixels = 0, mugSeen = 0;

  MugScene() {
    for (dt::Placed p : scene.objects()) {
      p.worldFromObject = localFromTable * p.worldFromObject;
      objects.push_back(p);
    }
  }

  std::vector<float> render(const XrView& view, uint32_t width, uint32_t height) {
    sdfg::DepthView v;
    const XrQuaternionf& q = view.pose.orientation;
    const XrVector3f& p = view.pose.position;
    v.worldFromView = sdfg::Pose{glm::quat(q.w, q.x, q.y, q.z), glm::vec3(p.x, p.y, p.z)};
    v.fov = sdfg::DepthFov{view.fov.angleLeft, view.fov.angleRight, view.fov.angleUp,
                           view.fov.angleDown};
    v.width = width;
    v.height = height;
    v.nearZ = 0.05f;  // the rasterizer reads only the pose, fov and size
    v.farZ = 100.0f;
    std::vector<float> z = dt::renderDistances(v, objects);
    ++renders;
    const glm::vec3 mugCentre = (localFromTable * scene.worldFromMug).position;
    glm::vec2 pixel;
    float centreZ = 0.0f;
    if (v.project(mugCentre, pixel, centreZ) && pixel.x >= 0 && pixel.y >= 0 &&
        pixel.x < float(width) && pixel.y < float(height)) {
      const float seen = z[size_t(pixel.y) * width + size_t(pixel.x)];
      if (seen < centreZ && seen > centreZ - 0.07f) ++mugSeen;
    }
    pixels += z.size();
    finite += size_t(std::count_if(z.begin(), z.end(), [](float d) { return std::isfinite(d); }));
    return z;
  }
  DepthSubmitter::Render renderer() {
    return [this](const XrView& view, uint32_t w, uint32_t h) { return render(view, w, h); };
  }
};

struct Convention {
  const char* name;
  bool reversed, infiniteFar;
};
constexpr Convention kConventions[] = {{"standard", false, false},
                                       {"reversed", true, false},
                                       {"infinite far", false, true},
                                       {"reversed, infinite far", true, true}};

}  // namespace

TEST_CASE("The submitter's stored values read back through the depth view as their distances",
          "[layer][depth]") {
  for (const Convention& c : kConventions) {
    CAPTURE(c.name);
    const float inf = std::numeric_limits<float>::infinity();
    const float far = c.infiniteFar ? inf : 100.0f;
    sdfg::DepthView v;
    v.nearZ = c.reversed ? far : 0.05f;
    v.farZ = c.reversed ? 0.05f : far;
    for (float z : {0.05f, 0.1f, 0.4f, 1.0f, 7.5f, 99.0f}) {
      CAPTURE(z);
      const float stored = storedDepthValue(z, v.nearZ, v.farZ);
      CHECK(stored >= 0.0f);
      CHECK(stored <= 1.0f);
      CHECK(v.distance(stored) == Approx(z).epsilon(1e-4));
    }
    // Nothing drawn is the far plane's value; nearer than near is the near plane's.
    CHECK(storedDepthValue(inf, v.nearZ, v.farZ) == (c.reversed ? 0.0f : 1.0f));
    CHECK(storedDepthValue(0.01f, v.nearZ, v.farZ) == (c.reversed ? 1.0f : 0.0f));
  }
}

TEST_CASE("An app submits the depth of what it draws in every format, layout and convention",
          "[layer][depth][vulkan]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  const VkFormat format = GENERATE(VK_FORMAT_D16_UNORM, VK_FORMAT_D24_UNORM_S8_UINT,
                                   VK_FORMAT_D32_SFLOAT, VK_FORMAT_D32_SFLOAT_S8_UINT);
  const bool array = GENERATE(false, true);
  CAPTURE(formatName(format), array);
  applyEnv(XrEnv{});
  const size_t messagesBefore = vulkanMessages().size();
  {
    App app({{kDepthExtension}, true, Graphics::vulkan2});
    REQUIRE(app.ok());
    if (!offered(app, format)) {
      WARN("the mock runtime does not offer " << formatName(format) << " on this device");
      return;
    }
    MugScene scene;
    for (const Convention& c : kConventions) {
      CAPTURE(c.name);
      DepthSubmitOptions options;
      options.format = format;
      options.arraySwapchain = array;
      options.reversed = c.reversed;
      options.infiniteFar = c.infiniteFar;
      DepthSubmitter submitter(app, options);
      INFO(submitter.error());
      REQUIRE(submitter.ok());
      const MockDepthStats before = mockDepthStats(app);
      const uint64_t endedBefore = app.framesEnded;
      uint64_t frames = 0, refused = 0;
      bool submitted = true;
      const DepthSubmitter::Render render = scene.renderer();
      const bool done = app.framesUntil(
          [&] { return mockDepthStats(app).framesWithDepth >= before.framesWithDepth + 10; },
          std::chrono::seconds(60),
          [&] {
            ++frames;
            submitted = submitter.submit(render) && submitted;
          });
      // framesUntil ends a frame between two checks; a refused one would not count.
      refused = frames - (app.framesEnded - endedBefore);
      INFO(submitter.error());
      CHECK(submitted);
      REQUIRE(done);
      CHECK(refused == 0);
      CHECK(submitter.submitted() == frames);
      const MockDepthStats after = mockDepthStats(app);
      CHECK(after.framesWithDepth - before.framesWithDepth == frames);
      CHECK(after.depthInfos - before.depthInfos == 2 * frames);
      CHECK(mockStats(app).lastLayerCount == 1);
    }
    // The located views see the mug on the table below the horizon, and nothing above it.
    REQUIRE(scene.renders > 0);
    CHECK(scene.mugSeen == scene.renders);
    const double seen = double(scene.finite) / double(scene.pixels);
    CHECK(seen > 0.1);
    CHECK(seen < 0.5);
  }
  CHECK(validationLog().empty());
  CHECK(vulkanMessages().size() == messagesBefore);
}

TEST_CASE("The mock runtime refuses broken depth infos and ignores them without the extension",
          "[layer][depth][vulkan]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  applyEnv(XrEnv{});
  const size_t messagesBefore = vulkanMessages().size();
  MugScene scene;
  const DepthSubmitter::Render render = scene.renderer();
  {
    App app({{kDepthExtension}, true, Graphics::vulkan2});
    REQUIRE(app.ok());
    DepthSubmitter submitter(app, {});
    INFO(submitter.error());
    REQUIRE(submitter.ok());
    // Until the session runs, frame() does nothing.
    REQUIRE(app.framesUntil([&] { return app.framesEnded > 0; }, std::chrono::seconds(30),
                            [&] { CHECK(submitter.submit(render)); }));
    const MockDepthStats good = mockDepthStats(app);
    CHECK(good.framesWithDepth == 1);

    struct Broken {
      const char* name;
      std::function<void(DepthSubmitter&)> breakIt;
      XrResult expected;
    };
    const std::vector<Broken> broken = {
        {"minDepth > maxDepth",
         [](DepthSubmitter& s) {
           s.depthInfo(0).minDepth = 0.9f;
           s.depthInfo(0).maxDepth = 0.1f;
         },
         XR_ERROR_VALIDATION_FAILURE},
        {"maxDepth > 1", [](DepthSubmitter& s) { s.depthInfo(1).maxDepth = 1.5f; },
         XR_ERROR_VALIDATION_FAILURE},
        {"rect outside the image",
         [](DepthSubmitter& s) { s.depthInfo(1).subImage.imageRect.offset.x = 1; },
         XR_ERROR_SWAPCHAIN_RECT_INVALID},
        {"nearZ == farZ", [](DepthSubmitter& s) { s.depthInfo(0).farZ = s.depthInfo(0).nearZ; },
         XR_ERROR_VALIDATION_FAILURE},
        {"negative nearZ", [](DepthSubmitter& s) { s.depthInfo(0).nearZ = -0.05f; },
         XR_ERROR_VALIDATION_FAILURE},
        {"NaN farZ", [](DepthSubmitter& s) { s.depthInfo(1).farZ = std::nanf(""); },
         XR_ERROR_VALIDATION_FAILURE},
        {"slice beyond the array",
         [](DepthSubmitter& s) { s.depthInfo(0).subImage.imageArrayIndex = 1; },
         XR_ERROR_VALIDATION_FAILURE},
        {"a colour swapchain",
         [](DepthSubmitter& s) {
           s.depthInfo(0).subImage.swapchain = s.projection().views[0].subImage.swapchain;
         },
         XR_ERROR_VALIDATION_FAILURE},
    };
    for (const Broken& b : broken) {
      CAPTURE(b.name);
      app.frame([&] {
        REQUIRE(submitter.submit(render));
        b.breakIt(submitter);
      });
      CHECK(app.lastEndFrame == b.expected);
    }
    // None of them counted, and the next good frame is accepted.
    CHECK(mockDepthStats(app).framesWithDepth == good.framesWithDepth);
    app.frame([&] { REQUIRE(submitter.submit(render)); });
    CHECK(app.lastEndFrame == XR_SUCCESS);
    CHECK(mockDepthStats(app).framesWithDepth == good.framesWithDepth + 1);
  }
  // The refused frames are the app's errors, which core validation may report too: its log is
  // not this test's to read. The Vulkan side did nothing wrong.
  CHECK(vulkanMessages().size() == messagesBefore);

  SECTION("without the extension the runtime ignores a depth info, broken or not") {
    applyEnv(XrEnv{});
    App app({{}, true, Graphics::vulkan2});
    REQUIRE(app.ok());
    DepthSubmitter submitter(app, {});
    INFO(submitter.error());
    REQUIRE(submitter.ok());
    REQUIRE(app.framesUntil([&] { return app.framesEnded >= 2; }, std::chrono::seconds(30),
                            [&] {
                              REQUIRE(submitter.submit(render));
                              submitter.depthInfo(0).farZ = submitter.depthInfo(0).nearZ;
                            }));
    CHECK(app.lastEndFrame == XR_SUCCESS);
    CHECK(mockDepthStats(app).framesWithDepth == 0);
    CHECK(mockDepthStats(app).depthInfos == 0);
  }
}

TEST_CASE("Fault refuse_depth_readback: depth swapchains that could be read are refused",
          "[layer][depth][vulkan]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  XrEnv env;
  env.extra = {{"SDFG_MOCK_FAULT", "refuse_depth_readback"}};
  applyEnv(env);
  const size_t messagesBefore = vulkanMessages().size();
  {
    // XR_KHR_vulkan_enable here, so that the submitter runs on both bindings.
    App app({{kDepthExtension}, true, Graphics::vulkan});
    REQUIRE(app.ok());
    const std::vector<int64_t> formats = swapchainFormats(app);
    // Colour first, as the spec asks formats in order of preference; D32_SFLOAT always there.
    REQUIRE(!formats.empty());
    CHECK(formats.front() == VK_FORMAT_R8G8B8A8_SRGB);
    CHECK(std::find(formats.begin(), formats.end(), VK_FORMAT_D32_SFLOAT) != formats.end());
    auto create = [&](int64_t format, XrSwapchainUsageFlags usage) {
      XrSwapchainCreateInfo ci{XR_TYPE_SWAPCHAIN_CREATE_INFO};
      ci.usageFlags = usage;
      ci.format = format;
      ci.sampleCount = 1;
      ci.width = ci.height = 64;
      ci.faceCount = ci.arraySize = ci.mipCount = 1;
      XrSwapchain sc = XR_NULL_HANDLE;
      const XrResult r = xrCreateSwapchain(app.session, &ci, &sc);
      if (sc != XR_NULL_HANDLE) xrDestroySwapchain(sc);
      return r;
    };
    constexpr XrSwapchainUsageFlags ds = XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
    for (VkFormat f : {VK_FORMAT_D16_UNORM, VK_FORMAT_D24_UNORM_S8_UINT, VK_FORMAT_D32_SFLOAT,
                       VK_FORMAT_D32_SFLOAT_S8_UINT}) {
      if (std::find(formats.begin(), formats.end(), int64_t(f)) == formats.end()) continue;
      CAPTURE(formatName(f));
      CHECK(create(f, ds | XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT) == XR_ERROR_FEATURE_UNSUPPORTED);
      CHECK(create(f, ds | XR_SWAPCHAIN_USAGE_SAMPLED_BIT) == XR_ERROR_FEATURE_UNSUPPORTED);
      CHECK(create(f, ds | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT) == XR_SUCCESS);
      CHECK(create(f, ds) == XR_SUCCESS);
    }
    // Colour swapchains may still be read.
    CHECK(create(VK_FORMAT_R8G8B8A8_SRGB, XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT |
                                              XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT |
                                              XR_SWAPCHAIN_USAGE_SAMPLED_BIT) == XR_SUCCESS);

    // An app that asks to read its own depth is refused; one that does not submits as usual.
    DepthSubmitOptions reads;
    reads.usage |= XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT;
    {
      DepthSubmitter refused(app, reads);
      CHECK_FALSE(refused.ok());
      CHECK(refused.result() == XR_ERROR_FEATURE_UNSUPPORTED);
    }
    DepthSubmitter submitter(app, {});
    INFO(submitter.error());
    REQUIRE(submitter.ok());
    MugScene scene;
    const DepthSubmitter::Render render = scene.renderer();
    CHECK(app.framesUntil([&] { return mockDepthStats(app).framesWithDepth >= 3; },
                          std::chrono::seconds(30), [&] { CHECK(submitter.submit(render)); }));
  }
  CHECK(vulkanMessages().size() == messagesBefore);
}
