#include "run_scenes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#if SDFG_BENCH_HAVE_VULKAN
#include "eval/buffer_scene.h"
#endif

namespace sdfg::bench {

namespace {

SceneRun sceneRun(const Options& o, const GridBox& box, unsigned threads) {
  SceneRun run;
  run.placements = o.placements;
  run.seed = o.seed;
  run.threads = threads;
  run.options.da = o.da;
  run.options.clearance = o.clearHand;
  run.exactCheck = o.exactCheck;
  run.box = box;
  return run;
}

std::string objectList(const BenchScene& scene) {
  std::string objects;
  for (const SceneObject& obj : scene.objects) {
    if (!objects.empty()) objects += ", ";
    objects += obj.name + (obj.graspable ? " (graspable)" : " (scene)");
  }
  return objects;
}

// One scene's row of `run` (named `method`), or nothing with the reason on stderr.
void addRow(const BenchScene& scene, const SceneRun& run, const std::string& method,
            std::vector<SceneRow>& rows, bool& failed) {
  const auto t0 = std::chrono::steady_clock::now();
  const Result<SceneFigures> figures = measureScene(scene, run);
  if (!figures) {
    std::fprintf(stderr, "autograsp-bench: scene %s, %s: %s\n", scene.name.c_str(), method.c_str(),
                 figures.error().message.c_str());
    failed = true;
    return;
  }
  std::fprintf(stderr, "scene %s, %s: %d grasps in %.1f s\n", scene.name.c_str(), method.c_str(),
               figures->grasps,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  rows.push_back(SceneRow{scene.name, scene.description, objectList(scene), method, *figures});
}

}  // namespace

std::vector<SceneRow> runBufferScenes(const std::vector<BenchScene>& scenes, const Options& o,
                                      const GridBox& box, unsigned threads, bool& failed,
                                      bool& available) {
  std::vector<SceneRow> rows;
#if SDFG_BENCH_HAVE_VULKAN
  auto solver = BufferSceneSolver::create();
  available = solver.ok();
  if (!solver) {
    std::fprintf(stderr, "autograsp-bench: buffer targets: %s; their rows are left out\n",
                 solver.error().message.c_str());
    return rows;
  }
  std::fprintf(stderr, "autograsp-bench: buffer targets on %s\n", (*solver)->deviceName().c_str());
  SceneRun run = sceneRun(o, box, threads);
  run.solves = (*solver)->solves(run);
  for (const BenchScene& scene : scenes) addRow(scene, run, "ours/buffers", rows, failed);
#else
  (void)scenes, (void)o, (void)box, (void)threads, (void)failed;
  available = false;
  std::fprintf(stderr, "autograsp-bench: buffer targets: built without Vulkan\n");
#endif
  return rows;
}

std::vector<SceneRow> runScenes(const std::vector<BenchScene>& scenes, const Options& o,
                                const GridBox& box, unsigned threads, bool& failed) {
  SceneRun run = sceneRun(o, box, threads);
  std::vector<SceneRow> rows;
  for (const BenchScene& scene : scenes) {
    for (const std::string& method : o.methods) {
      run.method = method;
      addRow(scene, run, method, rows, failed);
    }
  }
  return rows;
}

void printSceneTable(const std::vector<SceneRow>& rows, const char* title) {
  std::printf("\n%s\n", title != nullptr
                            ? title
                            : "Scenes: the whole hand inside objects it does not hold (mm, per "
                              "grasp's deepest), grasps that took another graspable object than "
                              "the one the palm faces, and the single-object figures on the "
                              "object held");
  int width = 20;
  for (const SceneRow& r : rows) width = std::max(width, int(r.scene.size()));
  std::printf("%-*s %-15s %7s %9s %9s %11s %8s %9s %9s %9s %6s %5s\n", width, "scene", "method",
              "grasps", "other p99", "other max", "wrong/face", "nothing", "contacts", "resid p95",
              "pen max", "early", "thru");
  for (const SceneRow& r : rows) {
    const SceneFigures& f = r.figures;
    const std::string wrong =
        std::to_string(f.wrongObject) + "/" + std::to_string(f.facingGraspable);
    std::printf("%-*s %-15s %7d %9.3f %9.3f %11s %8d %9.3f %9.4f %9.3f %6d %5d\n", width,
                r.scene.c_str(), r.method.c_str(), f.grasps, f.otherPenetrationP99Mm,
                f.otherPenetrationMaxMm, wrong.c_str(), f.heldNothing, f.held.contactsPerGrasp,
                f.held.contactResidualP95Mm, f.held.penetrationMaxMm, f.held.earlyStops,
                f.held.passThroughs);
  }
}

tools::Json scenesJson(const std::vector<SceneRow>& rows) {
  using tools::Json;
  using tools::jsonNumber;
  Json out = Json::array();
  for (const SceneRow& r : rows) {
    const SceneFigures& f = r.figures;
    Json row;
    row["scene"] = r.scene;
    row["description"] = r.description;
    row["objects"] = r.objects;
    row["method"] = r.method;
    row["grasps"] = f.grasps;
    row["other_penetration_mm"] = {{"p99", jsonNumber(f.otherPenetrationP99Mm)},
                                   {"max", jsonNumber(f.otherPenetrationMaxMm)}};
    row["other_penetrating_grasps"] = f.otherPenetrating;
    row["deepest_placement"] = f.deepestPlacement;
    row["deepest_object"] = f.deepestObject;
    row["facing_graspable"] = f.facingGraspable;
    row["wrong_object"] = f.wrongObject;
    row["held_nothing"] = f.heldNothing;
    row["wrong_fingers_on_taken"] = f.wrongFingersOnTaken;
    row["wrong_fingers_on_faced"] = f.wrongFingersOnFaced;
    row["wrong_with_finger_on_faced"] = f.wrongWithFingerOnFaced;
    row["contacts_mean"] = jsonNumber(f.held.contactsPerGrasp);
    row["fingers_in_contact"] = f.held.fingersInContact;
    // NaN-free: no finger in contact reads as null.
    const bool any = f.held.fingersInContact > 0;
    row["contact_residual_mm"] = {
        {"median", any ? jsonNumber(f.held.contactResidualMedianMm) : Json()},
        {"p95", any ? jsonNumber(f.held.contactResidualP95Mm) : Json()}};
    row["penetration_mm"] = {{"p99", jsonNumber(f.held.penetrationP99Mm)},
                             {"max", jsonNumber(f.held.penetrationMaxMm)}};
    row["early_stops"] = f.held.earlyStops;
    row["pass_through"] = f.held.passThroughs;
    // "ours": the version 1 contacts on the object taken against its exact distance.
    row["v1_contacts"] = f.v1Contacts;
    row["v1_residual_max_mm"] = jsonNumber(f.v1ResidualMaxMm);
    out.push_back(std::move(row));
  }
  return out;
}

}  // namespace sdfg::bench
