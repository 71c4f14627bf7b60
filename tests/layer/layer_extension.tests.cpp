// XR_SDFG_auto_grasp input validation: every function given bad handles, null pointers, wrong
// structure types, NaN vertices, out-of-range indices and zero counts returns the right error
// and changes nothing.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "grasp_checks.h"
#include "xr_harness.h"

namespace {

using namespace sdfg::test;

// A tetrahedron, valid.
const XrVector3f kVerts[4] = {{0, 0, 0}, {0.1f, 0, 0}, {0, 0.1f, 0}, {0, 0, 0.1f}};
const uint32_t kIdx[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
const XrGraspTargetSDFG kSentinel = reinterpret_cast<XrGraspTargetSDFG>(uintptr_t{55});

}  // namespace

TEST_CASE("Every extension function rejects bad input with the right error and changes nothing",
          "[layer][extension]") {
  applyEnv({});
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  REQUIRE(ext.ok());
  XrGraspTargetVerticesSDFG mesh{XR_TYPE_GRASP_TARGET_VERTICES_SDFG, nullptr, 4, kVerts, 12, kIdx};
  XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG, &mesh};
  ci.placement = {
      XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, app.local, {{0, 0, 0, 1}, {0, 0, -0.5f}}};
  XrGraspTargetSDFG good = XR_NULL_HANDLE;
  REQUIRE(ext.create(app.session, &ci, &good) == XR_SUCCESS);
  REQUIRE(good != XR_NULL_HANDLE);
  const XrSession badSession = reinterpret_cast<XrSession>(uintptr_t{0xdead0000});
  const XrGraspTargetSDFG badTarget = reinterpret_cast<XrGraspTargetSDFG>(uintptr_t{0xbeef0000});
  const float nan = std::numeric_limits<float>::quiet_NaN();

  SECTION("xrCreateGraspTargetSDFG") {
    XrGraspTargetSDFG out = kSentinel;
    auto tryCreate = [&](XrSession s, const XrGraspTargetCreateInfoSDFG* info) {
      out = kSentinel;
      return ext.create(s, info, &out);
    };
    CHECK(tryCreate(XR_NULL_HANDLE, &ci) == XR_ERROR_HANDLE_INVALID);
    CHECK(tryCreate(badSession, &ci) == XR_ERROR_HANDLE_INVALID);
    CHECK(tryCreate(app.session, nullptr) == XR_ERROR_VALIDATION_FAILURE);
    CHECK(ext.create(app.session, &ci, nullptr) == XR_ERROR_VALIDATION_FAILURE);
    auto c = ci;
    c.type = XR_TYPE_GRASP_STATE_SDFG;
    CHECK(tryCreate(app.session, &c) == XR_ERROR_VALIDATION_FAILURE);
    c = ci;
    c.next = nullptr;  // no mesh
    CHECK(tryCreate(app.session, &c) == XR_ERROR_VALIDATION_FAILURE);
    c = ci;
    c.placement.type = XR_TYPE_GRASP_OPTIONS_SDFG;
    CHECK(tryCreate(app.session, &c) == XR_ERROR_VALIDATION_FAILURE);
    c = ci;
    c.placement.space = XR_NULL_HANDLE;
    CHECK(tryCreate(app.session, &c) == XR_ERROR_HANDLE_INVALID);
    c.placement.space = reinterpret_cast<XrSpace>(uintptr_t{0xabc0000});
    CHECK(tryCreate(app.session, &c) == XR_ERROR_HANDLE_INVALID);
    c = ci;
    c.placement.pose.orientation = {0, 0, 0, 2};
    CHECK(tryCreate(app.session, &c) == XR_ERROR_POSE_INVALID);
    c.placement.pose.orientation = {0, 0, 0, 1};
    c.placement.pose.position.y = nan;
    CHECK(tryCreate(app.session, &c) == XR_ERROR_VALIDATION_FAILURE);

    auto withMesh = [&](XrGraspTargetVerticesSDFG m) {
      auto c2 = ci;
      c2.next = &m;
      return tryCreate(app.session, &c2);
    };
    auto m = mesh;
    m.type = XR_TYPE_GRASP_STATE_SDFG;  // unknown struct: ignored, so no mesh is chained
    CHECK(withMesh(m) == XR_ERROR_VALIDATION_FAILURE);
    m = mesh;
    m.vertexCount = 0;
    CHECK(withMesh(m) == XR_ERROR_VALIDATION_FAILURE);
    m = mesh;
    m.indexCount = 0;
    CHECK(withMesh(m) == XR_ERROR_VALIDATION_FAILURE);
    m = mesh;
    m.indexCount = 11;
    CHECK(withMesh(m) == XR_ERROR_VALIDATION_FAILURE);
    m = mesh;
    m.vertices = nullptr;
    CHECK(withMesh(m) == XR_ERROR_VALIDATION_FAILURE);
    m = mesh;
    m.indices = nullptr;
    CHECK(withMesh(m) == XR_ERROR_VALIDATION_FAILURE);
    m = mesh;
    m.vertexCount = 0xFFFFFFFFu;  // huge
    CHECK(withMesh(m) == XR_ERROR_VALIDATION_FAILURE);
    XrVector3f nanVerts[4] = {kVerts[0], kVerts[1], {nan, 0, 0}, kVerts[3]};
    m = mesh;
    m.vertices = nanVerts;
    CHECK(withMesh(m) == XR_ERROR_VALIDATION_FAILURE);
    XrVector3f infVerts[4] = {
        kVerts[0], kVerts[1], kVerts[2], {0, std::numeric_limits<float>::infinity(), 0}};
    m.vertices = infVerts;
    CHECK(withMesh(m) == XR_ERROR_VALIDATION_FAILURE);
    uint32_t outOfRange[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 4};
    m = mesh;
    m.indices = outOfRange;
    CHECK(withMesh(m) == XR_ERROR_VALIDATION_FAILURE);
    uint32_t degenerate[12] = {0, 0, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    m.indices = degenerate;
    CHECK(withMesh(m) == XR_ERROR_VALIDATION_FAILURE);
    // Nothing was created by any of these.
    CHECK(out == kSentinel);
  }

  SECTION("xrDestroyGraspTargetSDFG") {
    CHECK(ext.destroy(XR_NULL_HANDLE) == XR_ERROR_HANDLE_INVALID);
    CHECK(ext.destroy(badTarget) == XR_ERROR_HANDLE_INVALID);
    CHECK(ext.destroy(good) == XR_SUCCESS);
    CHECK(ext.destroy(good) == XR_ERROR_HANDLE_INVALID);  // already destroyed
    good = XR_NULL_HANDLE;
  }

  SECTION("xrUpdateGraspTargetVerticesSDFG") {
    XrGraspTargetVerticesSDFG u{XR_TYPE_GRASP_TARGET_VERTICES_SDFG, nullptr, 4, kVerts, 0, nullptr};
    CHECK(ext.update(XR_NULL_HANDLE, &u) == XR_ERROR_HANDLE_INVALID);
    CHECK(ext.update(badTarget, &u) == XR_ERROR_HANDLE_INVALID);
    CHECK(ext.update(good, nullptr) == XR_ERROR_VALIDATION_FAILURE);
    auto v = u;
    v.type = XR_TYPE_GRASP_OPTIONS_SDFG;
    CHECK(ext.update(good, &v) == XR_ERROR_VALIDATION_FAILURE);
    v = u;
    v.vertexCount = 3;  // not the target's count
    CHECK(ext.update(good, &v) == XR_ERROR_VALIDATION_FAILURE);
    v = u;
    v.vertexCount = 0;
    CHECK(ext.update(good, &v) == XR_ERROR_VALIDATION_FAILURE);
    v = u;
    v.indexCount = 12;  // topology is fixed
    v.indices = kIdx;
    CHECK(ext.update(good, &v) == XR_ERROR_VALIDATION_FAILURE);
    XrVector3f nanVerts[4] = {kVerts[0], {0, nan, 0}, kVerts[2], kVerts[3]};
    v = u;
    v.vertices = nanVerts;
    CHECK(ext.update(good, &v) == XR_ERROR_VALIDATION_FAILURE);
    v.vertices = nullptr;
    CHECK(ext.update(good, &v) == XR_ERROR_VALIDATION_FAILURE);
    CHECK(ext.update(good, &u) == XR_SUCCESS);  // the target is still there and accepts good input
  }

  SECTION("xrSetGraspTargetPlacementSDFG") {
    XrGraspTargetPlacementSDFG p{
        XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, app.local, {{0, 0, 0, 1}, {0, 0, -0.4f}}};
    CHECK(ext.place(XR_NULL_HANDLE, &p) == XR_ERROR_HANDLE_INVALID);
    CHECK(ext.place(badTarget, &p) == XR_ERROR_HANDLE_INVALID);
    CHECK(ext.place(good, nullptr) == XR_ERROR_VALIDATION_FAILURE);
    auto q = p;
    q.type = XR_TYPE_GRASP_STATE_SDFG;
    CHECK(ext.place(good, &q) == XR_ERROR_VALIDATION_FAILURE);
    q = p;
    q.space = reinterpret_cast<XrSpace>(uintptr_t{0x123450000});
    CHECK(ext.place(good, &q) == XR_ERROR_HANDLE_INVALID);
    q = p;
    q.pose.orientation = {nan, 0, 0, 1};
    CHECK(ext.place(good, &q) == XR_ERROR_VALIDATION_FAILURE);
    q.pose.orientation = {0, 0, 0, 0};
    CHECK(ext.place(good, &q) == XR_ERROR_POSE_INVALID);
    CHECK(ext.place(good, &p) == XR_SUCCESS);
  }

  SECTION("xrGetGraspStateSDFG") {
    XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_LEFT_EXT};
    XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG};
    st.squeeze = 55.0f;
    CHECK(ext.state(XR_NULL_HANDLE, &gi, &st) == XR_ERROR_HANDLE_INVALID);
    CHECK(ext.state(badSession, &gi, &st) == XR_ERROR_HANDLE_INVALID);
    CHECK(ext.state(app.session, nullptr, &st) == XR_ERROR_VALIDATION_FAILURE);
    CHECK(ext.state(app.session, &gi, nullptr) == XR_ERROR_VALIDATION_FAILURE);
    auto g = gi;
    g.type = XR_TYPE_GRASP_STATE_SDFG;
    CHECK(ext.state(app.session, &g, &st) == XR_ERROR_VALIDATION_FAILURE);
    g = gi;
    g.hand = XrHandEXT(0);
    CHECK(ext.state(app.session, &g, &st) == XR_ERROR_VALIDATION_FAILURE);
    g.hand = XrHandEXT(3);
    CHECK(ext.state(app.session, &g, &st) == XR_ERROR_VALIDATION_FAILURE);
    auto s = st;
    s.type = XR_TYPE_GRASP_STATE_GET_INFO_SDFG;
    CHECK(ext.state(app.session, &gi, &s) == XR_ERROR_VALIDATION_FAILURE);
    CHECK(st.squeeze == 55.0f);  // untouched by the failures
    CHECK(ext.state(app.session, &gi, &st) == XR_SUCCESS);
    CHECK(st.isGrasping == XR_FALSE);
    CHECK(st.squeeze == 0.0f);
  }

  SECTION("xrSetGraspOptionsSDFG") {
    XrGraspOptionsSDFG o{XR_TYPE_GRASP_OPTIONS_SDFG};
    CHECK(ext.options(XR_NULL_HANDLE, &o) == XR_ERROR_HANDLE_INVALID);
    CHECK(ext.options(badSession, &o) == XR_ERROR_HANDLE_INVALID);
    CHECK(ext.options(app.session, nullptr) == XR_ERROR_VALIDATION_FAILURE);
    auto p = o;
    p.type = XR_TYPE_GRASP_STATE_SDFG;
    CHECK(ext.options(app.session, &p) == XR_ERROR_VALIDATION_FAILURE);
    p = o;
    p.solver = XrGraspSolverSDFG(7);
    CHECK(ext.options(app.session, &p) == XR_ERROR_VALIDATION_FAILURE);
    p = o;
    p.tipRadius = nan;
    CHECK(ext.options(app.session, &p) == XR_ERROR_VALIDATION_FAILURE);
    p.tipRadius = -0.01f;
    CHECK(ext.options(app.session, &p) == XR_ERROR_VALIDATION_FAILURE);
    p = o;
    p.boxSize = {0.2f, 0.0f, 0.2f};
    p.boxPose.orientation.w = 1;
    CHECK(ext.options(app.session, &p) == XR_ERROR_VALIDATION_FAILURE);
    p.boxSize = {0.2f, 0.2f, 0.2f};
    p.boxPose.orientation = {0, 0, 0, 3};
    CHECK(ext.options(app.session, &p) == XR_ERROR_POSE_INVALID);
    p = o;
    p.resolution = 1;
    CHECK(ext.options(app.session, &p) == XR_ERROR_VALIDATION_FAILURE);
    p.resolution = 129;
    CHECK(ext.options(app.session, &p) == XR_ERROR_VALIDATION_FAILURE);
    p = o;
    p.curlStep = 2.0f;
    CHECK(ext.options(app.session, &p) == XR_ERROR_VALIDATION_FAILURE);
    p = o;
    p.grabThreshold = nan;
    CHECK(ext.options(app.session, &p) == XR_ERROR_VALIDATION_FAILURE);
    CHECK(ext.options(app.session, &o) == XR_SUCCESS);  // all zero: the defaults
    p = o;
    p.solver = XR_GRASP_SOLVER_PAPER_SDFG;
    p.resolution = 24;
    p.curlStep = 0.05f;
    CHECK(ext.options(app.session, &p) == XR_SUCCESS);
  }

  if (good != XR_NULL_HANDLE) CHECK(ext.destroy(good) == XR_SUCCESS);
  CHECK(validationLog().empty());
}
