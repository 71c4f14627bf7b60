#version 450
// The mesh of a buffer target read back for the CPU (vulkan/vk_mesh_readback.h): one invocation
// per vertex and per index copies the app's positions (any offset and stride) as packed floats,
// and its 16- or 32-bit indices as 32-bit ones. A copy command cannot do this: it needs the
// app's buffers to carry the transfer-source usage, and it cannot unpack strides or 16-bit
// indices; a storage read needs only the usage every buffer target already has.
layout(local_size_x_id = 0) in;

layout(push_constant) uniform Params {
  uint positionOffset;  // words
  uint positionStride;  // words
  uint vertexCount;
  uint indexOffset;  // indices (16- or 32-bit)
  uint indexCount;   // 0: positions only
  uint index16;
}
P;

layout(std430, set = 0, binding = 0) readonly buffer Positions { uint posWords[]; };
layout(std430, set = 0, binding = 1) readonly buffer Indices { uint idxWords[]; };
// 3 * vertexCount position words, then indexCount indices.
layout(std430, set = 0, binding = 2) writeonly buffer Gathered { uint outWords[]; };

const uint kNaNBits = 0x7fc00000u;
const uint kNoIndex = 0xffffffffu;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < P.vertexCount) {
    // A position past the end of the app's buffer reads as NaN: the CPU refuses the mesh.
    uint w = P.positionOffset + i * P.positionStride;
    bool inside = w + 2u < uint(posWords.length());
    outWords[3u * i] = inside ? posWords[w] : kNaNBits;
    outWords[3u * i + 1u] = inside ? posWords[w + 1u] : kNaNBits;
    outWords[3u * i + 2u] = inside ? posWords[w + 2u] : kNaNBits;
  }
  if (i < P.indexCount) {
    uint k = P.indexOffset + i;
    uint index = kNoIndex;
    if (P.index16 != 0u) {
      uint w = k >> 1u;
      if (w < uint(idxWords.length())) index = (idxWords[w] >> ((k & 1u) * 16u)) & 0xffffu;
    } else if (k < uint(idxWords.length())) {
      index = idxWords[k];
    }
    outWords[3u * P.vertexCount + i] = index;
  }
}
