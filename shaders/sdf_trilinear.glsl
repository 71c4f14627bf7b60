// Trilinear sampling of the node grid at normalized box coordinates, clamped to the box (the
// paper's Algorithm 2), shared by sdf_sample.comp (from the values buffer) and
// sdf_flood_group.comp (from shared memory). The includer defines SDF_NODE_VALUE(i), the value of
// node i. Done by hand with the same arithmetic as SdfGrid::sampleNormalized (src/sdf_grid.cpp),
// so the GPU and the CPU agree to rounding; `precise` keeps the compiler from fusing the lerps
// differently.

void locate(float u, uint n, out uint i0, out float t) {
  precise float x = clamp(u, 0.0, 1.0) * float(n - 1u);
  float fl = min(floor(x), float(n - 2u));
  i0 = uint(fl);
  t = x - fl;
}

float sampleGrid(vec3 uvw) {
  uint i, j, k;
  float tx, ty, tz;
  locate(uvw.x, P.res.x, i, tx);
  locate(uvw.y, P.res.y, j, ty);
  locate(uvw.z, P.res.z, k, tz);
  uint sx = 1u, sy = P.res.x, sz = P.res.x * P.res.y;
  uint b = i + P.res.x * (j + P.res.y * k);
  precise float c00 = SDF_NODE_VALUE(b) + (SDF_NODE_VALUE(b + sx) - SDF_NODE_VALUE(b)) * tx;
  precise float c10 =
      SDF_NODE_VALUE(b + sy) + (SDF_NODE_VALUE(b + sy + sx) - SDF_NODE_VALUE(b + sy)) * tx;
  precise float c01 =
      SDF_NODE_VALUE(b + sz) + (SDF_NODE_VALUE(b + sz + sx) - SDF_NODE_VALUE(b + sz)) * tx;
  precise float c11 = SDF_NODE_VALUE(b + sz + sy) +
                      (SDF_NODE_VALUE(b + sz + sy + sx) - SDF_NODE_VALUE(b + sz + sy)) * tx;
  precise float c0 = c00 + (c10 - c00) * ty;
  precise float c1 = c01 + (c11 - c01) * ty;
  precise float result = c0 + (c1 - c0) * tz;
  return isnan(uvw.x + uvw.y + uvw.z) ? uintBitsToFloat(0x7fc00000u) : result;
}
