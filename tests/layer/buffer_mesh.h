// A mesh in the app's own Vulkan buffers, as XrGraspTargetVulkanBuffersSDFG describes it, for
// the layer tests of buffer targets (layer_vulkan, layer_buffer_scenes).
#pragma once

#include <openxr/openxr.h>
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "test_scenes.h"
#include "xr_harness.h"

namespace sdfg::test {

// The mesh in a vertex buffer of stride 24 starting 16 bytes in, every non-position float NaN
// (a reader that ignores the stride or offset meets NaN corners and skips those triangles), and
// 16-bit indices 6 bytes into their buffer (whose size is rounded up to whole 32-bit words, as
// a GPU allocation's is: the layer's shaders read words).
struct BufferMesh {
  HostBuffer vertices, indices;
  XrGraspTargetVulkanBuffersSDFG desc{XR_TYPE_GRASP_TARGET_VULKAN_BUFFERS_SDFG};
};

inline void writeVertices(const BufferMesh& m, const TestMesh& mesh, float scale) {
  auto* v = static_cast<float*>(m.vertices.mapped);
  for (size_t i = 0; i < m.desc.vertexOffset / 4 + mesh.vertices.size() * 6; ++i)
    v[i] = std::nanf("");
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    float* p = v + m.desc.vertexOffset / 4 + i * (m.desc.vertexStride / 4);
    p[0] = mesh.vertices[i].x * scale;
    p[1] = mesh.vertices[i].y * scale;
    p[2] = mesh.vertices[i].z * scale;
  }
}

inline BufferMesh uploadMesh(App& app, const TestMesh& mesh, float scale) {
  REQUIRE(mesh.vertices.size() < 65536);
  BufferMesh m;
  m.desc.vertexOffset = 16;
  m.desc.vertexStride = 24;
  m.desc.vertexCount = uint32_t(mesh.vertices.size());
  m.desc.indexOffset = 6;
  m.desc.indexType = VK_INDEX_TYPE_UINT16;
  m.desc.indexCount = uint32_t(mesh.indices.size());
  m.vertices = app.createBuffer(16 + mesh.vertices.size() * 24);
  m.indices = app.createBuffer((6 + mesh.indices.size() * 2 + 3) / 4 * 4);
  REQUIRE(m.vertices.mapped != nullptr);
  REQUIRE(m.indices.mapped != nullptr);
  m.desc.vertexBuffer = m.vertices.buffer;
  m.desc.indexBuffer = m.indices.buffer;
  writeVertices(m, mesh, scale);
  auto* idx = reinterpret_cast<uint16_t*>(static_cast<char*>(m.indices.mapped) + 6);
  for (size_t i = 0; i < mesh.indices.size(); ++i) idx[i] = uint16_t(mesh.indices[i]);
  XrVector3f lo{1e9f, 1e9f, 1e9f}, hi{-1e9f, -1e9f, -1e9f};
  for (const XrVector3f& p : mesh.vertices) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  m.desc.boundsMin = lo;
  m.desc.boundsMax = hi;
  return m;
}

}  // namespace sdfg::test
