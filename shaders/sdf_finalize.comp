#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 5, one invocation per node: the exact distance to the node's propagated closest triangle,
// signed, on closed and consistently oriented meshes given as arrays, by the pseudo-normal of the
// closest feature (as the CPU builder does), and otherwise by the generalized winding number of
// the whole mesh (Jacobson et al. 2013): inside where it exceeds 0.5. The winding number is
// summed over the hierarchy of pass 2, exact for triangles in nodes closer than beta * radius,
// the node's dipole term beyond (Barill et al. 2018). It degrades gracefully at holes and needs
// no adjacency: the app's skinned buffers work as they are. The pseudo-normal value and the
// repair of sdf_repair.comp are in sdf_final.glsl, shared with sdf_flood_group.comp.
#include "sdf_common.glsl"

struct HierarchyNode {
  vec4 centroidRadius;
  vec4 areaVector;
};
layout(std430, set = 0, binding = 4) readonly buffer Hierarchy { HierarchyNode nodes[]; };
// Binding 6 or 7 holds the final ids (pc.flip says which; see sdf_jfa.comp).
layout(std430, set = 0, binding = 6) readonly buffer IdsA { uint idsA[]; };
layout(std430, set = 0, binding = 7) readonly buffer IdsB { uint idsB[]; };
// Binding 8: the signed distances, node-centred, values[i + Nx * (j + Ny * k)].
layout(std430, set = 0, binding = 8) writeonly buffer Values { float values[]; };
// Binding 5 (the splat's scratch, free by now): the values before sdf_repair, pseudo-normal mode.
layout(std430, set = 0, binding = 5) writeonly buffer Unrepaired { float unrepaired[]; };

// Only pseudoNormalValue() is used here; repairedValue() is sdf_repair.comp's.
#define SDF_UNREPAIRED(i) 0.0
#include "sdf_final.glsl"

void store(uint v, float value) {
  if (P.signMode == 1u) unrepaired[v] = value; else values[v] = value;
}

layout(push_constant) uniform Push { uint step; uint flip; } pc;

const float kFourPi = 12.566370614359172;
const uint kStackSize = 5u * kFanOut;

// Solid angle of triangle (a, b, c), given relative to the query point (Van Oosterom & Strackee
// 1983); positive seen from behind a counter-clockwise face.
float solidAngle(vec3 a, vec3 b, vec3 c) {
  float la = length(a), lb = length(b), lc = length(c);
  float det = dot(a, cross(b, c));
  float den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
  if (det == 0.0 && den <= 0.0) return 0.0;  // on the triangle's plane at or behind a corner
  return 2.0 * atan(det, den);
}

float windingNumber(vec3 p) {
  uint stack[kStackSize];
  uint sp = 0u;
  uint top = P.nodeLevels - 1u;
  for (uint n = 0u; n < P.topNodeCount; ++n) stack[sp++] = (top << 27u) | n;
  float omega = 0.0;
  float beta2 = P.windingBeta * P.windingBeta;
  while (sp > 0u) {
    uint entry = stack[--sp];
    uint level = entry >> 27u, index = entry & 0x07ffffffu;
    HierarchyNode node = nodes[levelOffset(level) + index];
    vec3 r = node.centroidRadius.xyz - p;
    float dist2 = dot(r, r);
    float radius = node.centroidRadius.w;
    if (dist2 > beta2 * radius * radius) {
      omega += dot(node.areaVector.xyz, r) / (dist2 * sqrt(dist2));
      continue;
    }
    uint first = index * kFanOut;
    if (level == 0u) {
      uint last = min(first + kFanOut, P.triangleCount);
      for (uint t = first; t < last; ++t) {
        vec4 a = tri[3u * t];
        if (a.w < 0.0) continue;  // dropped triangle
        omega += solidAngle(a.xyz - p, tri[3u * t + 1u].xyz - p, tri[3u * t + 2u].xyz - p);
      }
    } else {
      uint last = min(first + kFanOut, levelCount(level - 1u));
      // At most kFanOut children per level on the stack: kStackSize bounds the depth-first walk.
      for (uint m = first; m < last && sp < kStackSize; ++m) stack[sp++] = ((level - 1u) << 27u) | m;
    }
  }
  return omega / kFourPi;
}

void main() {
  uint v = gl_GlobalInvocationID.x;
  if (v >= P.res.w) return;  // the dispatch is rounded up to whole groups
  vec3 p = nodePosition(nodeCoords(v));
  uint id = pc.flip == 0u ? idsA[v] : idsB[v];
  if (P.signMode == 1u) {
    store(v, pseudoNormalValue(p, id));
    return;
  }
  // No triangle within the cull margin: the surface is farther than the margin; spacing.w holds
  // the value to report (the margin), signed like every other node.
  if (id == kNoTriangle) {
    store(v, windingNumber(p) > 0.5 ? -P.spacing.w : P.spacing.w);
    return;
  }
  vec3 a = tri[3u * id].xyz, b = tri[3u * id + 1u].xyz, c = tri[3u * id + 2u].xyz;
  uint feature;
  float d = length(p - closestOnTriangleFeature(p, a, b, c, feature));
  store(v, windingNumber(p) > 0.5 ? -d : d);
}
