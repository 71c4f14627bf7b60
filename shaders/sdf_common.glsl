// Shared declarations of the grab-box SDF compute passes. Every struct here mirrors a host struct
// in src/vk_sdf_layout.h field for field; the host static_asserts sizes and offsets.
//
// Space: "box space" is the grab box's local frame in metres, centre at 0, spanning +-size/2.
// Node (i, j, k) sits at (i, j, k) * spacing - size / 2 (src/sdf_grid.h).


// Work-group size from the host (clamped to the device limits); 64 when not specialized. A pass
// with a fixed size of its own (sdf_flood_group.comp) defines SDF_FIXED_LOCAL_SIZE first.
#ifndef SDF_FIXED_LOCAL_SIZE
layout(local_size_x_id = 0) in;
#endif

// Binding 0: per-build parameters (host-visible, written before each submission). A storage
// buffer, not a uniform block: Mesa's lavapipe inlines uniform values into a recompiled shader
// variant and kept every variant, growing by ~230 KB per build (Mesa 22.3).
layout(std430, set = 0, binding = 0) readonly buffer BuildParams {
  mat4 boxFromObject;   // mesh space -> box space (rigid)
  vec4 boxHalf;         // xyz: size / 2; w: cull margin (metres)
  vec4 spacing;         // xyz: node spacing; w: distance written where no triangle is known
  uvec4 res;            // xyz: nodes per axis; w: node count
  uint triangleCount;   // triangles in the mesh source
  uint vertexCount;     // vertices addressable in the position source
  uint positionOffset;  // first position, in 32-bit words from the start of binding 1
  uint positionStride;  // between positions, in 32-bit words
  uint indexOffset;     // first index, in elements of the index type, from binding 2's start
  uint index16;         // 1: 16-bit indices, 0: 32-bit
  uint nodeLevels;      // levels of the winding-number hierarchy (>= 1)
  uint topNodeCount;    // nodes at the top level
  uint pointCount;      // points to sample
  uint levelOffset0;    // first node of each level in binding 4 (level 0 = clusters of
  uint levelOffset1;    //   kFanOut triangles, level l+1 = clusters of kFanOut level-l nodes)
  uint levelOffset2;
  uint levelOffset3;
  uint levelOffset4;
  uint levelCount0;     // nodes at each level
  uint levelCount1;
  uint levelCount2;
  uint levelCount3;
  uint levelCount4;
  float windingBeta;    // a cluster farther than beta * radius uses its dipole approximation
  uint signMode;       // 0: winding number; 1: pseudo-normals of binding 11 (closed meshes)
  uint pad1;
  uint pad2;
} P;

const uint kFanOut = 32u;
const uint kNoTriangle = 0xffffffffu;

// Binding 3: every triangle in box space: a.xyz, b.xyz, c.xyz. a.w: 1 within the cull margin of
// the box, 0 valid but outside it, -1 dropped (bad index or non-finite corner).
layout(std430, set = 0, binding = 3) buffer Triangles { vec4 tri[]; };

uint levelOffset(uint l) {
  return l == 0u ? P.levelOffset0 : l == 1u ? P.levelOffset1 : l == 2u ? P.levelOffset2
       : l == 3u ? P.levelOffset3 : P.levelOffset4;
}
uint levelCount(uint l) {
  return l == 0u ? P.levelCount0 : l == 1u ? P.levelCount1 : l == 2u ? P.levelCount2
       : l == 3u ? P.levelCount3 : P.levelCount4;
}

vec3 nodePosition(uvec3 ijk) { return vec3(ijk) * P.spacing.xyz - P.boxHalf.xyz; }

uvec3 nodeCoords(uint v) {
  uint i = v % P.res.x;
  uint r = v / P.res.x;
  return uvec3(i, r % P.res.y, r / P.res.y);
}

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5): the
// Voronoi region of p decides vertex, edge or face, so the result is exact, not iterative.
vec3 closestOnTriangle(vec3 p, vec3 a, vec3 b, vec3 c) {
  vec3 ab = b - a, ac = c - a, ap = p - a;
  float d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  vec3 bp = p - b;
  float d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + ab * (d1 / (d1 - d3));
  vec3 cp = p - c;
  float d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + ac * (d2 / (d2 - d6));
  float va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  float denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

float triangleDistance(vec3 p, uint t) {
  vec3 a = tri[3u * t].xyz, b = tri[3u * t + 1u].xyz, c = tri[3u * t + 2u].xyz;
  return length(p - closestOnTriangle(p, a, b, c));
}

// Same as closestOnTriangle, also naming the closest feature: 0 face, 1 + e edge e (edge 0 is
// a-b, 1 is b-c, 2 is c-a), 4 + k corner k.
vec3 closestOnTriangleFeature(vec3 p, vec3 a, vec3 b, vec3 c, out uint feature) {
  vec3 ab = b - a, ac = c - a, ap = p - a;
  float d1 = dot(ab, ap), d2 = dot(ac, ap);
  feature = 4u;
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  vec3 bp = p - b;
  float d3 = dot(ab, bp), d4 = dot(ac, bp);
  feature = 5u;
  if (d3 >= 0.0 && d4 <= d3) return b;
  float vc = d1 * d4 - d3 * d2;
  feature = 1u;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + ab * (d1 / (d1 - d3));
  vec3 cp = p - c;
  float d5 = dot(ab, cp), d6 = dot(ac, cp);
  feature = 6u;
  if (d6 >= 0.0 && d5 <= d6) return c;
  float vb = d5 * d2 - d1 * d6;
  feature = 3u;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + ac * (d2 / (d2 - d6));
  float va = d3 * d6 - d5 * d4;
  feature = 2u;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  feature = 0u;
  float denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}
