#include "vulkan/vk_sdf_backend.h"

namespace sdfg {

std::unique_ptr<GrabBoxSdf> GrabBoxSdf::create(const VulkanDevice* device,
                                               const VkSdfOptions& options, unsigned cpuThreads) {
  std::unique_ptr<GrabBoxSdf> s(new GrabBoxSdf());
  s->cpu_ = std::make_unique<CpuSdfBuilder>(cpuThreads);
  if (device != nullptr) {
    auto gpu = VkSdfBuilder::create(*device, options);
    if (gpu) {
      s->gpu_ = std::move(gpu.value());
    } else if (options.log) {
      options.log("sdfg: Vulkan SDF backend unavailable, using the CPU: " + gpu.error().message);
    }
  }
  return s;
}

GrabBoxSdf::~GrabBoxSdf() = default;

void GrabBoxSdf::fallBack() {
  // VkSdfBuilder has logged its one line; waiting on a failed device is not needed.
  gpu_.reset();
}

Status GrabBoxSdf::setMesh(const TriangleMesh& mesh) {
  if (gpu_ && gpu_->poll() == SdfPoll::pending) return Status::unsupported;
  auto distance = MeshDistance::create(mesh);
  if (!distance) return distance.error().code;
  if (gpu_) {
    // The welded mesh (MeshDistance::mesh()): the device signs a closed one by pseudo-normals,
    // which need the topology the app's split vertices hide (mesh/mesh_weld.h).
    const Status s = gpu_->setMesh((*distance)->mesh());
    if (s == Status::invalid_argument) return s;
    if (s != Status::ok) fallBack();
  }
  distance_ = std::move(distance.value());
  mesh_ = mesh;
  haveMesh_ = true;
  cpuReady_ = false;
  return Status::ok;
}

Status GrabBoxSdf::runOnCpu() {
  const Status s = cpu_->build(*distance_, objectFromHand_, box_, cpuGrid_);
  if (s != Status::ok) return s;
  cpuSamples_.resize(points_.size());
  for (size_t i = 0; i < points_.size(); ++i)
    cpuSamples_[i] = cpuGrid_.sampleNormalized(points_[i]);
  cpuReady_ = true;
  return Status::ok;
}

Status GrabBoxSdf::submit(const GridBox& box, const Pose& objectFromHand,
                          std::span<const glm::vec3> points, bool readBackGrid) {
  if (!haveMesh_ || box.validate()) return Status::invalid_argument;
  if (gpu_ && gpu_->poll() == SdfPoll::pending) return Status::unsupported;
  box_ = box;
  objectFromHand_ = objectFromHand;
  points_.assign(points.begin(), points.end());
  cpuReady_ = false;
  if (gpu_) {
    const Status s = gpu_->submitBuild(box, objectFromHand, points, readBackGrid);
    if (s == Status::ok || s == Status::invalid_argument || s == Status::unsupported) return s;
    fallBack();
  }
  return runOnCpu();
}

SdfPoll GrabBoxSdf::poll() {
  if (gpu_) {
    const SdfPoll p = gpu_->poll();
    if (p != SdfPoll::failed) return p;
    fallBack();
    return runOnCpu() == Status::ok ? SdfPoll::ready : SdfPoll::failed;
  }
  return cpuReady_ ? SdfPoll::ready : SdfPoll::idle;
}

SdfPoll GrabBoxSdf::wait(uint64_t timeoutNs) {
  if (gpu_) {
    const SdfPoll p = gpu_->wait(timeoutNs);
    if (p != SdfPoll::failed) return p;
  }
  return poll();
}

std::span<const float> GrabBoxSdf::samples() const {
  return gpu_ ? gpu_->samples() : std::span<const float>(cpuSamples_);
}

const SdfGrid* GrabBoxSdf::grid() const {
  if (gpu_) return gpu_->grid();
  return cpuReady_ ? &cpuGrid_ : nullptr;
}

}  // namespace sdfg
