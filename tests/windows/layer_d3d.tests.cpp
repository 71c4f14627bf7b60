// Sessions with a D3D11 or D3D12 binding (Windows only): the layer cannot build on a D3D device,
// so it must leave the device alone and grasp on its CPU path. The mock runtime has no D3D; with
// XR_MND_headless enabled it ignores the binding, so the binding reaches the layer carrying a
// null device: one read of it through the layer would crash the test.
#include <d3d11.h>
#include <d3d12.h>
#define XR_USE_GRAPHICS_API_D3D11
#define XR_USE_GRAPHICS_API_D3D12
#define XR_USE_GRAPHICS_API_VULKAN
#include <vulkan/vulkan.h>
// After every graphics API's header, which it needs.
#include <openxr/openxr_platform.h>

#include <catch2/catch.hpp>

#include "grasp_checks.h"
#include "test_scenes.h"
#include "xr_harness.h"

using namespace sdfg::test;

namespace {

void graspSphereWith(const void* binding) {
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  const XrVector3f centre = boxCentreInLocal(grip, /*right=*/true);
  const float radius = 0.04f;
  const GraspOutcome out =
      graspScene(makeIcosphere(radius, 4), {{0, 0, 0, 1}, centre}, grip, "right", 0, binding);
  checkContacts(out, [&](const XrVector3f& p) { return length(sub(p, centre)) - radius; });
}

}  // namespace

TEST_CASE("A D3D11 session grasps on the CPU path and never touches the D3D device",
          "[layer][d3d]") {
  XrGraphicsBindingD3D11KHR binding{XR_TYPE_GRAPHICS_BINDING_D3D11_KHR};
  binding.device = nullptr;
  graspSphereWith(&binding);
}

TEST_CASE("A D3D12 session grasps on the CPU path and never touches the D3D device",
          "[layer][d3d]") {
  XrGraphicsBindingD3D12KHR binding{XR_TYPE_GRAPHICS_BINDING_D3D12_KHR};
  binding.device = nullptr;
  binding.queue = nullptr;
  graspSphereWith(&binding);
}
