#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 3, one invocation per triangle, run twice: exact distances from the triangle to every node
// of its bounding box grown by one node spacing (clamped to the grid, so a triangle outside the
// box seeds the nearest boundary layer). Mode 0 keeps the smallest distance per node with an
// atomic minimum on its bits (non-negative floats order like their bit patterns); mode 1 writes
// the triangle id where its distance equals that minimum (the largest id of equal triangles, by
// atomics, so the result does not depend on the order the device runs the triangles in).
// Every node within one spacing of the surface ends with its exact closest triangle.
//
// Each triangle has 2^splitLog2 invocations, each taking every 2^splitLog2-th z layer of its
// nodes: a small triangle's 4 x 4 x 4 nodes are then 4 short loops side by side instead of one
// loop of 64 dependent memory operations, which on a GPU is what the pass waits for.
#include "sdf_common.glsl"

// Binding 5: per node, bits of the smallest distance found (cleared to +inf bits).
layout(std430, set = 0, binding = 5) buffer DistBits { uint distBits[]; };
// Binding 6: per node, closest triangle id (cleared to kNoTriangle).
layout(std430, set = 0, binding = 6) buffer IdsA { uint idsA[]; };

layout(push_constant) uniform Push { uint mode; uint splitLog2; } pc;

uvec3 nodeRangeLow(vec3 lo) {
  vec3 f = floor((lo + P.boxHalf.xyz) / P.spacing.xyz) - 1.0;
  return uvec3(clamp(f, vec3(0.0), vec3(P.res.xyz - 1u)));
}
uvec3 nodeRangeHigh(vec3 hi) {
  vec3 f = ceil((hi + P.boxHalf.xyz) / P.spacing.xyz) + 1.0;
  return uvec3(clamp(f, vec3(0.0), vec3(P.res.xyz - 1u)));
}

void main() {
  uint t = gl_GlobalInvocationID.x >> pc.splitLog2;
  uint layer = gl_GlobalInvocationID.x & ((1u << pc.splitLog2) - 1u);
  if (t >= P.triangleCount) return;  // the dispatch is rounded up to whole groups
  vec4 a4 = tri[3u * t];
  if (a4.w != 1.0) return;  // outside the cull margin, or dropped
  vec3 a = a4.xyz, b = tri[3u * t + 1u].xyz, c = tri[3u * t + 2u].xyz;
  uvec3 lo = nodeRangeLow(min(a, min(b, c)));
  uvec3 hi = nodeRangeHigh(max(a, max(b, c)));
  float seedReach = 2.0 * max(P.spacing.x, max(P.spacing.y, P.spacing.z));
  bool outside = any(greaterThan(max(a, max(b, c)), P.boxHalf.xyz)) ||
                 any(lessThan(min(a, min(b, c)), -P.boxHalf.xyz));
  for (uint k = lo.z + layer; k <= hi.z; k += 1u << pc.splitLog2) {
    for (uint j = lo.y; j <= hi.y; ++j) {
      for (uint i = lo.x; i <= hi.x; ++i) {
        uint v = i + P.res.x * (j + P.res.y * k);
        vec3 p = nodePosition(uvec3(i, j, k));
        float d = length(p - closestOnTriangle(p, a, b, c));
        // Beyond two spacings a seed adds little the flood would not find: skip the atomic. (One
        // spacing is enough for exact values near the surface, but the thinner seed shell let
        // the flood hand more far nodes the back of a thin part: sign errors on the armadillo.)
        // (Nodes of the boundary layer seeded for triangles outside the box are always kept.)
        if (d > seedReach && !outside) continue;
        uint bits = floatBitsToUint(d);
        if (pc.mode == 0u) {
          // A plain read first: most candidates lose, and atomics are costly under contention
          // (many small triangles per node). A stale read only costs an unneeded atomic.
          if (bits < distBits[v]) atomicMin(distBits[v], bits);
        } else if (distBits[v] == bits) {
          // The first equal triangle replaces kNoTriangle, a later larger id replaces it.
          uint old = atomicCompSwap(idsA[v], kNoTriangle, t);
          if (old != kNoTriangle && old < t) atomicMax(idsA[v], t);
        }
      }
    }
  }
}
