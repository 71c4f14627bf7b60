// The grab-box SDF on the GPU: builds the signed distance field of the grasped object inside the
// box around the hand on a borrowed Vulkan device, and samples it at any number of points in the
// same submission (the paper's Algorithm 2), so only those floats come back to the CPU.
//
// Method (shaders/): every triangle is moved into box space and culled to the box plus one box
// diagonal (enough for the closest triangle of every node whenever the box holds some surface);
// exact distances splat into the nodes within one spacing of each triangle (their closest
// triangle is exact); jump flooding (step N/2 .. 1, then 2, 1) carries closest-triangle ids to
// every other node, each keeping the candidate at the smallest exact distance; the final value
// is the exact distance to that triangle. The sign follows the CPU builder: on a closed,
// consistently oriented mesh given as arrays, the angle-weighted pseudo-normal of the closest
// feature (computed on the CPU at setMesh), with far nodes taking the majority sign of their
// face neighbours so that a flooded id from the back of a thin part cannot flip one; otherwise
// (open meshes, the app's buffers) the generalized winding number (> 0.5 inside), summed over a
// 32-ary hierarchy of triangle clusters with a dipole far field. It needs no adjacency, so skinned
// meshes in app buffers work as they are, at a higher cost.
//
// Frame path: submit*() records and submits one command buffer and returns at once; poll()
// checks the fence without waiting. One submission is in flight at a time. Every Vulkan object
// is owned by the builder and destroyed with it. After any Vulkan failure (device lost included)
// the builder logs one line, reports Status::device_lost or the failing kind, and refuses
// further work; SdfBackend (vk_sdf_backend.h) then continues on the CPU.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "base/pose.h"
#include "base/status.h"
#include "mesh/mesh.h"
#include "sdf/sdf_grid.h"
#include "vulkan/vk_context.h"

namespace sdfg {

// A mesh that lives in the app's Vulkan buffers (for example one it skins on the GPU). Borrowed:
// the buffers must stay alive and unchanged in size while set, and carry
// VK_BUFFER_USAGE_STORAGE_BUFFER_BIT. Writes to them must be ordered before the submission that
// reads them (same queue: submit order plus the barrier the builder records; another queue: a
// semaphore the caller owns). Positions are three 32-bit floats (x, y, z) at `positionOffset +
// v * positionStride` bytes.
struct VkMeshBuffers {
  VkBuffer positions = VK_NULL_HANDLE;
  VkDeviceSize positionOffset = 0;  // bytes, multiple of 4
  uint32_t positionStride = 12;     // bytes, multiple of 4, at least 12
  uint32_t vertexCount = 0;
  VkBuffer indices = VK_NULL_HANDLE;
  VkDeviceSize indexOffset = 0;                  // bytes, multiple of the index size
  VkIndexType indexType = VK_INDEX_TYPE_UINT32;  // or VK_INDEX_TYPE_UINT16
  uint32_t indexCount = 0;                       // multiple of 3, at least 3
};

// Whether `m` is a description the builder and the readback take: both buffers, counts,
// alignments and index type as VkMeshBuffers says (the values in the buffers are checked where
// they are read).
bool validMeshBuffers(const VkMeshBuffers& m);

struct VkSdfOptions {
  uint32_t workGroupSize = 64;  // clamped to the device limits
  // A hierarchy cluster farther than beta times its radius uses its dipole term. 2 keeps the
  // winding number within about 1e-3 of the exact sum on the test meshes.
  float windingBeta = 2.0f;
  // Time each pass of a build with GPU timestamps (see passTimesMs()); off in the frame path.
  bool profile = false;
  // Where the one failure line goes; stderr when empty.
  std::function<void(const std::string&)> log;
};

enum class SdfPoll {
  idle,     // nothing submitted since creation
  pending,  // the GPU is still working
  ready,    // results of the last submission are available
  failed,   // the device failed; see failure()
};

class VkSdfBuilder {
 public:
  // Loads functions, builds pipelines and fixed objects. Errors: see VkContext::create, plus
  // out_of_memory or internal when an object cannot be made.
  static Result<std::unique_ptr<VkSdfBuilder>> create(const VulkanDevice& device,
                                                      const VkSdfOptions& options = {});
  ~VkSdfBuilder();  // waits for an in-flight submission first
  VkSdfBuilder(const VkSdfBuilder&) = delete;
  VkSdfBuilder& operator=(const VkSdfBuilder&) = delete;

  // The target as CPU arrays: copied now, uploaded by the next build. `objectFromHand` of later
  // builds maps hand space into this mesh's space. Errors: invalid_argument (see validateMesh;
  // over 2^30 triangles), unsupported (busy: a submission is in flight).
  Status setMesh(const TriangleMesh& mesh);
  // The target as the app's buffers (see VkMeshBuffers). Errors: invalid_argument (null buffer,
  // zero or misaligned counts, offsets or stride), unsupported (busy). Index values are checked
  // on the GPU: a triangle with an index out of range or a non-finite corner is ignored.
  Status setMesh(const VkMeshBuffers& buffers);

  // Builds the SDF of the current mesh in `box` (placed by `objectFromHand`) and samples it at
  // `points` (normalized box coordinates, clamped to the box like SdfGrid::sampleNormalized) in
  // one submission. `readBackGrid` also copies every node value back (tests, tools; the frame
  // path needs only the samples). Returns at once. Errors: invalid_argument (bad box, no mesh,
  // non-finite pose), unsupported (busy), device_lost / out_of_memory / internal (the device
  // failed: the builder is now unusable and has logged one line).
  Status submitBuild(const GridBox& box, const Pose& objectFromHand,
                     std::span<const glm::vec3> points, bool readBackGrid = false);
  // Samples the last built grid again at new points (no rebuild). Errors as submitBuild, plus
  // invalid_argument when nothing was built yet.
  Status submitSample(std::span<const glm::vec3> points);

  // Checks the fence without waiting (the frame path). On `ready` the results below are valid
  // until the next submission.
  SdfPoll poll();
  // Blocks up to `timeoutNs` for the submission (tests and tools only, never in a frame).
  SdfPoll wait(uint64_t timeoutNs);

  // One value per point of the last submission, in order.
  std::span<const float> samples() const { return samples_; }
  // The last built grid when it was read back; null otherwise.
  const SdfGrid* grid() const { return gridValid_ ? &grid_ : nullptr; }

  // With VkSdfOptions::profile and a device that has timestamps: milliseconds of the last
  // build's passes, in order transform, hierarchy, splat, flood, finalize, sample. Grids of up
  // to 4096 nodes flood in one work group; signed by pseudo-normals, that one dispatch also
  // finalizes and samples, so its time is the flood's and finalize and sample read about 0.
  // Empty otherwise.
  std::span<const double> passTimesMs() const { return passTimesMs_; }

  bool failed() const { return failed_; }
  const std::string& failure() const { return failure_; }
  const VkContext& context() const { return *ctx_; }
  uint32_t workGroupSize() const { return workGroupSize_; }

  // Test hook: the next submission or poll behaves as if the device returned
  // VK_ERROR_DEVICE_LOST.
  void simulateDeviceLostForTesting() { simulateLost_ = true; }

 private:
  struct Objects;
  VkSdfBuilder() = default;
  Status fail(VkResult result, const char* what);
  Status fail(const Error& error);
  Status checkUsable() const;
  Status ensureBuffers(size_t nodeCount, size_t pointCount, bool readBack);
  Status ensureBuffer(uint32_t slot, size_t bytes, uint32_t kind);
  void updateDescriptors();
  Status record(bool build, size_t pointCount, bool readBack);
  Status submitRecorded();
  void collectResults();

  std::unique_ptr<VkContext> ctx_;  // first: destroyed last, after every object it made
  std::unique_ptr<Objects> objects_;
  VkSdfOptions options_;
  uint32_t workGroupSize_ = 64;

  // Mesh source.
  enum class MeshSource { none, cpu, app } meshSource_ = MeshSource::none;
  VkMeshBuffers appMesh_{};
  uint32_t triangleCount_ = 0;
  uint32_t vertexCount_ = 0;
  bool uploadPending_ = false;
  bool pseudoNormalSign_ = false;  // closed CPU-array mesh: sign from pseudo-normals

  // Last build and results.
  GridBox box_{};
  bool built_ = false;
  bool pending_ = false;
  bool readBackPending_ = false;
  bool everSubmitted_ = false;
  size_t pointCount_ = 0;
  std::vector<float> samples_;
  std::vector<double> passTimesMs_;
  SdfGrid grid_;
  bool gridValid_ = false;
  bool profiledBuild_ = false;

  bool failed_ = false;
  bool simulateLost_ = false;
  std::string failure_;
};

}  // namespace sdfg
