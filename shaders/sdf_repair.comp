#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 5b, one invocation per node, pseudo-normal mode only: the majority-sign repair of
// sdf_final.glsl (repairedValue) from the values sdf_finalize.comp left in binding 5.
#include "sdf_common.glsl"

layout(std430, set = 0, binding = 5) readonly buffer Unrepaired { float unrepaired[]; };
layout(std430, set = 0, binding = 8) writeonly buffer Values { float values[]; };

#define SDF_UNREPAIRED(i) unrepaired[i]
#include "sdf_final.glsl"

void main() {
  uint v = gl_GlobalInvocationID.x;
  if (v >= P.res.w) return;  // the dispatch is rounded up to whole groups
  values[v] = repairedValue(v, unrepaired[v]);
}
