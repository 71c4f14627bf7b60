// The benchmark's grasp scenes (issue 26): objects among other objects, as an app registers them.
//
// A scene is a few solids at fixed places in a world frame: graspable objects and scene geometry
// (a table top, a wall) that hands stop on and never take. One object is the one the benchmark's
// hands reach for (its surface is where the placements are drawn); the others are there to be
// touched by mistake: the table under it, a second mug beside it, the mug a spoon stands in, the
// wall behind a mug's handle. Scene geometry is an analytic box (the engine gets it as a shape
// target) with the same box as a mesh for the graders and the physics colliders.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "base/pose.h"
#include "mesh/mesh.h"
#include "scene/analytic_shape.h"

namespace sdfg {

struct SceneObject {
  std::string name;
  TriangleMesh mesh;                   // in the object's frame
  std::optional<AnalyticShape> shape;  // scene geometry: the same solid as `mesh`, analytic
  Pose worldFromObject;
  bool graspable = true;  // else scene geometry (TargetRole::scene)
};

struct BenchScene {
  std::string name;
  std::string description;  // one line, for the report
  std::vector<SceneObject> objects;
  size_t reachedFor = 0;  // the object the placements are drawn on (graspable)
};

// The table top every scene stands on: a box 50 x 4 x 50 cm whose top face is the world's y = 0.
SceneObject makeTable();

// `mesh` (any size and place) scaled to the benchmark's object size (kBenchObjectDiagonal) and
// resting on the table: its lowest point on the table top, centred over it. Name "<name>/table".
BenchScene tableScene(const std::string& name, const TriangleMesh& mesh);

// `mesh` alone, scaled to the benchmark's object size and centred on the world's origin, as the
// single-object benchmark places it (eval/quality.h): a scene's figures on it are the
// single-object figures. Name "<name>/alone".
BenchScene aloneScene(const std::string& name, const TriangleMesh& mesh);

// The scenes of objects among objects, all of them at real size on the table:
//  - "mug-beside-mug": two mugs 5 mm apart (the second turned so its handle points away), both
//    graspable, the hand reaching for the first; "mug-near-mug": the same 1 cm apart;
//  - "ruler-on-table": a ruler (15 x 3 cm, 3 mm thick) lying flat, graspable;
//  - "spoon-in-mug": a spoon (makeSpoon) standing slanted in a mug, touching neither, both
//    graspable, the hand reaching for the spoon (only its handle, above the rim, has room);
//  - "mug-handle-wall": a mug whose handle ends 1.5 cm from a wall (scene geometry, 2 cm thick).
std::vector<BenchScene> objectScenes();

// Every embedded object (shapes.h) on the table, then objectScenes().
std::vector<BenchScene> embeddedScenes();

}  // namespace sdfg
