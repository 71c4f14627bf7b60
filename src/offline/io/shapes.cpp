#include "io/shapes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

namespace sdfg {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// Appends the quad a-b-c-d (counter-clockwise seen from outside) as two triangles.
void addQuad(std::vector<uint32_t>& indices, uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  indices.insert(indices.end(), {a, b, c, a, c, d});
}

// Removes vertices no triangle uses (the mug's wall keeps a grid vertex in each handle hole),
// keeping the order of the rest.
void dropUnusedVertices(TriangleMesh& mesh) {
  std::vector<uint32_t> remap(mesh.positions.size(), UINT32_MAX);
  for (uint32_t v : mesh.indices) remap[v] = 0;
  std::vector<glm::vec3> kept;
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    if (remap[v] == UINT32_MAX) continue;
    remap[v] = static_cast<uint32_t>(kept.size());
    kept.push_back(mesh.positions[v]);
  }
  for (uint32_t& v : mesh.indices) v = remap[v];
  mesh.positions = std::move(kept);
}

// ---------------------------------------------------------------------------------------------
// The mug. Axis Y, bottom at y = -height/2, handle on +X in the XY plane.

constexpr int kMugSegments = 40;     // around the axis; 9 degrees each
constexpr float kMugRadius = 0.04f;  // outer
constexpr float kMugHeight = 0.095f;
constexpr float kMugWall = 0.005f;
constexpr float kMugBottom = 0.006f;       // thickness of the floor
constexpr float kHandleAttachY = 0.025f;   // handle joins the wall at y = +-this
constexpr float kHoleHalfHeight = 0.006f;  // half height of each hole cut in the wall
constexpr float kHandleGap = 0.004f;       // tube ends stop this far outside the wall
constexpr float kHandleReach = 0.025f;     // how far the handle's centre line bulges beyond that
constexpr float kHandleHalfThickness = 0.0045f;  // tube cross-section, in the XY plane
constexpr float kHandleHalfWidth = 0.0055f;      // tube cross-section, along Z
constexpr int kHandleSegments = 24;              // along the tube
constexpr int kTubeSides = 8;  // must match the 8 boundary vertices of a 2 x 2-quad hole

}  // namespace

TriangleMesh makeMug() {
  // The cup is a surface of revolution of this profile, from the outer bottom's centre round to
  // the inner floor's centre; both ends are poles. Rows 2-4 and 5-7 are the wall rows framing the
  // two handle holes. The profile direction and the angle direction (from +X towards +Z) make
  // the quads below face outwards.
  const float bottom = -0.5f * kMugHeight, top = 0.5f * kMugHeight;
  const float inner = kMugRadius - kMugWall;
  const float lowY = -kHandleAttachY, highY = kHandleAttachY, dh = kHoleHalfHeight;
  const std::array<glm::vec2, 12> profile = {{
      {0.0f, bottom},                // 0: pole, outer bottom
      {kMugRadius, bottom},          // 1
      {kMugRadius, lowY - dh},       // 2: lower hole
      {kMugRadius, lowY},            // 3
      {kMugRadius, lowY + dh},       // 4
      {kMugRadius, highY - dh},      // 5: upper hole
      {kMugRadius, highY},           // 6
      {kMugRadius, highY + dh},      // 7
      {kMugRadius, top},             // 8: rim, outer edge
      {inner, top},                  // 9: rim, inner edge
      {inner, bottom + kMugBottom},  // 10
      {0.0f, bottom + kMugBottom},   // 11: pole, inner floor
  }};
  constexpr int kRows = static_cast<int>(profile.size());
  constexpr int kLowHoleRow = 3, kHighHoleRow = 6;

  TriangleMesh mesh;
  // Vertex of profile row k at angle step j; the poles are one vertex each.
  std::vector<uint32_t> ids(kRows * kMugSegments);
  auto at = [&ids](int k, int j) {
    return ids[k * kMugSegments + ((j % kMugSegments) + kMugSegments) % kMugSegments];
  };
  for (int k = 0; k < kRows; ++k) {
    const bool pole = profile[k].x == 0.0f;
    for (int j = 0; j < kMugSegments; ++j) {
      if (pole && j > 0) {
        ids[k * kMugSegments + j] = ids[k * kMugSegments];
        continue;
      }
      const float angle = 2.0f * kPi * float(j) / kMugSegments;
      ids[k * kMugSegments + j] = static_cast<uint32_t>(mesh.positions.size());
      mesh.positions.emplace_back(profile[k].x * std::cos(angle), profile[k].y,
                                  profile[k].x * std::sin(angle));
    }
  }
  auto inHole = [](int k, int j) {
    const bool column = j == kMugSegments - 1 || j == 0;  // the two quads either side of +X
    return column &&
           (k == kLowHoleRow - 1 || k == kLowHoleRow || k == kHighHoleRow - 1 || k == kHighHoleRow);
  };
  for (int k = 0; k + 1 < kRows; ++k) {
    for (int j = 0; j < kMugSegments; ++j) {
      if (inHole(k, j)) continue;
      const uint32_t a = at(k, j), b = at(k + 1, j), c = at(k + 1, j + 1), d = at(k, j + 1);
      if (k == 0) {
        mesh.indices.insert(mesh.indices.end(), {a, b, c});  // a == d: the outer pole
      } else if (k + 1 == kRows - 1) {
        mesh.indices.insert(mesh.indices.end(), {a, b, d});  // b == c: the inner pole
      } else {
        addQuad(mesh.indices, a, b, c, d);
      }
    }
  }

  // The handle: a tube along half an ellipse in the XY plane from the upper hole round to the
  // lower one. Ring frame: tangent T, binormal B = +Z, normal N = B x T (outwards from the
  // ellipse's centre); ring vertex m sits at angle 45 degrees * m from N towards B, so rings run
  // in the positive sense about T and the quads between rings face outwards.
  const glm::vec3 centre(kMugRadius + kHandleGap, 0.5f * (lowY + highY), 0.0f);
  const float reachY = 0.5f * (highY - lowY);
  const glm::vec3 binormal(0.0f, 0.0f, 1.0f);
  std::vector<uint32_t> rings;  // (kHandleSegments + 1) * kTubeSides vertex ids
  for (int i = 0; i <= kHandleSegments; ++i) {
    const float theta = 0.5f * kPi - kPi * float(i) / kHandleSegments;
    const glm::vec3 point =
        centre + glm::vec3(kHandleReach * std::cos(theta), reachY * std::sin(theta), 0.0f);
    const glm::vec3 tangent =
        glm::normalize(glm::vec3(kHandleReach * std::sin(theta), -reachY * std::cos(theta), 0.0f));
    const glm::vec3 normal = glm::cross(binormal, tangent);
    for (int m = 0; m < kTubeSides; ++m) {
      const float phi = 2.0f * kPi * float(m) / kTubeSides;
      rings.push_back(static_cast<uint32_t>(mesh.positions.size()));
      mesh.positions.push_back(point + normal * (kHandleHalfThickness * std::cos(phi)) +
                               binormal * (kHandleHalfWidth * std::sin(phi)));
    }
  }
  auto ring = [&rings](int i, int m) { return rings[i * kTubeSides + (m % kTubeSides)]; };
  for (int i = 0; i < kHandleSegments; ++i) {
    for (int m = 0; m < kTubeSides; ++m) {
      addQuad(mesh.indices, ring(i, m), ring(i, m + 1), ring(i + 1, m + 1), ring(i + 1, m));
    }
  }

  // Join each tube end to its hole. Hole vertex m is the wall vertex in the direction of tube
  // vertex m: one row up or down along N (+Y at the upper end, -Y at the lower one) and one
  // angle step along B (+Z). Both rings then turn the same way about T, and a band of quads
  // joins them using each edge opposite to the way the wall or the tube uses it.
  const std::array<glm::ivec2, kTubeSides> direction = {
      {{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1}}};  // (along N, B)
  for (int m = 0; m < kTubeSides; ++m) {
    const int n = (m + 1) % kTubeSides;
    const uint32_t upperM = at(kHighHoleRow + direction[m].x, direction[m].y);
    const uint32_t upperN = at(kHighHoleRow + direction[n].x, direction[n].y);
    addQuad(mesh.indices, ring(0, n), ring(0, m), upperM, upperN);
    const uint32_t lowerM = at(kLowHoleRow - direction[m].x, direction[m].y);
    const uint32_t lowerN = at(kLowHoleRow - direction[n].x, direction[n].y);
    addQuad(mesh.indices, ring(kHandleSegments, m), ring(kHandleSegments, n), lowerN, lowerM);
  }
  dropUnusedVertices(mesh);
  return mesh;
}

TriangleMesh makeTorus(float major, float minor, int ringSegments, int tubeSegments) {
  ringSegments = std::max(ringSegments, 3);
  tubeSegments = std::max(tubeSegments, 3);
  TriangleMesh mesh;
  mesh.positions.reserve(size_t(ringSegments) * size_t(tubeSegments));
  for (int i = 0; i < ringSegments; ++i) {
    const float theta = 2.0f * kPi * float(i) / float(ringSegments);
    for (int j = 0; j < tubeSegments; ++j) {
      const float phi = 2.0f * kPi * float(j) / float(tubeSegments);
      const float r = major + minor * std::cos(phi);
      mesh.positions.emplace_back(r * std::cos(theta), minor * std::sin(phi), r * std::sin(theta));
    }
  }
  auto id = [=](int i, int j) {
    return static_cast<uint32_t>((i % ringSegments) * tubeSegments + (j % tubeSegments));
  };
  // Stepping j turns about the tube (towards +Y at the outer equator), stepping i goes round the
  // ring (towards +Z at +X): j then i is counter-clockwise seen from outside.
  for (int i = 0; i < ringSegments; ++i) {
    for (int j = 0; j < tubeSegments; ++j) {
      addQuad(mesh.indices, id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j));
    }
  }
  return mesh;
}

TriangleMesh makeThinPlate(float width, float depth, float thickness) {
  return makeBox(glm::vec3(width, thickness, depth));
}

TriangleMesh makeBox(const glm::vec3& extent) {
  TriangleMesh mesh;
  // Corner c has bit k set when it is on the + side along axis k.
  for (uint32_t c = 0; c < 8; ++c) {
    mesh.positions.emplace_back((c & 1 ? 0.5f : -0.5f) * extent.x,
                                (c & 2 ? 0.5f : -0.5f) * extent.y,
                                (c & 4 ? 0.5f : -0.5f) * extent.z);
  }
  for (int axis = 0; axis < 3; ++axis) {
    // Going round (0,0) (1,0) (1,1) (0,1) in the (u, v) axes that follow `axis` cyclically turns
    // positively about `axis`: counter-clockwise seen from the + side.
    const uint32_t a = 1u << axis, u = 1u << ((axis + 1) % 3), v = 1u << ((axis + 2) % 3);
    addQuad(mesh.indices, a, a | u, a | u | v, a | v);
    addQuad(mesh.indices, 0, v, u | v, u);  // the - side, reversed
  }
  return mesh;
}

TriangleMesh makeSphere(float radius, int subdivisions) {
  subdivisions = std::clamp(subdivisions, 0, 7);  // 7: 327,680 triangles
  const float g = 0.5f * (1.0f + std::sqrt(5.0f));
  TriangleMesh mesh;
  mesh.positions = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                    {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
  mesh.indices = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                  4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                  6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
  for (glm::vec3& p : mesh.positions) p = glm::normalize(p);
  // Outward by construction for a convex solid around the origin: make sure of it per face.
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    const glm::vec3 a = mesh.positions[mesh.indices[3 * t]];
    const glm::vec3 b = mesh.positions[mesh.indices[3 * t + 1]];
    const glm::vec3 c = mesh.positions[mesh.indices[3 * t + 2]];
    if (glm::dot(glm::cross(b - a, c - a), a + b + c) < 0.0f) {
      std::swap(mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]);
    }
  }
  for (int level = 0; level < subdivisions; ++level) {
    // Each edge's midpoint is made once and shared by both triangles on that edge.
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
    auto midpoint = [&mesh, &midpoints](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto [it, inserted] =
          midpoints.try_emplace(key, static_cast<uint32_t>(mesh.positions.size()));
      if (inserted) {
        mesh.positions.push_back(glm::normalize(mesh.positions[a] + mesh.positions[b]));
      }
      return it->second;
    };
    std::vector<uint32_t> finer;
    finer.reserve(mesh.indices.size() * 4);
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
      const uint32_t a = mesh.indices[3 * t], b = mesh.indices[3 * t + 1],
                     c = mesh.indices[3 * t + 2];
      const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      finer.insert(finer.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
    }
    mesh.indices = std::move(finer);
  }
  for (glm::vec3& p : mesh.positions) p *= radius;
  return mesh;
}

TriangleMesh makeSpoon(float length) {
  constexpr int kRings = 60;         // cross-sections between the two poles
  constexpr int kSides = 16;         // vertices per cross-section
  constexpr float kBowlEnd = 0.36f;  // fraction of the length the bowl takes
  // Half width and half thickness at fraction s of the length: the larger of the bowl's swell
  // and the handle's constant section, the handle rounded off over its last tenth.
  auto section = [](float s) {
    const float bowl =
        s < kBowlEnd ? std::sqrt(std::max(0.0f, std::sin(kPi * s / kBowlEnd))) : 0.0f;
    const float end =
        s > 0.9f ? std::sqrt(std::max(0.0f, 1.0f - ((s - 0.9f) / 0.1f) * ((s - 0.9f) / 0.1f)))
                 : 1.0f;
    return glm::vec2(std::max(0.017f * bowl, 0.0055f * end),
                     std::max(0.005f * bowl, 0.0022f * end));
  };
  TriangleMesh mesh;
  mesh.positions.emplace_back(0.0f, 0.0f, 0.0f);  // pole at the bowl's tip
  for (int i = 1; i <= kRings; ++i) {
    const float s = float(i) / float(kRings + 1);
    const glm::vec2 half = section(s);
    for (int j = 0; j < kSides; ++j) {
      const float phi = 2.0f * kPi * float(j) / float(kSides);
      mesh.positions.emplace_back(s * length, half.y * std::sin(phi), half.x * std::cos(phi));
    }
  }
  const uint32_t tip = 0, end = uint32_t(mesh.positions.size());
  mesh.positions.emplace_back(length, 0.0f, 0.0f);  // pole at the handle's end
  auto id = [](int ring, int side) { return uint32_t(1 + (ring - 1) * kSides + side % kSides); };
  // Stepping j turns from +Z towards +Y and stepping the ring goes along +X, so (ring, j) ->
  // (ring + 1, j) -> (ring + 1, j + 1) is counter-clockwise seen from outside.
  for (int j = 0; j < kSides; ++j) {
    mesh.indices.insert(mesh.indices.end(), {tip, id(1, j), id(1, j + 1)});
    for (int i = 1; i < kRings; ++i) {
      addQuad(mesh.indices, id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
    }
    mesh.indices.insert(mesh.indices.end(), {end, id(kRings, j + 1), id(kRings, j)});
  }
  return mesh;
}

std::vector<NamedMesh> embeddedObjects() {
  std::vector<NamedMesh> objects;
  objects.push_back({"mug", makeMug()});
  objects.push_back({"torus", makeTorus()});
  objects.push_back({"thin-plate", makeThinPlate()});
  return objects;
}

}  // namespace sdfg
