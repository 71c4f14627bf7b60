// Host mirrors of the structs the SDF compute shaders read and write (shaders/sdf_common.glsl and
// the pass files). Each is checked field for field against the GLSL std430 layout rules, so a
// change on one side fails to compile here.
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

namespace sdfg::vk_layout {

inline constexpr uint32_t kFanOut = 32;    // children per winding-hierarchy node
inline constexpr uint32_t kMaxLevels = 5;  // levels the shaders address (levelOffset0..4)
inline constexpr uint32_t kNoTriangle = 0xffffffffu;
// shaders/sdf_flood_group.comp: one work group of this many invocations, each with 4 nodes, so
// grids of up to kFloodGroupNodes nodes (16^3) flood in shared memory (16 KB of ids).
inline constexpr uint32_t kFloodGroupThreads = 1024;
inline constexpr uint32_t kFloodGroupNodes = 4 * kFloodGroupThreads;
// Mirrored by shaders/sdf_jfa_wide.comp: its fixed work-group size, 32 lanes per node (27
// neighbours, the rest idle).
inline constexpr uint32_t kWideFloodThreads = 64;
inline constexpr uint32_t kWideFloodNodesPerGroup = kWideFloodThreads / 32;
// shaders/sdf_splat.comp: invocations per triangle (log2), each taking every 4th z layer.
inline constexpr uint32_t kSplatSplitLog2 = 2;

// Binding 0 (std430, read-only storage buffer): per-build parameters. See BuildParams in
// sdf_common.glsl.
struct BuildParams {
  glm::mat4 boxFromObject;  // column-major, like GLSL's mat4
  glm::vec4 boxHalf;        // xyz: size / 2; w: cull margin
  glm::vec4 spacing;        // xyz: node spacing; w: distance where no triangle is known
  glm::uvec4 res;           // xyz: nodes per axis; w: node count
  uint32_t triangleCount;
  uint32_t vertexCount;
  uint32_t positionOffset;  // 32-bit words
  uint32_t positionStride;  // 32-bit words
  uint32_t indexOffset;     // elements of the index type
  uint32_t index16;
  uint32_t nodeLevels;
  uint32_t topNodeCount;
  uint32_t pointCount;
  uint32_t levelOffset[kMaxLevels];
  uint32_t levelCount[kMaxLevels];
  float windingBeta;
  uint32_t signMode;  // 0: winding number; 1: pseudo-normals (binding 11)
  uint32_t pad[2];
};
static_assert(offsetof(BuildParams, boxHalf) == 64);
static_assert(offsetof(BuildParams, spacing) == 80);
static_assert(offsetof(BuildParams, res) == 96);
static_assert(offsetof(BuildParams, triangleCount) == 112);
static_assert(offsetof(BuildParams, pointCount) == 144);
static_assert(offsetof(BuildParams, levelOffset) == 148);
static_assert(offsetof(BuildParams, levelCount) == 168);
static_assert(offsetof(BuildParams, windingBeta) == 188);
static_assert(offsetof(BuildParams, signMode) == 192);
static_assert(sizeof(BuildParams) == 204);        // GLSL: last member (pad2) ends at 204
inline constexpr size_t kBuildParamsBytes = 208;  // the block aligns to its mat4: 16 bytes

// Binding 3 (std430): one triangle in box space, three vec4 (a.w = cull flag).
struct BoxTriangle {
  glm::vec4 a, b, c;
};
static_assert(sizeof(BoxTriangle) == 48);

// Binding 4 (std430): one node of the winding-number hierarchy.
struct HierarchyNode {
  glm::vec4 centroidRadius;
  glm::vec4 areaVector;
};
static_assert(sizeof(HierarchyNode) == 32);

// Binding 9 (std430): one point to sample, normalized box coordinates in xyz.
struct SamplePoint {
  glm::vec4 uvw;
};
static_assert(sizeof(SamplePoint) == 16);

// Binding 11 (std430): per triangle, object-space pseudo-normals of edges 0..2 (a-b, b-c, c-a)
// then corners 0..2, xyz used.
struct TrianglePseudoNormals {
  glm::vec4 edge[3];
  glm::vec4 corner[3];
};
static_assert(sizeof(TrianglePseudoNormals) == 96);

// Push constants shared by every pass (each reads the members it declares).
struct PushConstants {
  uint32_t a = 0;  // cluster: level; splat: mode; jfa/finalize: step
  uint32_t b = 0;  // splat: log2 of invocations per triangle; jfa/finalize: flip
};
static_assert(sizeof(PushConstants) == 8);

// Descriptor bindings, numbered as in the shaders.
enum Binding : uint32_t {
  kParams = 0,
  kPositions = 1,
  kIndices = 2,
  kTriangles = 3,
  kHierarchy = 4,
  kDistBits = 5,
  kIdsA = 6,
  kIdsB = 7,
  kValues = 8,
  kPoints = 9,
  kSamples = 10,
  kPseudoNormals = 11,
  kBindingCount = 12,
};

}  // namespace sdfg::vk_layout
