#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
// Pass 4, one invocation per node, once per jump step: jump flooding (Rong & Tan 2006) of
// closest-triangle ids. A node looks at the 26 nodes `step` away and keeps, of its own and
// their triangles, the one at the smallest exact distance from itself. Distances are always
// exact point-triangle distances, so a propagated id can only make a node's value larger than
// the true distance when the flood missed the true closest triangle.
// The builder takes this pass on CPU devices (lavapipe) for grids over 4096 nodes; smaller grids
// there flood in one work group (sdf_flood_group.comp), and GPUs take sdf_jfa_wide.comp, a lane
// per neighbour: all three give the same ids, bit for bit (tests/unit/vk_sdf.tests.cpp).
#include "sdf_common.glsl"

// Bindings 6 and 7: ping-pong id buffers; pc.flip picks the direction.
layout(std430, set = 0, binding = 6) buffer IdsA { uint idsA[]; };
layout(std430, set = 0, binding = 7) buffer IdsB { uint idsB[]; };

layout(push_constant) uniform Push { uint step; uint flip; } pc;

uint readId(uint v) { return pc.flip == 0u ? idsA[v] : idsB[v]; }

void main() {
  uint v = gl_GlobalInvocationID.x;
  if (v >= P.res.w) return;  // the dispatch is rounded up to whole groups
  uvec3 ijk = nodeCoords(v);
  vec3 p = nodePosition(ijk);
  uint best = readId(v);
  float bestD = best == kNoTriangle ? 3.4e38 : triangleDistance(p, best);
  // Within one spacing the splat already found the exact closest triangle (every triangle that
  // close covered this node); nothing can beat it.
  float exactBand = min(P.spacing.x, min(P.spacing.y, P.spacing.z));
  if (bestD > exactBand) {
    ivec3 base = ivec3(ijk);
    ivec3 n = ivec3(P.res.xyz);
    int s = int(pc.step);
    // Every neighbour's id first, then the candidates: 27 loads in flight together instead of
    // one after another (the pass waits on memory, not arithmetic). Same order as before: x
    // fastest, then y, then z.
    uint cands[27];
    [[unroll]] for (int o = 0; o < 27; ++o) {
      ivec3 q = base + (ivec3(o % 3, (o / 3) % 3, o / 9) - 1) * s;
      bool inGrid = all(greaterThanEqual(q, ivec3(0))) && all(lessThan(q, n));
      cands[o] =
          inGrid ? readId(uint(q.x) + P.res.x * (uint(q.y) + P.res.y * uint(q.z))) : kNoTriangle;
    }
    uint last = best;  // neighbours often share one id: evaluate a repeat only once
    [[unroll]] for (int o = 0; o < 27; ++o) {
      uint cand = cands[o];
      if (cand == kNoTriangle || cand == best || cand == last) continue;
      last = cand;
      // Lower bound from the sphere about corner a through the farther corner: a candidate
      // that cannot beat the best skips the exact distance.
      vec3 a = tri[3u * cand].xyz;
      float reach = sqrt(max(dot(tri[3u * cand + 1u].xyz - a, tri[3u * cand + 1u].xyz - a),
                             dot(tri[3u * cand + 2u].xyz - a, tri[3u * cand + 2u].xyz - a)));
      if (length(p - a) - reach >= bestD) continue;
      float d = triangleDistance(p, cand);
      if (d < bestD) {
        bestD = d;
        best = cand;
      }
    }
  }
  if (pc.flip == 0u) idsB[v] = best; else idsA[v] = best;
}
