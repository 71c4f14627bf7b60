#include "depth_quality.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include <glm/geometric.hpp>

#include "depth/depth_fusion.h"
#include "eval/depth_render.h"
#include "eval/evaluator.h"
#include "eval/placements.h"
#include "grasp/scene_exact_source.h"
#include "scene/scene_field.h"

namespace sdfg {
namespace {

// The q-quantile of `v` (its element at q of the way through, sorted); 0 when empty.
float quantile(std::vector<float> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0f : v[size_t(q * double(v.size() - 1))];
}

struct WorldSolid {
  TriangleMesh mesh;  // in the world
  std::unique_ptr<ExactMeshQuery> query;
};

Result<WorldSolid> worldSolid(const SceneObject& o) {
  WorldSolid s;
  s.mesh = o.mesh;
  transformMesh(s.mesh, o.worldFromObject);
  auto q = ExactMeshQuery::create(s.mesh);
  if (!q) return q.error();
  s.query = std::move(*q);
  return s;
}

}  // namespace

Status solveOnDepth(const DepthView& view, std::span<const float> stored, const Pose& worldFromHand,
                    const GridBox& box, GraspSolver& solver, SdfBackend& backend,
                    GraspResult& out) {
  auto made = DepthFusion::create(DepthFusionOptions{});
  if (!made) return made.error().code;
  DepthFusion fusion = std::move(*made);
  fusion.recentre(worldFromHand.transformPoint(box.handFromBox.position));
  // One frame: the scene and the view hold still, so more frames average the same values.
  if (Status s = fusion.integrate(view, stored, {}, 0.0); s != Status::ok) return s;
  fusion.finishFrame(0.0);
  SceneMember m;
  m.id = 1;
  m.volume = &fusion.volume();
  m.objectFromHand = worldFromHand;  // the volume's frame is the world
  m.graspable = true;
  SdfGrid grid(box), scratch(box);
  if (Status s = buildSceneField({&m, 1}, box, backend, grid, scratch); s != Status::ok) return s;
  const SceneExactSource exact({&m, 1});
  GraspScene gs;
  gs.field = &grid;
  gs.objectFromHand = worldFromHand;
  gs.exact = &exact;
  return solver.solve(gs, out);
}

Result<DepthQuality> depthSceneQuality(const BenchScene& scene, const HandModel& hand,
                                       const GridBox& box, GraspSolver& solver, SdfBackend& backend,
                                       const DepthQualityOptions& options) {
  if (scene.reachedFor >= scene.objects.size() || scene.objects.size() < 2)
    return makeError(Status::invalid_argument,
                     "depth quality: the scene needs the object reached for and a table");
  // The truth: every solid of the scene in the world, exactly.
  std::vector<WorldSolid> solids;
  std::vector<DepthPlaced> drawn;
  for (const SceneObject& o : scene.objects) {
    auto s = worldSolid(o);
    if (!s) return s.error();
    solids.push_back(std::move(*s));
  }
  for (const SceneObject& o : scene.objects) drawn.push_back({&o.mesh, o.worldFromObject});
  const WorldSolid& object = solids[scene.reachedFor];

  // The head: above and in front of the object's centre (its box's), 40 cm away, 42 degrees down.
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : object.mesh.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const glm::vec3 centre = 0.5f * (lo + hi);
  const glm::vec3 eye = centre + options.headDistance * glm::normalize(glm::vec3(0.0f, 0.9f, 1.0f));
  const DepthView view = depthLookAt(eye, centre, 0.05f, 100.0f);
  const std::vector<float> stored =
      storedDepthValues(view, renderDepthDistances(view, drawn), DepthStored::d24);

  // Reaches for what the head sees, the open hand clear of every other solid.
  const auto clearOfOthers = [&](const Pose& worldFromHand) {
    for (size_t i = 0; i < solids.size(); ++i)
      if (i != scene.reachedFor && openHandIntersects(*solids[i].query, hand, worldFromHand))
        return true;
    return false;
  };
  const std::vector<Placement> drawnPlacements = generatePlacements(
      object.mesh, *object.query, hand, box, 20 * options.placements, options.seed, clearOfOthers);
  struct Kind {
    const char* name;
    float minUp, maxUp;  // the normal's y
  };
  const std::array<Kind, 2> kinds{
      {{"above", std::cos(0.25f * 3.14159265f), 1.01f},
       {"side", -std::sin(0.14f * 3.14159265f), std::sin(0.14f * 3.14159265f)}}};
  DepthQuality out;
  out.scene = scene.name;
  for (const Kind& kind : kinds) {
    DepthReachFigures fig;
    fig.reach = kind.name;
    std::vector<float> penetrations, residuals;
    for (const Placement& pl : drawnPlacements) {
      if (fig.reaches >= options.placements) break;
      const glm::vec3 toEye = glm::normalize(eye - pl.surfacePoint);
      if (pl.normal.y < kind.minUp || pl.normal.y > kind.maxUp ||
          glm::dot(pl.normal, toEye) <= 0.2f)
        continue;
      ++fig.reaches;
      const Pose& worldFromHand = pl.objectFromHand;  // the object's mesh is in the world
      GraspResult result;
      if (Status st = solveOnDepth(view, stored, worldFromHand, box, solver, backend, result);
          st != Status::ok)
        return makeError(st, "depth quality: the fusion, the field's build or the solve failed");
      // Each finger against the nearest true surface.
      std::array<float, kFingerCount> gap;
      gap.fill(1e30f);
      float deepest = 0.0f;
      for (const WorldSolid& s : solids) {
        const GraspMetrics g = evaluateGrasp(*s.query, hand, worldFromHand, result);
        for (int f = 0; f < kFingerCount; ++f) {
          gap[size_t(f)] = std::min(gap[size_t(f)], g.fingers[size_t(f)].clearanceMm);
          deepest = std::max(deepest, g.fingers[size_t(f)].penetrationMm);
        }
      }
      int touching = 0;
      for (int f = 0; f < kFingerCount; ++f) {
        touching += gap[size_t(f)] <= kTouchingMm ? 1 : 0;
        if (result.fingers[size_t(f)].contact) residuals.push_back(std::abs(gap[size_t(f)]));
      }
      fig.made += touching >= 2 ? 1 : 0;
      penetrations.push_back(deepest);
    }
    fig.penetrationP99Mm = quantile(penetrations, 0.99);
    fig.penetrationMaxMm = quantile(penetrations, 1.0);
    fig.residualMedianMm = quantile(residuals, 0.5);
    fig.residualP95Mm = quantile(residuals, 0.95);
    out.reaches.push_back(fig);
  }
  return out;
}

}  // namespace sdfg
