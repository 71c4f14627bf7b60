#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 2, one invocation per node of one level of the winding-number hierarchy: a level-0 node
// sums kFanOut consecutive triangles, a level-l node kFanOut level-(l-1) nodes. Each node keeps
// what the far-field (dipole) approximation of its solid angle needs: the area-weighted ctr,
// a radius bounding its triangles, and the sum of its area vectors (Barill et al. 2018, order 1).
#include "sdf_common.glsl"

struct HierarchyNode {
  vec4 centroidRadius;  // xyz: area-weighted ctr (box space); w: bounding radius
  vec4 areaVector;      // xyz: sum of 0.5 * cross(b - a, c - a); w: total area
};
// Binding 4: all levels of the hierarchy, level after level (offsets in P).
layout(std430, set = 0, binding = 4) buffer Hierarchy { HierarchyNode nodes[]; };

layout(push_constant) uniform Push { uint level; } pc;

void main() {
  uint n = gl_GlobalInvocationID.x;
  if (n >= levelCount(pc.level)) return;  // the dispatch is rounded up to whole groups
  vec3 weighted = vec3(0.0), plainSum = vec3(0.0), areaVector = vec3(0.0);
  float area = 0.0, count = 0.0;
  uint first = n * kFanOut;
  if (pc.level == 0u) {
    uint last = min(first + kFanOut, P.triangleCount);
    for (uint t = first; t < last; ++t) {
      vec4 a = tri[3u * t];
      if (a.w < 0.0) continue;  // dropped triangle
      vec3 b = tri[3u * t + 1u].xyz, c = tri[3u * t + 2u].xyz;
      vec3 av = 0.5 * cross(b - a.xyz, c - a.xyz);
      float ar = length(av);
      vec3 centre = (a.xyz + b + c) / 3.0;
      weighted += ar * centre;
      plainSum += centre;
      areaVector += av;
      area += ar;
      count += 1.0;
    }
    vec3 ctr = area > 0.0 ? weighted / area : (count > 0.0 ? plainSum / count : vec3(0.0));
    float radius = 0.0;
    for (uint t = first; t < last; ++t) {
      if (tri[3u * t].w < 0.0) continue;
      for (uint k = 0u; k < 3u; ++k) radius = max(radius, length(tri[3u * t + k].xyz - ctr));
    }
    nodes[levelOffset(0u) + n].centroidRadius = vec4(ctr, radius);
    nodes[levelOffset(0u) + n].areaVector = vec4(areaVector, area);
    return;
  }
  uint below = levelOffset(pc.level - 1u);
  uint last = min(first + kFanOut, levelCount(pc.level - 1u));
  for (uint m = first; m < last; ++m) {
    HierarchyNode child = nodes[below + m];
    weighted += child.areaVector.w * child.centroidRadius.xyz;
    plainSum += child.centroidRadius.xyz;
    areaVector += child.areaVector.xyz;
    area += child.areaVector.w;
    count += 1.0;
  }
  vec3 ctr = area > 0.0 ? weighted / area : (count > 0.0 ? plainSum / count : vec3(0.0));
  float radius = 0.0;
  for (uint m = first; m < last; ++m) {
    HierarchyNode child = nodes[below + m];
    radius = max(radius, length(child.centroidRadius.xyz - ctr) + child.centroidRadius.w);
  }
  nodes[levelOffset(pc.level) + n].centroidRadius = vec4(ctr, radius);
  nodes[levelOffset(pc.level) + n].areaVector = vec4(areaVector, area);
}
