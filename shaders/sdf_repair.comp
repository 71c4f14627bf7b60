#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 5b, one invocation per node, pseudo-normal mode only: repairs isolated sign errors of the
// flood. A flooded id can be a slightly farther triangle than the closest (the back of a thin
// part), whose pseudo-normal then gives the wrong side. A node at distance r > spacing has no
// surface within r, so its six face neighbours (one spacing away) are on its side of the
// surface: such a node takes the majority sign of itself and them. Nodes nearer the surface
// have their exact closest triangle (the splat) and keep their sign.
#include "sdf_common.glsl"

layout(std430, set = 0, binding = 5) readonly buffer Unrepaired { float unrepaired[]; };
layout(std430, set = 0, binding = 8) writeonly buffer Values { float values[]; };

void main() {
  uint v = gl_GlobalInvocationID.x;
  if (v >= P.res.w) return;  // the dispatch is rounded up to whole groups
  float value = unrepaired[v];
  float h = max(P.spacing.x, max(P.spacing.y, P.spacing.z));
  // 1.5 spacings: the flood's distance may exceed the true one a little.
  if (abs(value) <= 1.5 * h) {
    values[v] = value;
    return;
  }
  ivec3 ijk = ivec3(nodeCoords(v));
  ivec3 n = ivec3(P.res.xyz);
  int inside = value < 0.0 ? 1 : 0, votes = 1;
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = -1; side <= 1; side += 2) {
      ivec3 q = ijk;
      q[axis] += side;
      if (q[axis] < 0 || q[axis] >= n[axis]) continue;
      float neighbour = unrepaired[uint(q.x) + P.res.x * (uint(q.y) + P.res.y * uint(q.z))];
      inside += neighbour < 0.0 ? 1 : 0;
      ++votes;
    }
  }
  // Ties keep the node's own sign.
  bool negative = 2 * inside == votes ? value < 0.0 : 2 * inside > votes;
  values[v] = negative ? -abs(value) : abs(value);
}
