// The truth and the reaches of the depth scene's grasp tests: the mug and the table of MugOnTable
// as exact distance queries in the world, and the benchmark's placements on the mug
// (eval/placements.h: the palm facing a surface point 1 to 4 cm off it) whose open hand is clear
// of the table and whose surface point the head sees (turned toward it): the reaches a user makes
// for what is in view, from above, the side or into the cup.
#pragma once

#include <algorithm>
#include <array>
#include <memory>
#include <vector>

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include "depth_render.h"
#include "eval/evaluator.h"
#include "eval/placements.h"

namespace sdfg::depth_test {

struct MugTruth {
  TriangleMesh worldMug;
  std::unique_ptr<ExactMeshQuery> mug, table;
};

inline MugTruth mugTruth(const MugOnTable& scene) {
  MugTruth t;
  t.worldMug = scene.mug;
  transformMesh(t.worldMug, scene.worldFromMug);
  auto mug = ExactMeshQuery::create(t.worldMug);
  REQUIRE(mug.ok());
  t.mug = std::move(*mug);
  TriangleMesh worldTable = scene.table;
  transformMesh(worldTable, scene.worldFromTable);
  auto table = ExactMeshQuery::create(worldTable);
  REQUIRE(table.ok());
  t.table = std::move(*table);
  return t;
}

// The first `count` such reaches, seen from `view` (seed 1).
inline std::vector<Placement> seenReaches(const MugTruth& truth, const DepthView& view,
                                          const HandModel& hand, const GridBox& box, int count) {
  const glm::vec3 eye = view.worldFromView.position;
  std::vector<Placement> out;
  for (const Placement& pl : generatePlacements(
           truth.worldMug, *truth.mug, hand, box, 4 * count, 1, [&](const Pose& worldFromHand) {
             return openHandIntersects(*truth.table, hand, worldFromHand);
           })) {
    if (glm::dot(pl.normal, glm::normalize(eye - pl.surfacePoint)) > 0.2f &&
        out.size() < size_t(count))
      out.push_back(pl);
  }
  REQUIRE(out.size() == size_t(count));
  return out;
}

// A grasp against the true surfaces: each finger's gap to the nearer of the mug and the table
// (mm, negative inside), how many fingers touch one (within kTouchingMm), and the deepest any
// finger entered either.
struct TrueGrade {
  std::array<float, kFingerCount> clearanceMm{};
  int touching = 0;
  float deepestMm = 0.0f;
};

inline TrueGrade gradeOnTruth(const MugTruth& truth, const HandModel& hand,
                              const Pose& worldFromHand, const GraspResult& result) {
  const GraspMetrics onMug = evaluateGrasp(*truth.mug, hand, worldFromHand, result);
  const GraspMetrics onTable = evaluateGrasp(*truth.table, hand, worldFromHand, result);
  TrueGrade g;
  for (int f = 0; f < kFingerCount; ++f) {
    const FingerMetrics& m = onMug.fingers[size_t(f)];
    const FingerMetrics& t = onTable.fingers[size_t(f)];
    g.clearanceMm[size_t(f)] = std::min(m.clearanceMm, t.clearanceMm);
    g.deepestMm = std::max({g.deepestMm, m.penetrationMm, t.penetrationMm});
    if (g.clearanceMm[size_t(f)] <= kTouchingMm) ++g.touching;
  }
  return g;
}

// The q-quantile of `v` (its element at q of the way through, sorted); 0 when empty.
inline float quantile(std::vector<float> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0f : v[size_t(q * double(v.size() - 1))];
}

}  // namespace sdfg::depth_test
