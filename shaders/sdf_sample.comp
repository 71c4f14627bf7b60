#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 6, one invocation per point: trilinear sampling of the built grid (sdf_trilinear.glsl).
// Runs after sdf_finalize.comp / sdf_repair.comp, and alone when the last built grid is sampled
// again; sdf_flood_group.comp samples in its own dispatch.
#include "sdf_common.glsl"

layout(std430, set = 0, binding = 8) readonly buffer Values { float values[]; };
// Binding 9: points, normalized box coordinates in xyz (w unused).
layout(std430, set = 0, binding = 9) readonly buffer Points { vec4 points[]; };
// Binding 10: one sampled value per point.
layout(std430, set = 0, binding = 10) writeonly buffer Samples { float samples[]; };

#define SDF_NODE_VALUE(i) values[i]
#include "sdf_trilinear.glsl"

void main() {
  uint s = gl_GlobalInvocationID.x;
  if (s >= P.pointCount) return;  // the dispatch is rounded up to whole groups
  samples[s] = sampleGrid(points[s].xyz);
}
