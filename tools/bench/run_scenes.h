// autograsp-bench --scenes: every method in the scenes of eval/scenes.h (each test mesh on a table,
// two mugs side by side, a spoon in a mug, a mug's handle near a wall), measured by
// eval/scene_quality.h, printed as a table and written into the results JSON ("scenes").
#pragma once

#include <string>
#include <vector>

#include "bench_options.h"
#include "eval/scene_quality.h"
#include "eval/scenes.h"
#include "json_file.h"

namespace sdfg::bench {

struct SceneRow {
  std::string scene;
  std::string description;
  std::string objects;  // "mug (graspable), table (scene)"
  std::string method;
  SceneFigures figures;
};

// Every method of `o` in every scene, on the grab box `box`; a scene or method that fails is
// reported on stderr and sets `failed`, the others still run.
std::vector<SceneRow> runScenes(const std::vector<BenchScene>& scenes, const Options& o,
                                const GridBox& box, unsigned threads, bool& failed);

// With --sdf-backend vulkan: "ours" in every scene of `scenes` through a GraspSession whose
// meshes are buffer targets in a Vulkan device's buffers (eval/buffer_scene.h), method
// "ours/buffers". `available` is false (and nothing runs) where the tools have no Vulkan or no
// device could be made (the reason on stderr); a scene that fails sets `failed`.
std::vector<SceneRow> runBufferScenes(const std::vector<BenchScene>& scenes, const Options& o,
                                      const GridBox& box, unsigned threads, bool& failed,
                                      bool& available);

// `title` heads the table (default: the scenes').
void printSceneTable(const std::vector<SceneRow>& rows, const char* title = nullptr);

// The rows as the JSON's "scenes" array (one object per scene and method).
tools::Json scenesJson(const std::vector<SceneRow>& rows);

}  // namespace sdfg::bench
