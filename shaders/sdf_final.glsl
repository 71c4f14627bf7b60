// The final value of a node with the pseudo-normal sign, and its repair, shared by
// sdf_finalize.comp / sdf_repair.comp (values in buffers) and sdf_flood_group.comp (values in
// shared memory). The includer defines SDF_UNREPAIRED(i), the unrepaired value of node i.

// Binding 11: per triangle, object-space pseudo-normals of its edges 0..2 then corners 0..2
// (equal-weight edge normals, angle-weighted vertex normals; Baerentzen & Aanaes 2005).
layout(std430, set = 0, binding = 11) readonly buffer PseudoNormals { vec4 pseudoNormals[]; };

// The exact distance from p to triangle `id`, negative on the inner side of the pseudo-normal of
// its closest feature (closed, consistently oriented meshes, as the CPU builder signs them). No
// triangle within the cull margin: the surface is farther than the margin; spacing.w holds the
// value to report (the margin).
float pseudoNormalValue(vec3 p, uint id) {
  if (id == kNoTriangle) return P.spacing.w;
  vec3 a = tri[3u * id].xyz, b = tri[3u * id + 1u].xyz, c = tri[3u * id + 2u].xyz;
  uint feature;
  vec3 q = closestOnTriangleFeature(p, a, b, c, feature);
  float d = length(p - q);
  vec3 n = feature == 0u ? cross(b - a, c - a)
                         : mat3(P.boxFromObject) * pseudoNormals[6u * id + feature - 1u].xyz;
  return dot(p - q, n) < 0.0 ? -d : d;
}

// Repairs isolated sign errors of the flood. A flooded id can be a slightly farther triangle than
// the closest (the back of a thin part), whose pseudo-normal then gives the wrong side. A node at
// distance r > spacing has no surface within r, so its six face neighbours (one spacing away) are
// on its side of the surface: such a node takes the majority sign of itself and them. Nodes
// nearer the surface have their exact closest triangle (the splat) and keep their sign.
float repairedValue(uint v, float value) {
  float h = max(P.spacing.x, max(P.spacing.y, P.spacing.z));
  // 1.5 spacings: the flood's distance may exceed the true one a little.
  if (abs(value) <= 1.5 * h) return value;
  ivec3 ijk = ivec3(nodeCoords(v));
  ivec3 n = ivec3(P.res.xyz);
  int inside = value < 0.0 ? 1 : 0, votes = 1;
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = -1; side <= 1; side += 2) {
      ivec3 q = ijk;
      q[axis] += side;
      if (q[axis] < 0 || q[axis] >= n[axis]) continue;
      float neighbour = SDF_UNREPAIRED(uint(q.x) + P.res.x * (uint(q.y) + P.res.y * uint(q.z)));
      inside += neighbour < 0.0 ? 1 : 0;
      ++votes;
    }
  }
  // Ties keep the node's own sign.
  bool negative = 2 * inside == votes ? value < 0.0 : 2 * inside > votes;
  return negative ? -abs(value) : abs(value);
}
