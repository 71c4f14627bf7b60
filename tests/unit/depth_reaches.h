// The truth and the reaches of the depth scene's grasp tests: the mug and the table of MugOnTable
// as exact distance queries in the world, and the benchmark's placements on the mug
// (eval/placements.h: the palm facing a surface point 1 to 4 cm off it) whose open hand is clear
// of the table and whose surface point the head sees (turned toward it): the reaches a user makes
// for what is in view, from above, the side or into the cup.
#pragma once

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

}  // namespace sdfg::depth_test
