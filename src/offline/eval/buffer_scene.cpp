#include "eval/buffer_scene.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <optional>
#include <thread>
#include <utility>

#include "grasp/grasp_session.h"
#include "mesh/mesh.h"
#include "vulkan/vk_context.h"
#include "vulkan/vk_grasp_backend.h"
#include "vulkan_device/vk_standalone.h"

namespace sdfg {

namespace {

// The vertex layout of a typical game mesh: position, normal, UV (the normal and UV are zero here;
// the layer reads the positions only).
constexpr uint32_t kVertexStride = 32;  // bytes
constexpr auto kGraspBound = std::chrono::seconds(20);

// A mesh in buffers of the device, as an app keeps it: interleaved vertices, 16-bit indices where
// the vertex count allows them.
struct DeviceMesh {
  VkBufferAlloc vertices, indices;
  VkMeshBuffers desc;
};

Result<DeviceMesh> upload(const VkContext& ctx, const TriangleMesh& mesh) {
  DeviceMesh m;
  const bool small = mesh.positions.size() <= 0xffff;
  const VkDeviceSize indexSize = small ? 2 : 4;
  auto vertices = createBuffer(ctx, mesh.positions.size() * kVertexStride,
                               VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, VkMemoryKind::upload);
  if (!vertices) return vertices.error();
  // Rounded up to whole 32-bit words, as a GPU allocation is: the layer's shaders read words.
  auto indices = createBuffer(ctx, (mesh.indices.size() * indexSize + 3) / 4 * 4,
                              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, VkMemoryKind::upload);
  if (!indices) return indices.error();
  m.vertices = std::move(*vertices);
  m.indices = std::move(*indices);
  if (m.vertices.mapped == nullptr || m.indices.mapped == nullptr)
    return makeError(Status::unsupported, "buffer scene: upload memory is not host-visible");
  auto* v = static_cast<char*>(m.vertices.mapped);
  std::memset(v, 0, size_t(m.vertices.size));
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    std::memcpy(v + i * kVertexStride, &mesh.positions[i], sizeof(glm::vec3));
  auto* idx = static_cast<char*>(m.indices.mapped);
  std::memset(idx, 0, size_t(m.indices.size));
  for (size_t i = 0; i < mesh.indices.size(); ++i) {
    if (small) {
      const uint16_t k = uint16_t(mesh.indices[i]);
      std::memcpy(idx + 2 * i, &k, 2);
    } else {
      std::memcpy(idx + 4 * i, &mesh.indices[i], 4);
    }
  }
  if (flushBuffer(ctx, m.vertices) != VK_SUCCESS || flushBuffer(ctx, m.indices) != VK_SUCCESS)
    return makeError(Status::internal, "buffer scene: vkFlushMappedMemoryRanges failed");
  m.desc.positions = m.vertices.buffer.get();
  m.desc.positionStride = kVertexStride;
  m.desc.vertexCount = uint32_t(mesh.positions.size());
  m.desc.indices = m.indices.buffer.get();
  m.desc.indexType = small ? VK_INDEX_TYPE_UINT16 : VK_INDEX_TYPE_UINT32;
  m.desc.indexCount = uint32_t(mesh.indices.size());
  return m;
}

uint64_t targetId(size_t object) {
  return object + 1;
}

int objectIndex(uint64_t id, size_t objects) {
  return id >= 1 && id <= objects ? int(id - 1) : -1;
}

}  // namespace

Result<std::unique_ptr<BufferSceneSolver>> BufferSceneSolver::create(bool validation) {
  StandaloneVulkanOptions options;
  options.validation = validation;
  auto vulkan = StandaloneVulkan::create(options);
  if (!vulkan) return vulkan.error();
  std::unique_ptr<BufferSceneSolver> solver(new BufferSceneSolver());
  solver->vulkan_ = std::move(*vulkan);
  return solver;
}

BufferSceneSolver::~BufferSceneSolver() = default;

const std::string& BufferSceneSolver::deviceName() const {
  return vulkan_->deviceName();
}

uint32_t BufferSceneSolver::validationMessages() const {
  return vulkan_->messageCount();
}

SceneSolves BufferSceneSolver::solves(const SceneRun& run, BufferTargets which) {
  SceneRun copy = run;
  copy.solves = nullptr;
  return [this, copy, which](const BenchScene& scene, std::span<const Placement> placements) {
    return solve(scene, placements, copy, which);
  };
}

Result<std::vector<SceneSolve>> BufferSceneSolver::solve(const BenchScene& scene,
                                                         std::span<const Placement> placements,
                                                         const SceneRun& run, BufferTargets which) {
  const std::string where = "scene " + scene.name + " (buffer targets): ";
  auto ctx = VkContext::create(vulkan_->device());
  if (!ctx) return makeError(ctx.error().code, where + ctx.error().message);
  // Declared before the session: its backend waits for the device's reads of them when the
  // session goes, and only then are they destroyed.
  std::vector<std::optional<DeviceMesh>> buffers(scene.objects.size());
  auto inBuffers = [&](size_t i) {
    return !scene.objects[i].shape && (which == BufferTargets::everyMesh || i == scene.reachedFor);
  };
  VkGraspBackendOptions backendOptions;
  std::string deviceLog;
  backendOptions.log = [&deviceLog](const std::string& line) { deviceLog = line; };
  auto backend = VkGraspBackend::create(vulkan_->device(), nullptr, backendOptions);
  if (!backend) return makeError(backend.error().code, where + backend.error().message);
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& o = scene.objects[i];
    if (!inBuffers(i)) continue;
    auto m = upload(**ctx, o.mesh);
    if (!m) return makeError(m.error().code, where + o.name + ": " + m.error().message);
    buffers[i] = std::move(*m);
    if (Status s = (*backend)->setDeviceMesh(targetId(i), buffers[i]->desc); s != Status::ok)
      return makeError(s, where + o.name + ": the backend refused its buffers");
  }

  GraspSession session(makeCpuSdfBackend(1), std::move(*backend));
  GraspSettings settings;
  settings.solver = run.method;
  settings.solverOptions = run.options;
  settings.exactCheck = run.exactCheck;
  settings.box = run.box;
  // A measurement, not a frame: a build on a busy machine (lavapipe compiling its pipelines cold
  // while other tests run) may take longer than the layer's second and is waited for (CI once
  // gave up placement 0 of the mug at the default limit).
  settings.buildTimeLimit = std::chrono::duration_cast<std::chrono::milliseconds>(kGraspBound);
  if (Status s = session.configure(settings); s != Status::ok)
    return makeError(s, where + "the session refused the settings");
  std::vector<TargetFrame> frames;
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& o = scene.objects[i];
    const uint64_t id = targetId(i);
    const Status added = o.shape ? session.addShapeTarget(id, *o.shape)
                         : inBuffers(i)
                             ? session.addDeviceTarget(id, computeBounds(o.mesh.positions))
                             : session.addTarget(id, o.mesh);
    if (added != Status::ok) return makeError(added, where + o.name + ": not added");
    if (!o.graspable) session.setTargetRole(id, TargetRole::scene);
    frames.push_back(TargetFrame{id, true, o.worldFromObject});
  }

  int64_t time = 0;
  // One frame of the app: the hand's update, then the device work the layer submits inside
  // xrEndFrame.
  auto frame = [&](const HandFrame& hand) -> Status {
    const Status s = session.update(Hand::right, hand, frames);
    if (s != Status::ok) return s;
    if (session.needsSubmit(true)) return session.submitDeferred(true);
    return Status::ok;
  };
  HandFrame away;  // no hand: the readbacks are collected
  const auto setupDeadline = std::chrono::steady_clock::now() + kGraspBound;
  while (session.setupCounts().pending > 0) {
    away.time = ++time;
    if (Status s = frame(away); s != Status::ok)
      return makeError(s, where + "a frame failed while the buffers were read back");
    if (std::chrono::steady_clock::now() > setupDeadline)
      return makeError(Status::timed_out, where + "targets not set up within 20 s");
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  const GraspSession::SetupCounts counts = session.setupCounts();
  if (counts.failed > 0)
    return makeError(Status::invalid_argument, where + "a target's set-up failed");
  if (const auto notes = session.takeReadbackNotes(); !notes.empty())
    return makeError(Status::invalid_argument,
                     where + "target " + std::to_string(notes[0].first) + ": " + notes[0].second);

  std::vector<SceneSolve> out(placements.size());
  for (size_t p = 0; p < placements.size(); ++p) {
    HandFrame hand;
    hand.valid = true;
    hand.worldFromWrist = placements[p].objectFromHand;
    hand.squeeze = 1.0f;
    const auto deadline = std::chrono::steady_clock::now() + kGraspBound;
    while (!session.grasp(Hand::right).shown()) {
      hand.time = ++time;
      if (Status s = frame(hand); s != Status::ok)
        return makeError(s, where + "placement " + std::to_string(p) + ": the grasp failed (" +
                                std::string(toString(s)) + ")" +
                                (deviceLog.empty() ? "" : " (" + deviceLog + ")"));
      if (std::chrono::steady_clock::now() > deadline)
        return makeError(Status::timed_out,
                         where + "placement " + std::to_string(p) + ": no grasp within 20 s");
      if (!session.grasp(Hand::right).shown())
        std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
    const HandGrasp& g = session.grasp(Hand::right);
    SceneSolve& s = out[p];
    s.result = g.result;
    s.taken = objectIndex(g.target, scene.objects.size());
    for (int f = 0; f < kFingerCount; ++f)
      s.touched[size_t(f)] = objectIndex(g.touched[size_t(f)], scene.objects.size());
    s.contacts = g.contacts;
    ++grasps_;
    gpuGrasps_ += g.builtOnGpu ? 1 : 0;
    hand.squeeze = 0.0f;
    hand.time = ++time;
    if (Status st = frame(hand); st != Status::ok)
      return makeError(st, where + "placement " + std::to_string(p) + ": the release failed");
  }
  return out;
}

}  // namespace sdfg
