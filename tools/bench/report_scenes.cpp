// The report's scenes section (autograsp-bench --scenes): one table per run, rows by scene and
// method, read from the JSON's "scenes" array as the rest of the report is.
#include <sstream>

#include "report_detail.h"

namespace sdfg::bench {

std::string scenesSection(const Json& results) {
  const Json* scenes = member(results, "scenes");
  if (!scenes || !scenes->is_array() || scenes->empty()) return {};
  std::ostringstream md;
  md << "## Scenes\n\n"
     << "Every method with other objects around the one the hand reaches for (`--scenes`; "
        "`src/offline/eval/scenes.h`, measured by `src/offline/eval/scene_quality.h`). "
        "`other p99`, `other max`: the whole hand's deepest point inside an object it does not "
        "hold, per grasp, mm. `wrong / facing`: grasps that took another graspable object than "
        "the one the palm faces, of the grasps whose palm faces a graspable object; `nothing`: of "
        "those, the hand took nothing. The rest are the single-object figures on the object held "
        "(else the one reached for).\n\n"
     << "| scene | method | grasps | other p99 | other max | wrong / facing | nothing | "
        "contacts | residual median | residual p95 | penetration max | early stops | pass "
        "through |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::string lastScene;
  for (const Json& row : *scenes) {
    const std::string scene = stringOf(member(row, "scene"));
    md << "| " << (scene == lastScene ? std::string() : "`" + scene + "`") << " | "
       << stringOf(member(row, "method")) << " | " << fmt(numberOf(member(row, "grasps"))) << " | "
       << fmt(numberAt(row, "other_penetration_mm", "p99")) << " | "
       << fmt(numberAt(row, "other_penetration_mm", "max")) << " | "
       << fmt(numberOf(member(row, "wrong_object"))) << " / "
       << fmt(numberOf(member(row, "facing_graspable"))) << " | "
       << fmt(numberOf(member(row, "held_nothing"))) << " | "
       << fmt(numberOf(member(row, "contacts_mean"))) << " | "
       << fmt(numberAt(row, "contact_residual_mm", "median")) << " | "
       << fmt(numberAt(row, "contact_residual_mm", "p95")) << " | "
       << fmt(numberAt(row, "penetration_mm", "max")) << " | "
       << fmt(numberOf(member(row, "early_stops"))) << " | "
       << fmt(numberOf(member(row, "pass_through"))) << " |\n";
    lastScene = scene;
  }
  md << "\nThe scenes:\n\n";
  lastScene.clear();
  for (const Json& row : *scenes) {
    const std::string scene = stringOf(member(row, "scene"));
    if (scene == lastScene) continue;
    md << "- `" << scene << "`: " << stringOf(member(row, "description")) << " ("
       << stringOf(member(row, "objects")) << ")\n";
    lastScene = scene;
  }
  md << "\n";
  return md.str();
}

}  // namespace sdfg::bench
