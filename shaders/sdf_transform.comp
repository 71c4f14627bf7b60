#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 1, one invocation per triangle: fetch its indices and positions from the mesh source (our
// own upload or the app's buffers, any stride and 16/32-bit indices), move it into box space and
// mark whether it lies within the cull margin of the box. The dispatch also covers every node:
// invocation v clears node v's splat minimum and closest-triangle id for the splat that follows
// (one pass instead of two buffer fills and the barrier between them and this pass).
#include "sdf_common.glsl"

// Binding 1: vertex positions, raw 32-bit words (float bits), offset and stride from P.
layout(std430, set = 0, binding = 1) readonly buffer Positions { uint posWords[]; };
// Binding 2: indices, raw 32-bit words holding 32-bit or packed 16-bit indices.
layout(std430, set = 0, binding = 2) readonly buffer Indices { uint idxWords[]; };

uint fetchIndex(uint e) {
  uint k = P.indexOffset + e;
  if (P.index16 != 0u) {
    uint w = k >> 1u;
    if (w >= uint(idxWords.length())) return 0xffffffffu;
    return (idxWords[w] >> ((k & 1u) * 16u)) & 0xffffu;
  }
  if (k >= uint(idxWords.length())) return 0xffffffffu;
  return idxWords[k];
}

bool fetchPosition(uint v, out vec3 p) {
  uint w = P.positionOffset + v * P.positionStride;
  if (v >= P.vertexCount || w + 2u >= uint(posWords.length())) {
    p = vec3(0.0);
    return false;
  }
  p = vec3(uintBitsToFloat(posWords[w]), uintBitsToFloat(posWords[w + 1u]),
           uintBitsToFloat(posWords[w + 2u]));
  return true;
}

// Binding 5: per node, bits of the splat's smallest distance (+inf bits when cleared).
layout(std430, set = 0, binding = 5) writeonly buffer DistBits { uint distBits[]; };
// Binding 6: per node, closest triangle id (kNoTriangle when cleared).
layout(std430, set = 0, binding = 6) writeonly buffer IdsA { uint idsA[]; };

void main() {
  uint t = gl_GlobalInvocationID.x;
  if (t < P.res.w) {
    distBits[t] = 0x7f800000u;
    idsA[t] = kNoTriangle;
  }
  // The dispatch covers max(triangles, nodes), rounded up to whole groups.
  if (t >= P.triangleCount) return;
  vec3 p0, p1, p2;
  bool valid = fetchPosition(fetchIndex(3u * t), p0);
  valid = fetchPosition(fetchIndex(3u * t + 1u), p1) && valid;
  valid = fetchPosition(fetchIndex(3u * t + 2u), p2) && valid;
  vec3 q0 = (P.boxFromObject * vec4(p0, 1.0)).xyz;
  vec3 q1 = (P.boxFromObject * vec4(p1, 1.0)).xyz;
  vec3 q2 = (P.boxFromObject * vec4(p2, 1.0)).xyz;
  // A triangle with a bad index or a non-finite corner is dropped (a.w = -1): it neither seeds
  // the distance nor adds to the winding number, and reads stay in bounds.
  vec3 sum = q0 + q1 + q2;
  if (any(isnan(sum)) || any(isinf(sum)) || any(isnan(q0)) || any(isnan(q1)) || any(isnan(q2))) {
    valid = false;
  }
  if (!valid) {
    tri[3u * t] = vec4(0.0, 0.0, 0.0, -1.0);
    tri[3u * t + 1u] = vec4(0.0);
    tri[3u * t + 2u] = vec4(0.0);
    return;
  }
  vec3 lo = min(q0, min(q1, q2));
  vec3 hi = max(q0, max(q1, q2));
  vec3 reach = P.boxHalf.xyz + vec3(P.boxHalf.w);
  bool inside = valid && all(lessThanEqual(lo, reach)) && all(greaterThanEqual(hi, -reach));
  tri[3u * t] = vec4(q0, inside ? 1.0 : 0.0);
  tri[3u * t + 1u] = vec4(q1, 0.0);
  tri[3u * t + 2u] = vec4(q2, 0.0);
}
