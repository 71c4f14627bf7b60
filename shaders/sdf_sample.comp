#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 6, one invocation per point: the paper's Algorithm 2, trilinear sampling of the node grid
// at normalized box coordinates, clamped to the box. Done by hand from the storage buffer with
// the same arithmetic as SdfGrid::sampleNormalized (src/sdf_grid.cpp), so the GPU and the CPU
// agree to rounding; `precise` keeps the compiler from fusing the lerps differently.
#include "sdf_common.glsl"

layout(std430, set = 0, binding = 8) readonly buffer Values { float values[]; };
// Binding 9: points, normalized box coordinates in xyz (w unused).
layout(std430, set = 0, binding = 9) readonly buffer Points { vec4 points[]; };
// Binding 10: one sampled value per point.
layout(std430, set = 0, binding = 10) writeonly buffer Samples { float samples[]; };

void locate(float u, uint n, out uint i0, out float t) {
  precise float x = clamp(u, 0.0, 1.0) * float(n - 1u);
  float fl = min(floor(x), float(n - 2u));
  i0 = uint(fl);
  t = x - fl;
}

void main() {
  uint s = gl_GlobalInvocationID.x;
  if (s >= P.pointCount) return;  // the dispatch is rounded up to whole groups
  vec3 uvw = points[s].xyz;
  uint i, j, k;
  float tx, ty, tz;
  locate(uvw.x, P.res.x, i, tx);
  locate(uvw.y, P.res.y, j, ty);
  locate(uvw.z, P.res.z, k, tz);
  uint sx = 1u, sy = P.res.x, sz = P.res.x * P.res.y;
  uint b = i + P.res.x * (j + P.res.y * k);
  precise float c00 = values[b] + (values[b + sx] - values[b]) * tx;
  precise float c10 = values[b + sy] + (values[b + sy + sx] - values[b + sy]) * tx;
  precise float c01 = values[b + sz] + (values[b + sz + sx] - values[b + sz]) * tx;
  precise float c11 = values[b + sz + sy] + (values[b + sz + sy + sx] - values[b + sz + sy]) * tx;
  precise float c0 = c00 + (c10 - c00) * ty;
  precise float c1 = c01 + (c11 - c01) * ty;
  precise float result = c0 + (c1 - c0) * tz;
  samples[s] = isnan(uvw.x + uvw.y + uvw.z) ? uintBitsToFloat(0x7fc00000u) : result;
}
