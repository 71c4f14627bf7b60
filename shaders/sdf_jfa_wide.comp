#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 4 on GPUs, once per jump step: the jump step of sdf_jfa.comp with 32 lanes per node
// instead of one invocation, for the same ids bit for bit. sdf_jfa.comp's invocation evaluates
// up to 26 candidate triangles one after another; with one node per invocation a 16^3 grid is
// only 64 groups of 64, so each step waited on that serial chain (~15 us a step on an H200).
// Here lane k < 27 of a node reads neighbour k's id (the same order: x fastest, then y, then z;
// k = 13 is the node itself) and computes its candidate's lower bound and exact distance, lane 27
// the node's own distance, all side by side. Then one lane per node replays sdf_jfa.comp's loop
// over those stored values: the same skips (kNoTriangle, the current best, the last candidate
// evaluated, the lower bound against the current best) and the same strict comparison, so the
// first smallest distance in scan order wins and the own id wins ties, exactly as there. The
// replay only compares stored floats: no triangle is evaluated serially any more.
#define SDF_FIXED_LOCAL_SIZE
#include "sdf_common.glsl"

// Mirrored by vk_layout::kWideFloodThreads / kWideFloodNodesPerGroup (src/engine/vulkan).
const uint kLanes = 32u;  // per node: 27 neighbours (the node itself among them), its own distance
const uint kThreads = 64u;
layout(local_size_x = 64) in;

// Bindings 6 and 7: ping-pong id buffers; pc.flip picks the direction.
layout(std430, set = 0, binding = 6) buffer IdsA { uint idsA[]; };
layout(std430, set = 0, binding = 7) buffer IdsB { uint idsB[]; };

layout(push_constant) uniform Push { uint step; uint flip; } pc;

// Per lane: its neighbour's id, that candidate's lower bound and exact distance. Lane 27 of a node
// leaves its node's own distance in sD.
shared uint sCand[kThreads];
shared float sLow[kThreads];
shared float sD[kThreads];

uint readId(uint v) { return pc.flip == 0u ? idsA[v] : idsB[v]; }

void main() {
  uint lid = gl_LocalInvocationID.x;
  uint lane = lid % kLanes;
  uint first = lid - lane;  // this node's lane 0 in the group
  uint v = gl_WorkGroupID.x * (kThreads / kLanes) + lid / kLanes;
  bool live = v < P.res.w;  // the dispatch is rounded up to whole groups
  uvec3 ijk = live ? nodeCoords(v) : uvec3(0u);
  vec3 p = nodePosition(ijk);
  if (live && lane < 27u) {
    ivec3 q = ivec3(ijk) + (ivec3(int(lane) % 3, (int(lane) / 3) % 3, int(lane) / 9) - 1) *
                               int(pc.step);
    bool inGrid = all(greaterThanEqual(q, ivec3(0))) && all(lessThan(q, ivec3(P.res.xyz)));
    uint cand =
        inGrid ? readId(uint(q.x) + P.res.x * (uint(q.y) + P.res.y * uint(q.z))) : kNoTriangle;
    sCand[lid] = cand;
    // The node's own id (lane 13 reads it) is never a candidate; every other id is evaluated
    // here even where the replay will skip it (a repeat, or a bound above the best so far): in
    // parallel that costs no time, and the replay decides as sdf_jfa.comp does.
    if (cand != kNoTriangle && lane != 13u) {
      // As sdf_jfa.comp: the sphere about corner a through the farther corner.
      vec3 a = tri[3u * cand].xyz;
      float reach = sqrt(max(dot(tri[3u * cand + 1u].xyz - a, tri[3u * cand + 1u].xyz - a),
                             dot(tri[3u * cand + 2u].xyz - a, tri[3u * cand + 2u].xyz - a)));
      sLow[lid] = length(p - a) - reach;
      sD[lid] = triangleDistance(p, cand);
    }
  } else if (live && lane == 27u) {
    uint own = readId(v);
    sD[lid] = own == kNoTriangle ? 3.4e38 : triangleDistance(p, own);
  }
  barrier();
  if (!live || lane != 0u) return;
  // sdf_jfa.comp's main() on the stored values.
  uint best = sCand[first + 13u];
  float bestD = sD[first + 27u];
  float exactBand = min(P.spacing.x, min(P.spacing.y, P.spacing.z));
  if (bestD > exactBand) {
    uint last = best;
    for (uint o = 0u; o < 27u; ++o) {
      uint cand = sCand[first + o];
      if (cand == kNoTriangle || cand == best || cand == last) continue;
      last = cand;
      // The node's own id again (the best changed): its distance, bestD before any change,
      // cannot beat the best; only `last` changes, as there. (Lane 13 stored no values.)
      if (o == 13u || sLow[first + o] >= bestD) continue;
      float d = sD[first + o];
      if (d < bestD) {
        bestD = d;
        best = cand;
      }
    }
  }
  if (pc.flip == 0u) idsB[v] = best; else idsA[v] = best;
}
