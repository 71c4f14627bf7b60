// XR_SDFG_auto_grasp entry points. Each: resolve and check the handle, one check per argument,
// one call into the core, one conversion of the result. A failing call changes nothing. The
// session's lock is taken only to hand over to the engine: copies of the app's arrays happen
// before it, log lines of refusals after it (docs/threading.md).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "intercepts.h"
#include "log.h"
#include "state.h"

#if SDFG_LAYER_VULKAN
#include "vulkan/vk_grasp_backend.h"
#endif

namespace sdfg::layer {
namespace {

#define SDFG_VERIFY(cmd, cond, result, ...) \
  if (!(cond)) return logError(result, cmd, __VA_ARGS__)
#define SDFG_VERIFY_NOT_NULL(cmd, arg) \
  SDFG_VERIFY(cmd, (arg) != nullptr, XR_ERROR_VALIDATION_FAILURE, "(" #arg ") is null")
// `type` is compared as an integer: an out-of-range value must not be loaded as an enum.
#define SDFG_VERIFY_TYPE(cmd, arg, expected)                                               \
  SDFG_VERIFY_NOT_NULL(cmd, arg);                                                          \
  SDFG_VERIFY(cmd, rawEnum((arg)->type) == int32_t(expected), XR_ERROR_VALIDATION_FAILURE, \
              "(" #arg "->type) is %d, expected " #expected, int(rawEnum((arg)->type)))
// A `next` chain is walked only when it ends within kMaxChainLength structs.
#define SDFG_VERIFY_CHAIN(cmd, chain)                                    \
  SDFG_VERIFY(cmd, chainLength(chain) >= 0, XR_ERROR_VALIDATION_FAILURE, \
              "(" #chain ") has more than %zu structs: a cycle, or not a chain", kMaxChainLength)

std::shared_ptr<SessionState> findSession(XrSession session) {
  return sessions().find(key(session));
}

// The target and its live session, or nulls.
std::pair<std::shared_ptr<TargetState>, std::shared_ptr<SessionState>> findTarget(
    XrGraspTargetSDFG target) {
  auto t = targets().find(key(target));
  auto s = t == nullptr ? nullptr : t->session.lock();
  if (s == nullptr) return {nullptr, nullptr};
  return {t, s};
}

// The placement's own checks; whether its space is one of the session's is checked under the
// session's lock (liveSpace).
XrResult verifyPlacement(const char* cmd, const XrGraspTargetPlacementSDFG* placement) {
  SDFG_VERIFY_TYPE(cmd, placement, XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG);
  SDFG_VERIFY_CHAIN(cmd, placement->next);
  SDFG_VERIFY(cmd, placement->space != XR_NULL_HANDLE, XR_ERROR_HANDLE_INVALID,
              "(placement->space) is XR_NULL_HANDLE");
  SDFG_VERIFY(cmd, isFinitePose(placement->pose), XR_ERROR_VALIDATION_FAILURE,
              "(placement->pose) is not finite");
  SDFG_VERIFY(cmd, isUnitQuaternion(placement->pose.orientation), XR_ERROR_POSE_INVALID,
              "(placement->pose.orientation) is not a unit quaternion");
  return XR_SUCCESS;
}

// A reference or action space the app made on `s` and has not destroyed (nor is destroying).
// The caller holds s.mutex.
bool liveSpace(const SessionState& s, XrSpace space) {
  const auto use = s.spaces.find(key(space));
  return use != s.spaces.end() && !use->second.dying;
}

// Why a call found the session unable to take it, read under the session's lock and logged
// after it (the log may call the runtime).
enum class Refusal { none, sessionLost, notASpace, noGpu, engine };

XrResult refuse(const char* cmd, Refusal why, Status engine = Status::ok) {
  switch (why) {
    case Refusal::none:
      break;
    case Refusal::sessionLost:
      // The handle is going away under the call (a destroy on another thread): the spec's
      // answer for a handle that is no longer valid. Not SESSION_LOST: the runtime did not lose
      // the session.
      return logError(XR_ERROR_HANDLE_INVALID, cmd, "the session is being destroyed");
    case Refusal::notASpace:
      return logError(XR_ERROR_HANDLE_INVALID, cmd,
                      "(placement->space) is not a reference or action space of this session");
    case Refusal::noGpu:
      return logError(XR_ERROR_FEATURE_UNSUPPORTED, cmd,
                      "this session builds its SDFs on the CPU (gpu = false, no usable Vulkan "
                      "device, or a GPU failure): Vulkan buffer targets need the GPU path; pass "
                      "arrays");
    case Refusal::engine:
      return logError(toXrResult(engine), cmd, "refused by the grasp engine (%s)",
                      toString(engine));
  }
  return XR_SUCCESS;
}

// Copies `n` positions from the app's array to `out` and bounds them; false when a coordinate
// is NaN or infinite (then only `out` changed). The hot part of a vertex update, paid in every
// frame of a deforming target: a memcpy, then one pass over the copy as floats in blocks of 12
// (4 vertices, so lane j always holds axis j % 3) that the compiler vectorizes, unlike a loop per
// vertex. `check` turns NaN at the first NaN or infinity: x - x is 0 for a finite x.
bool copyFinite(const XrVector3f* in, uint32_t n, glm::vec3* out, Aabb& bounds) {
  static_assert(sizeof(XrVector3f) == sizeof(glm::vec3));
  std::memcpy(static_cast<void*>(out), in, size_t(n) * sizeof(glm::vec3));
  const float* f = &out[0].x;
  const size_t m = size_t(n) * 3;
  constexpr size_t kLanes = 12;
  float lo[kLanes], hi[kLanes], check[kLanes];
  for (size_t j = 0; j < kLanes; ++j) {
    lo[j] = std::numeric_limits<float>::infinity();
    hi[j] = -lo[j];
    check[j] = 0.0f;
  }
  size_t i = 0;
  for (; i + kLanes <= m; i += kLanes) {
    for (size_t j = 0; j < kLanes; ++j) {
      const float x = f[i + j];
      check[j] += x - x;
      lo[j] = x < lo[j] ? x : lo[j];
      hi[j] = x > hi[j] ? x : hi[j];
    }
  }
  for (size_t j = 0; i < m; ++i, ++j) {  // the last 0..3 vertices; m - i is a multiple of 3
    const float x = f[i];
    check[j] += x - x;
    lo[j] = x < lo[j] ? x : lo[j];
    hi[j] = x > hi[j] ? x : hi[j];
  }
  glm::vec3 boxLo(std::numeric_limits<float>::infinity()), boxHi(-boxLo);
  float sum = 0.0f;
  for (size_t j = 0; j < kLanes; ++j) {
    sum += check[j];
    boxLo[int(j % 3)] = std::min(boxLo[int(j % 3)], lo[j]);
    boxHi[int(j % 3)] = std::max(boxHi[int(j % 3)], hi[j]);
  }
  bounds = Aabb{boxLo, boxHi};
  return sum == 0.0f;
}

// copyFinite with the documented error: names the first non-finite vertex, looked for only
// when the copy found one.
XrResult copyFiniteVertices(const char* cmd, const XrGraspTargetVerticesSDFG* v, glm::vec3* out,
                            Aabb& bounds) {
  if (copyFinite(v->vertices, v->vertexCount, out, bounds)) return XR_SUCCESS;
  for (uint32_t i = 0; i < v->vertexCount; ++i) {
    const XrVector3f& p = v->vertices[i];
    SDFG_VERIFY(cmd, std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z),
                XR_ERROR_VALIDATION_FAILURE, "(vertices[%u]) is not finite", i);
  }
  // Not reached (copyFinite saw a non-finite coordinate), but never taken for a success.
  return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(vertices) has a non-finite coordinate");
}

// The create call's checks of the CPU arrays fused with their copy into `out`, one streaming
// pass over each array: counts, pointers, finite coordinates, index range, no triangle that
// repeats a vertex. What needs a gather over the whole mesh (zero-area triangles) is the set-up's
// on the session's worker: at 400k triangles it alone took milliseconds of the app's frame.
// On failure nothing but `out` changed.
XrResult copyArrays(const char* cmd, const XrGraspTargetVerticesSDFG* v, TriangleMesh& out) {
  SDFG_VERIFY(cmd, v->vertexCount >= 3 && v->vertexCount <= XR_MAX_GRASP_TARGET_VERTICES_SDFG,
              XR_ERROR_VALIDATION_FAILURE, "(vertexCount) is %u, must be in 3..%u", v->vertexCount,
              XR_MAX_GRASP_TARGET_VERTICES_SDFG);
  SDFG_VERIFY_NOT_NULL(cmd, v->vertices);
  SDFG_VERIFY(cmd,
              v->indexCount >= 3 && v->indexCount % 3 == 0 &&
                  v->indexCount <= XR_MAX_GRASP_TARGET_INDICES_SDFG,
              XR_ERROR_VALIDATION_FAILURE, "(indexCount) is %u, must be a multiple of 3 in 3..%u",
              v->indexCount, XR_MAX_GRASP_TARGET_INDICES_SDFG);
  SDFG_VERIFY_NOT_NULL(cmd, v->indices);
  out.positions.resize(v->vertexCount);
  Aabb bounds;
  if (XrResult r = copyFiniteVertices(cmd, v, out.positions.data(), bounds); r != XR_SUCCESS)
    return r;
  // Copied first (one write of fresh memory, not a zero-fill and a write), then checked.
  out.indices.assign(v->indices, v->indices + v->indexCount);
  uint32_t largest = 0, repeats = 0;
  const uint32_t* idx = out.indices.data();
  for (uint32_t t = 0; t < v->indexCount; t += 3) {
    const uint32_t a = idx[t], b = idx[t + 1], c = idx[t + 2];
    largest = std::max(largest, std::max(a, std::max(b, c)));
    repeats |= uint32_t(a == b) | uint32_t(b == c) | uint32_t(a == c);
  }
  if (largest >= v->vertexCount || repeats != 0) {
    for (uint32_t t = 0; t < v->indexCount; t += 3) {
      for (uint32_t k = 0; k < 3; ++k)
        SDFG_VERIFY(cmd, v->indices[t + k] < v->vertexCount, XR_ERROR_VALIDATION_FAILURE,
                    "(indices[%u]) is %u, the mesh has %u vertices", t + k, v->indices[t + k],
                    v->vertexCount);
      const uint32_t a = v->indices[t], b = v->indices[t + 1], c = v->indices[t + 2];
      SDFG_VERIFY(cmd, a != b && b != c && a != c, XR_ERROR_VALIDATION_FAILURE,
                  "(indices) triangle %u repeats a vertex (%u, %u, %u)", t / 3, a, b, c);
    }
  }
  return XR_SUCCESS;
}

// The update's checks (verifyVertices with update = true) fused with the copy into `out` and its
// bounds, in one pass over the app's array. On failure nothing but `out`'s contents changed.
XrResult copyVertices(const char* cmd, const XrGraspTargetVerticesSDFG* v,
                      uint32_t expectedVertexCount, std::vector<glm::vec3>& out, Aabb& bounds) {
  SDFG_VERIFY(cmd, v->vertexCount >= 3 && v->vertexCount <= XR_MAX_GRASP_TARGET_VERTICES_SDFG,
              XR_ERROR_VALIDATION_FAILURE, "(vertexCount) is %u, must be in 3..%u", v->vertexCount,
              XR_MAX_GRASP_TARGET_VERTICES_SDFG);
  SDFG_VERIFY_NOT_NULL(cmd, v->vertices);
  SDFG_VERIFY(cmd, v->vertexCount == expectedVertexCount, XR_ERROR_VALIDATION_FAILURE,
              "(vertexCount) is %u, the target has %u", v->vertexCount, expectedVertexCount);
  SDFG_VERIFY(cmd, v->indexCount == 0 && v->indices == nullptr, XR_ERROR_VALIDATION_FAILURE,
              "(indexCount) and (indices) must be 0 and NULL on update: the topology is fixed");
  out.resize(v->vertexCount);
  return copyFiniteVertices(cmd, v, out.data(), bounds);
}

// Checks a Vulkan-buffer description; `target` (update) fixes the counts.
XrResult verifyBuffers(const char* cmd, const XrGraspTargetVulkanBuffersSDFG* b,
                       const TargetState* target) {
  SDFG_VERIFY(cmd, b->vertexBuffer != VK_NULL_HANDLE, XR_ERROR_VALIDATION_FAILURE,
              "(vertexBuffer) is VK_NULL_HANDLE");
  SDFG_VERIFY(cmd, b->indexBuffer != VK_NULL_HANDLE, XR_ERROR_VALIDATION_FAILURE,
              "(indexBuffer) is VK_NULL_HANDLE");
  SDFG_VERIFY(cmd, b->vertexCount >= 3 && b->vertexCount <= XR_MAX_GRASP_TARGET_VERTICES_SDFG,
              XR_ERROR_VALIDATION_FAILURE, "(vertexCount) is %u, must be in 3..%u", b->vertexCount,
              XR_MAX_GRASP_TARGET_VERTICES_SDFG);
  SDFG_VERIFY(cmd,
              b->indexCount >= 3 && b->indexCount % 3 == 0 &&
                  b->indexCount <= XR_MAX_GRASP_TARGET_INDICES_SDFG,
              XR_ERROR_VALIDATION_FAILURE, "(indexCount) is %u, must be a multiple of 3 in 3..%u",
              b->indexCount, XR_MAX_GRASP_TARGET_INDICES_SDFG);
  SDFG_VERIFY(cmd, b->vertexStride >= 12 && b->vertexStride % 4 == 0, XR_ERROR_VALIDATION_FAILURE,
              "(vertexStride) is %u, must be >= 12 and a multiple of 4", b->vertexStride);
  SDFG_VERIFY(cmd, b->vertexOffset % 4 == 0, XR_ERROR_VALIDATION_FAILURE,
              "(vertexOffset) is %llu, must be a multiple of 4",
              (unsigned long long)b->vertexOffset);
  const int32_t indexType = rawEnum(b->indexType);
  SDFG_VERIFY(cmd, indexType == VK_INDEX_TYPE_UINT16 || indexType == VK_INDEX_TYPE_UINT32,
              XR_ERROR_VALIDATION_FAILURE, "(indexType) is %d, must be UINT16 or UINT32",
              int(indexType));
  const VkDeviceSize indexSize = indexType == VK_INDEX_TYPE_UINT16 ? 2 : 4;
  SDFG_VERIFY(cmd, b->indexOffset % indexSize == 0, XR_ERROR_VALIDATION_FAILURE,
              "(indexOffset) is %llu, must be a multiple of the index size",
              (unsigned long long)b->indexOffset);
  const float lo[3] = {b->boundsMin.x, b->boundsMin.y, b->boundsMin.z};
  const float hi[3] = {b->boundsMax.x, b->boundsMax.y, b->boundsMax.z};
  for (int a = 0; a < 3; ++a) {
    SDFG_VERIFY(cmd, std::isfinite(lo[a]) && std::isfinite(hi[a]) && lo[a] <= hi[a],
                XR_ERROR_VALIDATION_FAILURE,
                "(boundsMin) and (boundsMax) must be finite with boundsMin <= boundsMax");
  }
  if (target != nullptr) {
    SDFG_VERIFY(cmd, b->vertexCount == target->vertexCount && b->indexCount == target->indexCount,
                XR_ERROR_VALIDATION_FAILURE,
                "(vertexCount, indexCount) are %u, %u; the target has %u, %u", b->vertexCount,
                b->indexCount, target->vertexCount, target->indexCount);
  }
  return XR_SUCCESS;
}

#if SDFG_LAYER_VULKAN
VkMeshBuffers toMeshBuffers(const XrGraspTargetVulkanBuffersSDFG& b) {
  VkMeshBuffers m;
  m.positions = b.vertexBuffer;
  m.positionOffset = b.vertexOffset;
  m.positionStride = b.vertexStride;
  m.vertexCount = b.vertexCount;
  m.indices = b.indexBuffer;
  m.indexOffset = b.indexOffset;
  m.indexType = b.indexType;
  m.indexCount = b.indexCount;
  return m;
}
#endif

Aabb toBounds(const XrGraspTargetVulkanBuffersSDFG& b) {
  Aabb a;
  a.min = glm::vec3(b.boundsMin.x, b.boundsMin.y, b.boundsMin.z);
  a.max = glm::vec3(b.boundsMax.x, b.boundsMax.y, b.boundsMax.z);
  return a;
}

// The GPU path's calls for a buffer target, made on the device by the next pump (no wait here).
void postDeviceMesh(DeferredMailbox& gpu, uint64_t id, const XrGraspTargetVulkanBuffersSDFG& b) {
#if SDFG_LAYER_VULKAN
  const VkMeshBuffers buffers = toMeshBuffers(b);
  gpu.post([id, buffers](DeferredSdfBackend& device) {
    (void)static_cast<VkGraspBackend&>(device).setDeviceMesh(id, buffers);
  });
  gpu.noteDeviceMesh(id, true);
#else
  (void)gpu;
  (void)id;
  (void)b;
#endif
}

// The GPU path forgets a buffer target the engine refused, at the next pump: nothing read it.
void forgetDeviceMesh(DeferredMailbox& gpu, uint64_t id) {
  gpu.noteDeviceMesh(id, false);
#if SDFG_LAYER_VULKAN
  gpu.post([id](DeferredSdfBackend& device) {
    (void)static_cast<VkGraspBackend&>(device).removeDeviceMesh(id);
  });
#else
  (void)id;
#endif
}

// Takes the target out of its session: a hand holding it lets go (its fingers return to the
// user's pose at the next locate), it is unplaced and leaves the session's table.
void removeFromSession(SessionState& s, TargetState& t) {
  std::lock_guard lock(s.mutex);
  if (s.grasp != nullptr) {
    for (Hand hand : {Hand::left, Hand::right}) {
      const HandGrasp& g = s.grasp->grasp(hand);
      if (g.holdsTarget() && g.target == t.handle)
        noteGraspChange(s, hand, true, t.handle, /*destroyed=*/true);
    }
    s.grasp->removeTarget(t.handle);
    publishShownHands(s);  // the next locate shows the hand let go
  }
  unplaceTarget(s, t);
  s.targets.erase(t.handle);
}

enum class BufferTargetRemoval {
  removed,     // from the device and the session: the GPU reads its buffers no more
  deviceGone,  // the session's GPU path was shut down (the session is being destroyed)
  stillRead,   // the GPU's reads did not end in time: nothing changed
};

// Removes a buffer target from the device and then from the session, with no lock held on
// entry. The device is held meanwhile (DeferredMailbox::exclusive), so no pump submits a build
// of the target or collects one between the two steps: either both happen, or, when the GPU's
// reads of the app's buffers in flight do not end within the bounds (the device's 2 s, or
// another thread holding the device as long), neither.
BufferTargetRemoval removeBufferTarget(DeferredMailbox& gpu, SessionState& s, TargetState& t) {
#if SDFG_LAYER_VULKAN
  bool readsEnded = false;
  const DeferredMailbox::Access access = gpu.exclusive([&](DeferredSdfBackend& device) {
    readsEnded = static_cast<VkGraspBackend&>(device).removeDeviceMesh(t.handle);
    if (!readsEnded) return;
    gpu.noteDeviceMesh(t.handle, false);
    // The session lock inside the device's claim: nobody waits for a claim holding that lock.
    removeFromSession(s, t);
  });
  if (access == DeferredMailbox::Access::shut_down) return BufferTargetRemoval::deviceGone;
  return access == DeferredMailbox::Access::done && readsEnded ? BufferTargetRemoval::removed
                                                               : BufferTargetRemoval::stillRead;
#else
  (void)gpu;
  (void)s;
  (void)t;
  return BufferTargetRemoval::deviceGone;
#endif
}

}  // namespace

XrResult XRAPI_CALL SdfgXrCreateGraspTargetSDFG(XrSession session,
                                                const XrGraspTargetCreateInfoSDFG* createInfo,
                                                XrGraspTargetSDFG* target) {
  constexpr const char* cmd = "xrCreateGraspTargetSDFG";
  SDFG_ENTRY_BEGIN
  auto s = findSession(session);
  SDFG_VERIFY(cmd, s != nullptr, XR_ERROR_HANDLE_INVALID, "(session) is not valid");
  SDFG_VERIFY_TYPE(cmd, createInfo, XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG);
  SDFG_VERIFY_NOT_NULL(cmd, target);
  SDFG_VERIFY_CHAIN(cmd, createInfo->next);
  SDFG_VERIFY(cmd,
              countInChain(createInfo->next, XR_TYPE_GRASP_TARGET_VERTICES_SDFG) +
                      countInChain(createInfo->next, XR_TYPE_GRASP_TARGET_VULKAN_BUFFERS_SDFG) +
                      countInChain(createInfo->next, XR_TYPE_GRASP_TARGET_SHAPE_SDFG) ==
                  1,
              XR_ERROR_VALIDATION_FAILURE,
              "(createInfo->next) must chain exactly one XrGraspTargetVerticesSDFG, "
              "XrGraspTargetVulkanBuffersSDFG or XrGraspTargetShapeSDFG");
  const auto* arrays = findInChain<const XrGraspTargetVerticesSDFG>(
      createInfo->next, XR_TYPE_GRASP_TARGET_VERTICES_SDFG);
  const auto* buffers = findInChain<const XrGraspTargetVulkanBuffersSDFG>(
      createInfo->next, XR_TYPE_GRASP_TARGET_VULKAN_BUFFERS_SDFG);
  const auto* shapeInfo =
      findInChain<const XrGraspTargetShapeSDFG>(createInfo->next, XR_TYPE_GRASP_TARGET_SHAPE_SDFG);
  const auto* settings = findInChain<const XrGraspTargetSettingsSDFG>(
      createInfo->next, XR_TYPE_GRASP_TARGET_SETTINGS_SDFG);
  const auto* role = findInChain<const XrGraspTargetRoleInfoSDFG>(createInfo->next,
                                                                  XR_TYPE_GRASP_TARGET_ROLE_SDFG);
  if (XrResult r = verifyTargetSettings(cmd, settings); r != XR_SUCCESS) return r;
  if (XrResult r = verifyTargetRole(cmd, role); r != XR_SUCCESS) return r;
  if (XrResult r = verifyPlacement(cmd, &createInfo->placement); r != XR_SUCCESS) return r;
  // The checks and the copy of the app's arrays (up to 2^24 vertices) happen before the lock.
  TriangleMesh mesh;
  SharedMesh deviceCopy;
  AnalyticShape shape;
  if (shapeInfo != nullptr) {
    if (XrResult r = readShape(cmd, shapeInfo, shape); r != XR_SUCCESS) return r;
  } else if (buffers != nullptr) {
    // Fixed when the session was made: no lock needed.
    SDFG_VERIFY(cmd, s->vulkan, XR_ERROR_GRAPHICS_DEVICE_INVALID,
                "Vulkan buffers need a session with a Vulkan graphics binding");
    if (XrResult r = verifyBuffers(cmd, buffers, nullptr); r != XR_SUCCESS) return r;
  } else if (XrResult r = copyArrays(cmd, arrays, mesh); r != XR_SUCCESS) {
    return r;
  } else if (s->gpuForArrayTargets) {
    // The GPU path's own copy, made here rather than by the engine under the lock. The flag is
    // fixed when the session is made.
    deviceCopy.positions = std::make_shared<const std::vector<glm::vec3>>(mesh.positions);
    deviceCopy.indices = std::make_shared<const std::vector<uint32_t>>(mesh.indices);
  }
  auto t = std::make_shared<TargetState>();
  t->handle = newLayerHandle();
  t->session = s;
  t->placed = false;  // placeTarget below, under the lock
  t->shape = shapeInfo != nullptr;
  t->vertexCount = buffers != nullptr  ? buffers->vertexCount
                   : arrays != nullptr ? arrays->vertexCount
                                       : 0;
  t->indexCount = buffers != nullptr  ? buffers->indexCount
                  : arrays != nullptr ? arrays->indexCount
                                      : 0;
  t->deviceBuffers = buffers != nullptr;
  Refusal refusal = Refusal::none;
  Status status = Status::ok;
  {
    std::lock_guard lock(s->mutex);
    if (s->grasp == nullptr) {
      refusal = Refusal::sessionLost;
    } else if (!liveSpace(*s, createInfo->placement.space)) {
      refusal = Refusal::notASpace;
    } else if (shapeInfo != nullptr) {
      status = s->grasp->addShapeTarget(t->handle, shape);
    } else if (buffers != nullptr) {
      if (s->gpu == nullptr || !s->grasp->deferredUsable()) refusal = Refusal::noGpu;
      if (refusal == Refusal::none) {
        // Registered on the device by the next pump, before any build the engine asks for it.
        postDeviceMesh(*s->gpu, t->handle, *buffers);
        status = s->grasp->addDeviceTarget(t->handle, toBounds(*buffers));
        if (status != Status::ok) forgetDeviceMesh(*s->gpu, t->handle);
      }
    } else {
      // The rest of the set-up runs on the session's worker: the zero-area check, turning every
      // part outward (meshes come wound either way, or both), the BVH. syncGrasps logs once what
      // it found, or why it refused the mesh, and XrGraspTargetsSetupInfoSDFG reports it.
      status = s->grasp->addTarget(t->handle, std::move(mesh), std::move(deviceCopy));
    }
    if (refusal == Refusal::none && status == Status::ok) {
      applyTargetSettings(*s, t->handle, settings);
      // A plane is a floor or a wall: scene geometry unless the app says otherwise.
      const XrGraspTargetRoleInfoSDFG planeRole{XR_TYPE_GRASP_TARGET_ROLE_SDFG, nullptr,
                                                XR_GRASP_TARGET_ROLE_SCENE_SDFG};
      const bool plane = shapeInfo != nullptr && shape.kind == ShapeKind::plane;
      applyTargetRole(*s, t->handle, role != nullptr ? role : plane ? &planeRole : nullptr);
      placeTarget(*s, *t, createInfo->placement.space, createInfo->placement.pose);
      s->targets[t->handle] = t;
    }
  }
  if (refusal == Refusal::none && status != Status::ok) refusal = Refusal::engine;
  if (refusal != Refusal::none) return refuse(cmd, refusal, status);
  const uint64_t handle = t->handle;
  targets().insert(handle, std::move(t));
  *target = fromKey<XrGraspTargetSDFG>(handle);
  return XR_SUCCESS;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrDestroyGraspTargetSDFG(XrGraspTargetSDFG target) {
  constexpr const char* cmd = "xrDestroyGraspTargetSDFG";
  SDFG_ENTRY_BEGIN
  auto [t, s] = findTarget(target);
  SDFG_VERIFY(cmd, t != nullptr, XR_ERROR_HANDLE_INVALID, "(target) is not valid");
  std::shared_ptr<DeferredMailbox> gpu;
  if (t->deviceBuffers) {
    std::lock_guard lock(s->mutex);
    gpu = s->gpu;
  }
  // A buffer target: the layer's reads of the app's buffers end first (waited for with no lock
  // held), so the app may free them when this returns. When they do not end in time the app
  // must not free them: the call fails and changes nothing, and a later destroy tries again.
  const BufferTargetRemoval removal =
      gpu != nullptr ? removeBufferTarget(*gpu, *s, *t) : BufferTargetRemoval::deviceGone;
  if (removal == BufferTargetRemoval::stillRead)
    return logError(XR_ERROR_RUNTIME_FAILURE, cmd,
                    "the GPU still reads the target's buffers (a build in flight did not end "
                    "within the layer's bound): the target is kept unchanged; do not free its "
                    "buffers yet, and call xrDestroyGraspTargetSDFG again");
  if (removal != BufferTargetRemoval::removed) removeFromSession(*s, *t);
  targets().erase(t->handle);
  return XR_SUCCESS;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrUpdateGraspTargetVerticesSDFG(XrGraspTargetSDFG target,
                                                        const void* vertices) {
  constexpr const char* cmd = "xrUpdateGraspTargetVerticesSDFG";
  SDFG_ENTRY_BEGIN
  auto [t, s] = findTarget(target);
  SDFG_VERIFY(cmd, t != nullptr, XR_ERROR_HANDLE_INVALID, "(target) is not valid");
  SDFG_VERIFY_NOT_NULL(cmd, vertices);
  const auto* base = static_cast<const XrBaseInStructure*>(vertices);
  SDFG_VERIFY_CHAIN(cmd, base->next);
  const int32_t type = rawEnum(base->type);
  SDFG_VERIFY(cmd, !t->shape, XR_ERROR_VALIDATION_FAILURE,
              "(target) is an analytic shape: it has no vertices (destroy and create it again "
              "to change it)");
  Refusal refusal = Refusal::none;
  Status status = Status::ok;
  if (type == XR_TYPE_GRASP_TARGET_VULKAN_BUFFERS_SDFG) {
    const auto* b = static_cast<const XrGraspTargetVulkanBuffersSDFG*>(vertices);
    SDFG_VERIFY(cmd, t->deviceBuffers, XR_ERROR_VALIDATION_FAILURE,
                "(vertices) are Vulkan buffers; the target was created from arrays");
    if (XrResult r = verifyBuffers(cmd, b, t.get()); r != XR_SUCCESS) return r;
    {
      std::lock_guard lock(s->mutex);
      if (s->grasp == nullptr) {
        refusal = Refusal::sessionLost;
      } else if (s->gpu == nullptr || !s->grasp->deferredUsable()) {
        refusal = Refusal::noGpu;
      } else {
        // The new buffers reach the device before the build the touch asks for (posted calls
        // run first in a pump).
        postDeviceMesh(*s->gpu, t->handle, *b);
        status = s->grasp->touchTarget(t->handle);
        if (status == Status::ok) status = s->grasp->updateTargetBounds(t->handle, toBounds(*b));
      }
    }
    if (refusal == Refusal::none && status != Status::ok) refusal = Refusal::engine;
    return refuse(cmd, refusal, status);
  }
  SDFG_VERIFY(cmd, type == XR_TYPE_GRASP_TARGET_VERTICES_SDFG, XR_ERROR_VALIDATION_FAILURE,
              "(vertices->type) is %d, expected XR_TYPE_GRASP_TARGET_VERTICES_SDFG", int(type));
  SDFG_VERIFY(cmd, !t->deviceBuffers, XR_ERROR_VALIDATION_FAILURE,
              "(vertices) are arrays; the target was created from Vulkan buffers");
  const auto* v = static_cast<const XrGraspTargetVerticesSDFG*>(vertices);
  // A buffer the session's worker is done with (no allocation, no fresh pages), taken under the
  // lock; the one pass over the app's array (check, copy, bound) happens outside it. A deforming
  // mesh pays this every frame on the app's thread; everything else is the worker's: the refit,
  // and refusing positions that collapse a triangle (the target keeps its last shape; syncGrasps
  // logs it once). Checked here, that gather over every triangle was most of the 3.9 ms a frame
  // the 400k-triangle armadillo's updates cost (docs/benchmarks.md, frame cost).
  // On a session whose GPU builds array targets, the GPU path's copy of the positions is made
  // outside the lock too, and the one it replaces is freed after it.
  std::vector<glm::vec3> positions;
  bool deviceCopy = false;
  {
    std::lock_guard lock(s->mutex);
    if (s->grasp == nullptr) {
      refusal = Refusal::sessionLost;
    } else {
      positions = s->grasp->vertexBuffer(t->handle);
      deviceCopy = s->grasp->wantsDevicePositions(t->handle);
    }
  }
  if (refusal != Refusal::none) return refuse(cmd, refusal);
  Aabb bounds;
  if (XrResult r = copyVertices(cmd, v, t->vertexCount, positions, bounds); r != XR_SUCCESS)
    return r;
  std::shared_ptr<const std::vector<glm::vec3>> devicePositions;
  if (deviceCopy) devicePositions = std::make_shared<const std::vector<glm::vec3>>(positions);
  {
    std::lock_guard lock(s->mutex);
    if (s->grasp == nullptr)
      refusal = Refusal::sessionLost;
    else
      status =
          s->grasp->updateTargetVertices(t->handle, std::move(positions), bounds, devicePositions);
  }
  if (refusal == Refusal::none && status != Status::ok) refusal = Refusal::engine;
  return refuse(cmd, refusal, status);
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrSetGraspTargetPlacementSDFG(XrGraspTargetSDFG target,
                                                      const XrGraspTargetPlacementSDFG* placement) {
  constexpr const char* cmd = "xrSetGraspTargetPlacementSDFG";
  SDFG_ENTRY_BEGIN
  auto [t, s] = findTarget(target);
  SDFG_VERIFY(cmd, t != nullptr, XR_ERROR_HANDLE_INVALID, "(target) is not valid");
  if (XrResult r = verifyPlacement(cmd, placement); r != XR_SUCCESS) return r;
  Refusal refusal = Refusal::none;
  {
    std::lock_guard lock(s->mutex);
    if (!liveSpace(*s, placement->space)) {
      refusal = Refusal::notASpace;
    } else {
      // Placed again (also after its space was destroyed): it takes part from the next sync.
      placeTarget(*s, *t, placement->space, placement->pose);
    }
  }
  return refuse(cmd, refusal);
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrGetGraspStateSDFG(XrSession session,
                                            const XrGraspStateGetInfoSDFG* getInfo,
                                            XrGraspStateSDFG* state) {
  constexpr const char* cmd = "xrGetGraspStateSDFG";
  SDFG_ENTRY_BEGIN
  auto s = findSession(session);
  SDFG_VERIFY(cmd, s != nullptr, XR_ERROR_HANDLE_INVALID, "(session) is not valid");
  SDFG_VERIFY_TYPE(cmd, getInfo, XR_TYPE_GRASP_STATE_GET_INFO_SDFG);
  SDFG_VERIFY_TYPE(cmd, state, XR_TYPE_GRASP_STATE_SDFG);
  SDFG_VERIFY_CHAIN(cmd, getInfo->next);
  SDFG_VERIFY_CHAIN(cmd, state->next);
  const int32_t handValue = rawEnum(getInfo->hand);
  SDFG_VERIFY(cmd, handValue == XR_HAND_LEFT_EXT || handValue == XR_HAND_RIGHT_EXT,
              XR_ERROR_VALIDATION_FAILURE, "(getInfo->hand) is %d", int(handValue));
  const Hand hand = handValue == XR_HAND_LEFT_EXT ? Hand::left : Hand::right;
  std::unique_lock lock(s->mutex);
  if (s->grasp == nullptr) {
    lock.unlock();
    return refuse(cmd, Refusal::sessionLost);
  }
  const HandGrasp& g = s->grasp->grasp(hand);
  const bool held = g.holdsTarget();
  state->isGrasping = held ? XR_TRUE : XR_FALSE;
  state->target = held ? appTarget(g.target) : XR_NULL_HANDLE;
  state->squeeze = s->squeeze[hand == Hand::left ? 0 : 1];
  for (int f = 0; f < kFingerCount; ++f) {
    XrGraspFingerStateSDFG& out = state->fingers[f];
    const FingerState& fs = g.result.fingers[f];
    out.curl = held ? fs.curl : 0.0f;
    // A finger is in contact when it rests on the held target; one resting on a table or a
    // neighbour is not (its point and distance would be the other target's, not the held one's).
    // A contact the engine could not attribute (touched 0: device targets before their readback,
    // several in the box) counts as on the held target, as before scenes.
    const uint64_t on = g.touched[size_t(f)];
    const bool inContact = held && fs.contact && (on == g.target || on == 0);
    out.inContact = inContact ? XR_TRUE : XR_FALSE;
    // Version 2: the touching sphere (in the corrected hand: the hand may have been moved out
    // first)'s centre and the signed distance there (contact.h).
    const FingerContact& c = g.contacts[f];
    const bool honest = inContact && c.valid;
    const glm::vec3 p =
        honest      ? c.center
        : inContact ? (g.objectFromHand * g.result.handCorrection).transformPoint(fs.contactPoint)
                    : glm::vec3(0.0f);
    out.contactPoint = {p.x, p.y, p.z};
    out.distance = honest ? c.distance : inContact ? fs.distance : 0.0f;
  }
  writeGraspStateV2(*s, hand, held, state);
  if (auto* touches = findInChain<XrGraspTouchesSDFG>(state->next, XR_TYPE_GRASP_TOUCHES_SDFG))
    writeTouches(g, *touches);
  if (auto* info = findInChain<XrGraspBuildInfoSDFG>(state->next, XR_TYPE_GRASP_BUILD_INFO_SDFG)) {
    const SdfBuildStats& st = s->grasp->buildStats();
    info->graspBackend = !held          ? XR_GRASP_SDF_BACKEND_NONE_SDFG
                         : g.builtOnGpu ? XR_GRASP_SDF_BACKEND_VULKAN_SDFG
                                        : XR_GRASP_SDF_BACKEND_CPU_SDFG;
    info->sessionBackend = s->grasp->deferredReady() ? XR_GRASP_SDF_BACKEND_VULKAN_SDFG
                                                     : XR_GRASP_SDF_BACKEND_CPU_SDFG;
    info->gpuBuildCount = st.gpuBuilds;
    info->cpuBuildCount = st.cpuBuilds;
    info->gpuFailed = st.gpuFailed ? XR_TRUE : XR_FALSE;
    info->pendingGpuBuilds = uint32_t(s->grasp->pendingBuilds());
  }
  if (auto* setup = findInChain<XrGraspTargetsSetupInfoSDFG>(
          state->next, XR_TYPE_GRASP_TARGETS_SETUP_INFO_SDFG)) {
    const GraspSession::SetupCounts counts = s->grasp->setupCounts();
    setup->readyCount = uint32_t(counts.ready);
    setup->pendingCount = uint32_t(counts.pending);
    setup->failedCount = uint32_t(counts.failed);
  }
  if (auto* depth = findInChain<XrGraspDepthSceneInfoSDFG>(state->next,
                                                           XR_TYPE_GRASP_DEPTH_SCENE_INFO_SDFG)) {
    depth->enabled = s->depth != nullptr ? XR_TRUE : XR_FALSE;
    depth->framesRead = 0;
    if (s->depth != nullptr) {
      std::lock_guard depthLock(s->depth->mutex);  // after the session's: the one order taken
      depth->framesRead = uint32_t(std::min<uint64_t>(s->depth->framesSubmitted, UINT32_MAX));
    }
    depth->ready =
        s->grasp->depthSceneEnabled() && s->grasp->depthState(hand).valid ? XR_TRUE : XR_FALSE;
  }
  writeHandOffset(*s, hand == Hand::left ? 0 : 1, state->next);
  return XR_SUCCESS;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrSetGraspOptionsSDFG(XrSession session,
                                              const XrGraspOptionsSDFG* options) {
  constexpr const char* cmd = "xrSetGraspOptionsSDFG";
  SDFG_ENTRY_BEGIN
  auto s = findSession(session);
  SDFG_VERIFY(cmd, s != nullptr, XR_ERROR_HANDLE_INVALID, "(session) is not valid");
  SDFG_VERIFY_TYPE(cmd, options, XR_TYPE_GRASP_OPTIONS_SDFG);
  SDFG_VERIFY_CHAIN(cmd, options->next);
  const XrGraspOptionsSDFG& o = *options;
  const int32_t solver = rawEnum(o.solver);
  SDFG_VERIFY(cmd, solver >= XR_GRASP_SOLVER_DEFAULT_SDFG && solver <= XR_GRASP_SOLVER_OURS_SDFG,
              XR_ERROR_VALIDATION_FAILURE, "(options->solver) is %d", int(solver));
  SDFG_VERIFY(cmd, o.tipRadius == 0.0f || (o.tipRadius > 0.0f && o.tipRadius <= 0.05f),
              XR_ERROR_VALIDATION_FAILURE, "(options->tipRadius) must be 0 or in (0, 0.05]");
  const bool boxZero = o.boxSize.x == 0.0f && o.boxSize.y == 0.0f && o.boxSize.z == 0.0f;
  auto inBox = [](float v) { return v > 0.0f && v <= 1.0f; };
  SDFG_VERIFY(cmd, boxZero || (inBox(o.boxSize.x) && inBox(o.boxSize.y) && inBox(o.boxSize.z)),
              XR_ERROR_VALIDATION_FAILURE, "(options->boxSize) must be all 0 or each in (0, 1]");
  SDFG_VERIFY(
      cmd,
      boxZero || (isFinitePose(o.boxPose) && std::abs(o.boxPose.position.x) <= 1.0f &&
                  std::abs(o.boxPose.position.y) <= 1.0f && std::abs(o.boxPose.position.z) <= 1.0f),
      XR_ERROR_VALIDATION_FAILURE, "(options->boxPose) must be finite, within 1 m");
  SDFG_VERIFY(cmd, boxZero || isUnitQuaternion(o.boxPose.orientation), XR_ERROR_POSE_INVALID,
              "(options->boxPose.orientation) is not a unit quaternion");
  SDFG_VERIFY(cmd,
              o.resolution == 0 ||
                  (o.resolution >= kMinGridResolution && o.resolution <= kMaxGridResolution),
              XR_ERROR_VALIDATION_FAILURE, "(options->resolution) is %u, must be 0 or 2..128",
              o.resolution);
  SDFG_VERIFY(cmd, o.curlStep == 0.0f || (o.curlStep > 1e-5f && o.curlStep <= 1.0f),
              XR_ERROR_VALIDATION_FAILURE, "(options->curlStep) must be 0 or in (1e-5, 1]");
  SDFG_VERIFY(cmd, o.grabThreshold == 0.0f || (o.grabThreshold > 0.0f && o.grabThreshold <= 1.0f),
              XR_ERROR_VALIDATION_FAILURE, "(options->grabThreshold) must be 0 or in (0, 1]");
  ClearanceRequest clearance;
  if (XrResult r = readClearanceOptions(cmd, o.next, clearance); r != XR_SUCCESS) return r;
  OuterHandRequest outer;
  if (XrResult r = readOuterHandOptions(cmd, o.next, outer); r != XR_SUCCESS) return r;

  std::unique_lock lock(s->mutex);
  if (s->grasp == nullptr) {
    lock.unlock();
    return refuse(cmd, Refusal::sessionLost);
  }
  GraspSettings settings = settingsFromConfig(s->instance->config);
  if (solver == XR_GRASP_SOLVER_PAPER_SDFG) settings.solver = "paper";
  if (solver == XR_GRASP_SOLVER_OURS_SDFG) settings.solver = "ours";
  if (o.tipRadius > 0.0f) settings.solverOptions.threshold = o.tipRadius;
  if (!boxZero) {
    settings.box.handFromBox = toPose(o.boxPose);
    settings.box.size = glm::vec3(o.boxSize.x, o.boxSize.y, o.boxSize.z);
  }
  if (o.resolution != 0) settings.box.resolution = glm::uvec3(o.resolution);
  if (o.curlStep != 0.0f) settings.solverOptions.da = o.curlStep;
  if (o.grabThreshold != 0.0f) settings.grabThreshold = o.grabThreshold;
  float blendTime = s->instance->config.offsetBlendTime;
  clearance.apply(settings, blendTime, s->settings, s->offsets.blendTime);
  outer.apply(settings, s->settings);
  if (Status st = s->grasp->configure(settings); st != Status::ok) {
    lock.unlock();
    return logError(st == Status::invalid_argument && solver == XR_GRASP_SOLVER_OURS_SDFG
                        ? XR_ERROR_FEATURE_UNSUPPORTED
                        : toXrResult(st),
                    cmd, "the options were refused (%s; solver '%s')", toString(st),
                    settings.solver.c_str());
  }
  s->settings = settings;
  s->offsets.blendTime = blendTime;
  return XR_SUCCESS;
  SDFG_ENTRY_END(cmd)
}

}  // namespace sdfg::layer
