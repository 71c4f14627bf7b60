// The demo's table scene (issue 26): a table top (an analytic box that hands only stop on), a mug,
// a block and a comb on it, grasped one after the other by a GraspSession in this process
// (the engine the layer runs, with the "ours" strategy): the right hand is placed on each object
// and squeezes, the fingers close on everything in the grab box, and the session says which
// object the grasp took. The picture shows the whole scene with every grasp and each grasp close
// up; the report says what each grasp took, what each finger touches and how deep the hand is in
// the table.
#pragma once

#include <string>
#include <vector>

#include "renderer.h"
#include "report.h"

namespace sdfg::demo {

struct TableSceneOptions {
  uint32_t width = 640;  // of each of the picture's panels (the scene, then one per grasp)
  uint32_t supersample = 2;
  std::string outDir;
  std::string png = "table-scene.png";
};

// Runs the grasps, renders the picture (4 panels of width square, 4 px apart) into outDir/png and
// fills `report`. False with `error` when the session refused the scene or rendering or writing
// failed; a grasp that was not shown in time is a row with ok false, not an error.
bool runTableScene(Renderer& renderer, const TableSceneOptions& options, SceneReport& report,
                   std::string& error);

}  // namespace sdfg::demo
