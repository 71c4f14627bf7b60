#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 4 for grids of at most kMaxNodes nodes (16^3), one work group of kThreads invocations:
// the whole jump flood of sdf_jfa.comp (the same steps, candidates, order and comparisons, so
// the same ids) with every node's id in shared memory and a group barrier between steps, instead
// of one dispatch and one pipeline barrier per step. With pseudo-normal signs it goes on to the
// final values and their repair (sdf_final.glsl, as sdf_finalize.comp and sdf_repair.comp) and
// samples the points (sdf_trilinear.glsl, as sdf_sample.comp): one dispatch does everything
// after the splat. With the winding-number sign it writes the final ids to binding 7 for
// sdf_finalize.comp, whose per-node winding sums want the whole device.
#define SDF_FIXED_LOCAL_SIZE
#include "sdf_common.glsl"

// Mirrored by vk_layout::kFloodGroupThreads / kFloodGroupNodes (src/engine/vulkan).
const uint kThreads = 1024u;
const uint kPerThread = 4u;
const uint kMaxNodes = kThreads * kPerThread;  // 16 KB of shared ids: the guaranteed minimum
layout(local_size_x = 1024) in;

// Binding 6: the splat's seeds (closest-triangle ids, kNoTriangle where none).
layout(std430, set = 0, binding = 6) readonly buffer IdsA { uint idsA[]; };
// Binding 7: the final ids, winding-number mode only (read by sdf_finalize.comp, flip 1).
layout(std430, set = 0, binding = 7) writeonly buffer IdsB { uint idsB[]; };
// Binding 8: the signed distances, pseudo-normal mode.
layout(std430, set = 0, binding = 8) writeonly buffer Values { float values[]; };
// Binding 9: points, normalized box coordinates in xyz (w unused).
layout(std430, set = 0, binding = 9) readonly buffer Points { vec4 points[]; };
// Binding 10: one sampled value per point.
layout(std430, set = 0, binding = 10) writeonly buffer Samples { float samples[]; };

// Per node: the id during the flood, then the unrepaired value, then the repaired value (bits).
shared uint node[kMaxNodes];

#define SDF_UNREPAIRED(i) uintBitsToFloat(node[i])
#include "sdf_final.glsl"
#define SDF_NODE_VALUE(i) uintBitsToFloat(node[i])
#include "sdf_trilinear.glsl"

// One node's jump step, as sdf_jfa.comp's main() with its own id and distance carried in
// registers (the same triangleDistance() of the same id, so the same bits), and the neighbours
// in the same order (x fastest, then y, then z). The range of offsets is clipped to the grid
// once instead of testing every neighbour: the group's one multiprocessor is busy, not waiting,
// so instructions count here.
void floodNode(vec3 p, uvec3 ijk, uint s, inout uint best, inout float bestD) {
  ivec3 lo = ivec3(greaterThanEqual(ijk, uvec3(s))) * -1;      // -1 where ijk - s is in the grid
  ivec3 hi = ivec3(lessThan(ijk + s, P.res.xyz));              // 1 where ijk + s is
  uint rowStep = s * P.res.x, layerStep = s * P.res.x * P.res.y;
  uint centre = ijk.x + P.res.x * (ijk.y + P.res.y * ijk.z);
  uint last = best;  // neighbours often share one id: evaluate a repeat only once
  for (int dz = lo.z; dz <= hi.z; ++dz) {
    for (int dy = lo.y; dy <= hi.y; ++dy) {
      uint row = centre + uint(dy) * rowStep + uint(dz) * layerStep;  // wraps like int arithmetic
      for (int dx = lo.x; dx <= hi.x; ++dx) {
        uint cand = node[row + uint(dx) * s];
        if (cand == kNoTriangle || cand == best || cand == last) continue;
        last = cand;
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
  }
}

void main() {
  uint lid = gl_LocalInvocationID.x;
  uint count = P.res.w;  // at most kMaxNodes (the host's choice of this pass)
  // This invocation's nodes: lid, lid + kThreads, ...
  uint best[kPerThread];
  float bestD[kPerThread];
  for (uint k = 0u; k < kPerThread; ++k) {
    uint v = lid + k * kThreads;
    best[k] = kNoTriangle;
    bestD[k] = 3.4e38;
    if (v < count) {
      best[k] = idsA[v];
      node[v] = best[k];
      if (best[k] != kNoTriangle) bestD[k] = triangleDistance(nodePosition(nodeCoords(v)), best[k]);
    }
  }
  barrier();

  // The steps of jumpSteps() (vk_sdf_prepare.cpp): the largest power of two below the longest
  // axis, halving to 1, then 2 and 1 again when that axis has more than 2 nodes.
  uint longest = max(P.res.x, max(P.res.y, P.res.z));
  uint first = 1u;
  while (first * 2u < longest) first *= 2u;
  uint halvings = uint(findMSB(first)) + 1u;
  uint steps = halvings + (longest > 2u ? 2u : 0u);
  // Within one spacing the splat already found the exact closest triangle.
  float exactBand = min(P.spacing.x, min(P.spacing.y, P.spacing.z));
  for (uint i = 0u; i < steps; ++i) {
    uint s = i < halvings ? first >> i : (i == halvings ? 2u : 1u);
    for (uint k = 0u; k < kPerThread; ++k) {
      uint v = lid + k * kThreads;
      if (v < count && bestD[k] > exactBand) {
        uvec3 ijk = nodeCoords(v);
        floodNode(nodePosition(ijk), ijk, s, best[k], bestD[k]);
      }
    }
    barrier();  // every read of this step's ids is done
    for (uint k = 0u; k < kPerThread; ++k) {
      uint v = lid + k * kThreads;
      if (v < count) node[v] = best[k];
    }
    barrier();  // the next step reads them
  }

  if (P.signMode != 1u) {
    for (uint k = 0u; k < kPerThread; ++k) {
      uint v = lid + k * kThreads;
      if (v < count) idsB[v] = best[k];
    }
    return;
  }

  float value[kPerThread];
  for (uint k = 0u; k < kPerThread; ++k) {
    uint v = lid + k * kThreads;
    value[k] = 0.0;
    if (v < count) {
      value[k] = pseudoNormalValue(nodePosition(nodeCoords(v)), best[k]);
      node[v] = floatBitsToUint(value[k]);  // nothing reads ids any more (last barrier above)
    }
  }
  barrier();  // the repair reads the neighbours' unrepaired values
  for (uint k = 0u; k < kPerThread; ++k) {
    uint v = lid + k * kThreads;
    if (v < count) {
      value[k] = repairedValue(v, value[k]);
      values[v] = value[k];
    }
  }
  barrier();  // every unrepaired value is read
  for (uint k = 0u; k < kPerThread; ++k) {
    uint v = lid + k * kThreads;
    if (v < count) node[v] = floatBitsToUint(value[k]);
  }
  barrier();  // the sampling reads repaired values
  for (uint s = lid; s < P.pointCount; s += kThreads) samples[s] = sampleGrid(points[s].xyz);
}
