// "ours" meets its published quality on every object it is published for: the embedded objects
// always, the research meshes of ../shared/meshes where they are present. Quality figures are
// deterministic for a seed (eval/quality.h), so these are tests, not timings: a change to the
// solver, the field, the hand model or the evaluator that worsens one fails here.
//
// Gates, the same for every object (the project's published targets): contact residual median
// <= 0.1 mm and p95 <= 0.15 mm, penetration <= 0.5 mm at every placement, early stops <= 5 per
// 1000, no finger passing through; and per object, contacts per grasp no lower than measured at
// the commit that set the gate (see kObjects). Each object is its own test case, so an absent
// research mesh is skipped before any assertion and a present one is judged. Each case prints
// its figures (a passing run's log shows them). Every object is also graded with its vertices
// split as game exporters split them (soup, flat, seams; see "Split vertices" below).
#include <catch2/catch.hpp>

#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "eval/quality.h"
#include "eval/scene_quality.h"
#include "eval/scenes.h"
#include "io/mesh_io.h"
#include "io/mesh_variants.h"
#include "io/shapes.h"
#include "quality_gates.h"
#include "test_support.h"

using namespace sdfg;
using namespace sdfg::test;

namespace {

struct Gate {
  int placements;
  // Contacts per grasp (fingers within 2 mm, eval/evaluator.h) no lower than this.
  double contactsPerGrasp;
};

// The embedded objects run the published 1000 placements. The research meshes run the first 250
// of the same seeded sequence, so the label stays within a minute or two on the 2-core machine.
// Contacts per grasp: measured at the commit that fixed caa7400's regression, rounded down. Against
// docs/benchmarks.md of 2026-11-22 (1000 placements, before the hand's clearance) the embedded
// objects are higher (mug 4.777 vs 4.75, torus 4.649 vs 4.59, thin plate 4.604 vs 4.52: the
// thumb's metacarpal now counts), the teapot and Igea lower by 0.007 and 0.003 (a hand whose open
// palm was inside is moved out before closing, and a finger that grazed the surface from the old
// pose misses it from the new one).
constexpr Gate kMug{1000, 4.77};
constexpr Gate kTorus{1000, 4.64};
constexpr Gate kThinPlate{1000, 4.60};

// `reference`: the surface `mesh` is a variant of (io/mesh_variants.h), which the placements and
// the grading use while "ours" solves on `mesh`.
void checkQuality(const std::string& name, const TriangleMesh& mesh, const Gate& gate,
                  const TriangleMesh* reference = nullptr) {
  QualityRun run;
  run.placements = gate.placements;
  run.seed = kSeed;
  run.threads = kThreads;
  run.reference = reference;
  const Result<QualityFigures> measured = measureQuality(mesh, run);
  REQUIRE(measured.ok());
  const QualityFigures& q = *measured;
  std::printf(
      "%s: %d grasps; contact residual median %.4f mm, p95 %.4f mm; penetration p99 %.3f mm, max "
      "%.3f mm (placement %d); early stops %d (%.1f per 1000); contacts per grasp %.3f; pass "
      "through %d\n",
      name.c_str(), q.grasps, q.contactResidualMedianMm, q.contactResidualP95Mm, q.penetrationP99Mm,
      q.penetrationMaxMm, q.deepestPlacement, q.earlyStops, q.earlyStopsPer1000(),
      q.contactsPerGrasp, q.passThroughs);
  INFO(name << ", seed " << kSeed << ": deepest penetration at placement " << q.deepestPlacement
            << ", an early stop at placement " << q.earlyStopPlacement);
  CHECK(q.grasps == gate.placements);
  CHECK(q.contactResidualMedianMm <= kResidualMedianMm);
  CHECK(q.contactResidualP95Mm <= kResidualP95Mm);
  CHECK(q.penetrationMaxMm <= kPenetrationMaxMm);
  CHECK(q.earlyStopsPer1000() <= kEarlyStopsPer1000);
  CHECK(q.contactsPerGrasp >= gate.contactsPerGrasp);
  CHECK(q.passThroughs == 0);
}

TriangleMesh embeddedMesh(const std::string& name) {
  std::optional<TriangleMesh> mesh;
  for (const NamedMesh& o : embeddedObjects()) {
    if (o.name == name) mesh = o.mesh;
  }
  REQUIRE(mesh.has_value());
  return *mesh;
}

void checkEmbedded(const std::string& name, const Gate& gate) {
  checkQuality(name, embeddedMesh(name), gate);
}

// `mesh` with its vertices split as `variant` (io/mesh_variants.h), solved on, and measured
// against `mesh` itself.
void checkVariant(const std::string& name, const TriangleMesh& mesh, std::string_view variant,
                  const Gate& gate) {
  const Result<TriangleMesh> split = makeMeshVariant(variant, mesh);
  REQUIRE(split.ok());
  std::printf("%s/%.*s: %zu vertices (%zu in the original), %zu triangles\n", name.c_str(),
              int(variant.size()), variant.data(), split->vertexCount(), mesh.vertexCount(),
              split->triangleCount());
  checkQuality(name + "/" + std::string(variant), *split, gate, &mesh);
}

void checkEmbeddedVariant(const std::string& name, std::string_view variant, const Gate& gate) {
  checkVariant(name, embeddedMesh(name), variant, gate);
}

}  // namespace

// A research mesh of ../shared/meshes, or a skip (before any assertion) where it is absent.
#define SDFG_CHECK_SHARED(file, gate)                                                   \
  do {                                                                                  \
    const auto path = test::sharedMesh(file);                                           \
    if (!path) SDFG_SKIP(std::string(file) + ": ../shared/meshes is not present here"); \
    const Result<LoadedMesh> loaded = loadMesh(*path);                                  \
    REQUIRE(loaded.ok());                                                               \
    checkQuality(file, loaded->mesh, gate);                                             \
  } while (false)

// A research mesh of ../shared/meshes as each variant in turn (loaded once: the load and the
// original's exact query are most of such a case's time), or a skip where it is absent.
#define SDFG_CHECK_SHARED_VARIANTS(file, gate)                                          \
  do {                                                                                  \
    const auto path = test::sharedMesh(file);                                           \
    if (!path) SDFG_SKIP(std::string(file) + ": ../shared/meshes is not present here"); \
    const Result<LoadedMesh> loaded = loadMesh(*path);                                  \
    REQUIRE(loaded.ok());                                                               \
    for (std::string_view variant : meshVariantNames()) {                               \
      checkVariant(file, loaded->mesh, variant, gate);                                  \
    }                                                                                   \
  } while (false)

TEST_CASE("ours meets its published quality on the embedded mug", "[quality]") {
  checkEmbedded("mug", kMug);
}

TEST_CASE("ours meets its published quality on the embedded torus", "[quality]") {
  checkEmbedded("torus", kTorus);
}

TEST_CASE("ours meets its published quality on the embedded thin plate", "[quality]") {
  checkEmbedded("thin-plate", kThinPlate);
}

TEST_CASE("ours meets its published quality on the Stanford bunny", "[quality][shared]") {
  SDFG_CHECK_SHARED("stanford-bunny.obj", (Gate{250, 4.75}));
}

TEST_CASE("ours meets its published quality on the Newell teapot", "[quality][shared]") {
  SDFG_CHECK_SHARED("newell-teapot.obj", (Gate{250, 4.84}));
}

TEST_CASE("ours meets its published quality on the torus mesh", "[quality][shared]") {
  SDFG_CHECK_SHARED("torus.obj", (Gate{250, 4.56}));
}

TEST_CASE("ours meets its published quality on the Stanford armadillo (100k)",
          "[quality][shared]") {
  SDFG_CHECK_SHARED("stanford-armadillo-100k.obj", (Gate{250, 4.44}));
}

TEST_CASE("ours meets its published quality on the Stanford armadillo (400k)",
          "[quality][shared]") {
  SDFG_CHECK_SHARED("stanford-armadillo-400k-subdiv.obj", (Gate{250, 4.43}));
}

TEST_CASE("ours meets its published quality on the Stanford dragon", "[quality][shared]") {
  SDFG_CHECK_SHARED("stanford-dragon-100k.ply", (Gate{250, 4.26}));
}

TEST_CASE("ours meets its published quality on the Igea scan (268k)", "[quality][shared]") {
  SDFG_CHECK_SHARED("igea-268k.obj", (Gate{250, 4.88}));
}

// Split vertices (game meshes): every object again as a game exporter gives it
// (io/mesh_variants.h): a triangle soup, flat shaded (split at edges whose faces turn by more
// than 30 degrees) and box-mapped (split at the seams of 6 UV charts). "ours" solves on the
// variant, its SDF and exact check built from it; the placements and the grading are the
// original's (QualityRun::reference), so a figure moves only by what the split changes in the
// solve. The surface is the same, so the gates are the original's, contacts per grasp included,
// with no margin: every variant's figures equal the original's to the last printed digit, with
// MeshDistance welding split vertices (3c0ad0e) and before it (8b95918), when a split mesh read
// as open and was signed by the winding number. What splitting broke before the weld (the
// layer's winding repair on a soup, the GPU's pseudo-normals) is not on this CPU path; these
// cases keep the path the figures are published from independent of how vertices are shared.
// The embedded objects run the original's 1000 placements; the research meshes the first 100 of
// the same sequence (the label runs on 2 cores in CI).
namespace {

constexpr int kSharedVariantPlacements = 100;

}  // namespace

TEST_CASE("ours meets its published quality on the embedded mug as a triangle soup",
          "[quality][variants]") {
  checkEmbeddedVariant("mug", "soup", kMug);
}

TEST_CASE("ours meets its published quality on the embedded mug flat shaded",
          "[quality][variants]") {
  checkEmbeddedVariant("mug", "flat", kMug);
}

TEST_CASE("ours meets its published quality on the embedded mug with UV seams",
          "[quality][variants]") {
  checkEmbeddedVariant("mug", "seams", kMug);
}

TEST_CASE("ours meets its published quality on the embedded torus as a triangle soup",
          "[quality][variants]") {
  checkEmbeddedVariant("torus", "soup", kTorus);
}

TEST_CASE("ours meets its published quality on the embedded torus flat shaded",
          "[quality][variants]") {
  checkEmbeddedVariant("torus", "flat", kTorus);
}

TEST_CASE("ours meets its published quality on the embedded torus with UV seams",
          "[quality][variants]") {
  checkEmbeddedVariant("torus", "seams", kTorus);
}

TEST_CASE("ours meets its published quality on the embedded thin plate as a triangle soup",
          "[quality][variants]") {
  checkEmbeddedVariant("thin-plate", "soup", kThinPlate);
}

TEST_CASE("ours meets its published quality on the embedded thin plate flat shaded",
          "[quality][variants]") {
  checkEmbeddedVariant("thin-plate", "flat", kThinPlate);
}

TEST_CASE("ours meets its published quality on the embedded thin plate with UV seams",
          "[quality][variants]") {
  checkEmbeddedVariant("thin-plate", "seams", kThinPlate);
}

// The research meshes up to 100k triangles, one case each for its three variants (the 400k
// armadillo, the dragon and Igea took 220 s of the label's CPU time in all, a third of CI's budget
// for it: their variants are in the benchmark, `autograsp-bench --variants`, and
// docs/benchmarks-notes.md). Contacts per grasp: the original's
// over the same first 100 placements (measured at 3c0ad0e; the 250-placement gates above do not
// hold for a prefix: the bunny's first 100 give 4.66 against 4.75), less half a contact in 100
// grasps so the comparison is not one of floats at an exact hundredth.
TEST_CASE("ours meets its published quality on the variants of the Stanford bunny",
          "[quality][shared][variants]") {
  SDFG_CHECK_SHARED_VARIANTS("stanford-bunny.obj", (Gate{kSharedVariantPlacements, 4.655}));
}

TEST_CASE("ours meets its published quality on the variants of the Newell teapot",
          "[quality][shared][variants]") {
  SDFG_CHECK_SHARED_VARIANTS("newell-teapot.obj", (Gate{kSharedVariantPlacements, 4.835}));
}

TEST_CASE("ours meets its published quality on the variants of the torus mesh",
          "[quality][shared][variants]") {
  SDFG_CHECK_SHARED_VARIANTS("torus.obj", (Gate{kSharedVariantPlacements, 4.605}));
}

TEST_CASE("ours meets its published quality on the variants of the Stanford armadillo (100k)",
          "[quality][shared][variants]") {
  SDFG_CHECK_SHARED_VARIANTS("stanford-armadillo-100k.obj",
                             (Gate{kSharedVariantPlacements, 4.425}));
}

// Scenes (issue 26, eval/scene_quality.h): "ours" among other objects keeps the whole hand out of
// every object it does not hold (p99 <= 1 mm, max <= 2 mm) and takes the graspable object its
// palm faces. Fewer placements than the single-object gates (the first 100 of the same seeded
// sequence) keep the label within its two minutes. (Before target_choice.h preferred the object
// the palm faces, the hand took the other mug in 15 of 100 grasps beside a mug, and the mug in 11
// of 100 in the spoon scene: more fingers closed on the neighbour.)
namespace {

// The held object among others as clean as alone (issue 37; quality_gates.h): the fingers out of
// it (p99 <= 0.5 mm, max <= 1 mm, the single-object gates' figures), and the version 1 contacts an
// app reads are on it: the reported distance is its exact distance at the reported point
// (<= 0.2 mm).
// Open hands that start inside the mug reached for, a neighbour 1 cm away: cleared out of both.
constexpr double kClearedP99Mm = 1.0;

// Measured once per scene (and approaching or not): the cases below that check the same scene
// read the same run.
SceneFigures measureEmbeddedScene(const std::string& name, bool approaching = false) {
  static std::map<std::string, SceneFigures> measuredBefore;
  const std::string key = name + (approaching ? " (approaching)" : "");
  if (auto it = measuredBefore.find(key); it != measuredBefore.end()) return it->second;
  std::optional<BenchScene> scene;
  for (BenchScene& s : embeddedScenes()) {
    if (s.name == name) scene = std::move(s);
  }
  REQUIRE(scene.has_value());
  SceneRun run;
  run.placements = kScenePlacements;
  run.seed = kSeed;
  run.threads = kThreads;
  run.approaching = approaching;
  const Result<SceneFigures> measured = measureScene(*scene, run);
  INFO((measured.ok() ? std::string() : measured.error().message));
  REQUIRE(measured.ok());
  const SceneFigures& q = *measured;
  std::printf(
      "%s: %d grasps; objects not held: penetration p99 %.3f mm, max %.3f mm (placement %d, "
      "%s), %d grasps inside one; wrong object %d of %d facing a graspable one (first at %d), "
      "nothing held %d (in the wrong grasps, fingers on the one taken %d, on the one faced %d; "
      "%d with a finger on the one faced); "
      "contacts per grasp %.3f; finger penetration into the held max %.3f mm; contact residual "
      "median %.4f, p95 %.4f mm; early stops %d; pass through %d; held: penetration p99 %.3f mm; "
      "version 1 contacts %d, residual max %.4f mm; open hand inside %d, whole hand after p99 "
      "%.3f mm, max %.3f mm (placement %d), clearance bound exceeded %d (deeper after by %.3f mm "
      "at "
      "most, placement %d)\n",
      key.c_str(), q.grasps, q.otherPenetrationP99Mm, q.otherPenetrationMaxMm, q.deepestPlacement,
      q.deepestObject.c_str(), q.otherPenetrating, q.wrongObject, q.facingGraspable,
      q.firstWrongPlacement, q.heldNothing, q.wrongFingersOnTaken, q.wrongFingersOnFaced,
      q.wrongWithFingerOnFaced, q.held.contactsPerGrasp, q.held.penetrationMaxMm,
      q.held.contactResidualMedianMm, q.held.contactResidualP95Mm, q.held.earlyStops,
      q.held.passThroughs, q.held.penetrationP99Mm, q.v1Contacts, q.v1ResidualMaxMm, q.openInside,
      q.insideWholeP99Mm, q.insideWholeMaxMm, q.insideDeepestPlacement, q.clearanceExceeded,
      q.exceededDeeperMaxMm, q.exceededDeeperPlacement);
  CHECK(q.grasps == kScenePlacements);
  measuredBefore[key] = q;
  return q;
}

void checkOutOfOthers(const std::string& name, const SceneFigures& q) {
  INFO(name << ", seed " << kSeed << ": deepest penetration at placement " << q.deepestPlacement
            << " into " << q.deepestObject);
  CHECK(q.otherPenetrationP99Mm <= kOtherPenetrationP99Mm);
  CHECK(q.otherPenetrationMaxMm <= kOtherPenetrationMaxMm);
}

void checkRightObject(const std::string& name, const SceneFigures& q) {
  INFO(name << ", seed " << kSeed << ": first wrong object at placement " << q.firstWrongPlacement);
  CHECK(q.facingGraspable > 0);
  CHECK(q.wrongObject == 0);
}

void checkHeld(const std::string& name, const SceneFigures& q) {
  INFO(name << ", seed " << kSeed << ": deepest finger in the held object at placement "
            << q.held.deepestPlacement);
  CHECK(q.held.penetrationP99Mm <= kHeldPenetrationP99Mm);
  CHECK(q.held.penetrationMaxMm <= kHeldPenetrationMaxMm);
  CHECK(q.v1Contacts > 0);
  CHECK(q.v1ResidualMaxMm <= kV1ResidualMm);
}

void checkScene(const std::string& name) {
  const SceneFigures q = measureEmbeddedScene(name);
  checkOutOfOthers(name, q);
  checkRightObject(name, q);
}

}  // namespace

TEST_CASE("ours keeps out of the table under the mug", "[quality][scenes]") {
  checkScene("mug/table");
}

TEST_CASE("ours keeps out of the table under the torus", "[quality][scenes]") {
  checkScene("torus/table");
}

TEST_CASE("ours keeps out of the table under the thin plate", "[quality][scenes]") {
  checkScene("thin-plate/table");
}

TEST_CASE("ours keeps out of the wall behind the mug's handle", "[quality][scenes]") {
  checkScene("mug-handle-wall");
}

TEST_CASE("ours keeps out of the mug beside the one it grasps", "[quality][scenes]") {
  checkOutOfOthers("mug-beside-mug", measureEmbeddedScene("mug-beside-mug"));
}

TEST_CASE("ours keeps out of the mug the spoon stands in", "[quality][scenes]") {
  checkOutOfOthers("spoon-in-mug", measureEmbeddedScene("spoon-in-mug"));
}

TEST_CASE("ours takes the mug its palm faces and not the one beside it", "[quality][scenes]") {
  checkRightObject("mug-beside-mug", measureEmbeddedScene("mug-beside-mug"));
}

TEST_CASE("ours takes the spoon its palm faces and not the mug it stands in", "[quality][scenes]") {
  checkRightObject("spoon-in-mug", measureEmbeddedScene("spoon-in-mug"));
}

TEST_CASE("ours keeps out of the table under a ruler lying flat on it", "[quality][scenes]") {
  checkScene("ruler-on-table");
}

TEST_CASE("ours keeps the fingers out of what it holds, and its contacts on it, in every scene",
          "[quality][scenes]") {
  for (const BenchScene& s : embeddedScenes()) checkHeld(s.name, measureEmbeddedScene(s.name));
}

TEST_CASE("ours clears an open hand that starts inside a mug 1 cm from another out of both",
          "[quality][scenes]") {
  const SceneFigures q = measureEmbeddedScene("mug-near-mug", true);
  INFO("seed " << kSeed << ": deepest cleared hand at placement " << q.insideDeepestPlacement
               << ", deepest hand past the bound at " << q.exceededDeeperPlacement);
  // Cleared: moved out of the mug without going into the other one or the table.
  CHECK(q.openInside - q.clearanceExceeded > 0);
  CHECK(q.insideWholeP99Mm <= kClearedP99Mm);
  // Past the bound (a palm through the wall into the cup: more than 3 cm to come out), the hand
  // says so (XrGraspHandOffsetSDFG::exceeded) and its fingers close no deeper than it already was.
  CHECK(q.exceededDeeperMaxMm <= 0.1);
  checkOutOfOthers("mug-near-mug (approaching)", q);
}
