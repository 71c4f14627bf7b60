// Procedural objects generated in code: the embedded defaults of the demo and benchmark, and
// analytic shapes for tests. No data files. All meshes are closed (watertight) with outward,
// counter-clockwise faces, in metres, centred near the origin.
#pragma once

#include <string>
#include <vector>

#include "mesh/mesh.h"

namespace sdfg {

// A mug with a handle: a cup (concave: an open cavity) and a handle that leaves a through-hole
// between it and the wall; one closed genus-1 surface. About 8 cm across and 9.5 cm tall.
// Axis Y, centred on the origin: the cup has outer diameter 8 cm, height 9.5 cm, walls 5 mm and
// a 6 mm floor; the handle is a tube (9 x 11 mm) on +X in the XY plane, joined into the wall at
// y = +-2.5 cm, reaching x = 7.35 cm. Bounding box x [-0.04, 0.0735], y [-0.0475, 0.0475],
// z [-0.04, 0.04]. The through-hole is centred near (0.052, 0, 0).
TriangleMesh makeMug();

// A torus in the XZ plane (axis Y): ring radius `major`, tube radius `minor` (< major).
// Segment counts below 3 are raised to 3.
TriangleMesh makeTorus(float major = 0.05f, float minor = 0.015f, int ringSegments = 48,
                       int tubeSegments = 24);

// A thin rectangular plate (a box) centred at the origin, thickness along Y.
TriangleMesh makeThinPlate(float width = 0.14f, float depth = 0.10f, float thickness = 0.004f);

// An axis-aligned box centred at the origin with the given full extents (each > 0; a zero
// extent gives zero-area triangles that validateMesh rejects).
TriangleMesh makeBox(const glm::vec3& extent);

// A sphere (subdivided icosahedron, vertices on the sphere) centred at the origin:
// 20 * 4^subdivisions triangles; subdivisions is clamped to [0, 7].
TriangleMesh makeSphere(float radius, int subdivisions = 3);

// A spoon: one closed genus-0 loft along +X, from the bowl's tip at x = 0 to the handle's end at
// x = `length`. The cross-sections are ellipses (width along Z, thickness along Y): a bowl 3.4 cm
// wide and 1 cm thick over the first 36 % of the length, narrowing to a handle 1.1 cm wide and
// 4.4 mm thick. The bowl is solid (no cavity): the benchmark's scenes need a long, thin graspable
// part beside another object, not the hollow of the bowl.
TriangleMesh makeSpoon(float length = 0.15f);

struct NamedMesh {
  std::string name;
  TriangleMesh mesh;
};

// The embedded default objects: mug, torus, thin plate.
std::vector<NamedMesh> embeddedObjects();

}  // namespace sdfg
