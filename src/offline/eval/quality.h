// A strategy's grasp quality on one object, in the figures the benchmark publishes and the
// quality tests gate (DESIGN.md section 4): contact residual, penetration, early stops, contacts.
//
// measureQuality() runs the benchmark's own procedure without its timing: the object scaled to
// the bench's size, the seeded placements (eval/placements.h), a CPU grab-box SDF per placement,
// the strategy's solve (with the exact check where it reads one), and evaluateGrasp() on the
// exact mesh. Every figure is a pure function of the mesh, the settings and the seed (placements
// are graded independently, so the thread count changes nothing), which is what lets a test hold
// them to published values.
//
// With QualityRun::reference the strategy sees one mesh and the figures are measured on another
// of the same surface: a mesh whose vertices are split as a game exporter splits them
// (io/mesh_variants.h) is solved on, while the placements and the grading come from the original,
// so a variant's figures differ from the original's only by what the split changed in the solve.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "base/status.h"
#include "grasp/solver.h"
#include "mesh/mesh.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

// Every object of the benchmark is scaled to this bounding-box diagonal (a hand-sized object).
inline constexpr float kBenchObjectDiagonal = 0.18f;  // metres

struct QualityRun {
  std::string method = "ours";  // an SDF strategy of createSolver()
  int placements = 1000;
  uint64_t seed = 1;
  unsigned threads = 1;  // placements solved and graded at once; no effect on the figures
  SolverOptions options{};
  bool exactCheck = true;  // GraspScene::exact for the strategies that read it
  GridBox box = GridBox::referenceDefault();
  // The surface the figures are measured against, when not the mesh solved on: placements are
  // drawn on it and every grasp graded on its exact distance, while the SDF and the exact check
  // the strategy reads come from the mesh given to measureQuality(). Both are scaled by the
  // reference's bounds, so a variant with the reference's positions keeps them bit-identical.
  // Null: the mesh itself. Not owned; must outlive the call.
  const TriangleMesh* reference = nullptr;
};

// Figures in millimetres over the placements' grasps (residuals over fingers in contact).
struct QualityFigures {
  int grasps = 0;
  int fingersInContact = 0;
  double contactResidualMedianMm = 0.0;
  double contactResidualP95Mm = 0.0;
  double penetrationP99Mm = 0.0;  // over grasps (each grasp's deepest finger)
  double penetrationMaxMm = 0.0;
  int earlyStops = 0;
  double contactsPerGrasp = 0.0;  // fingers touching (within kTouchingMm), mean per grasp
  int passThroughs = 0;
  // The grasp with the deepest penetration and one with an early stop (-1: none), for a failing
  // test to name.
  int deepestPlacement = -1;
  int earlyStopPlacement = -1;

  double earlyStopsPer1000() const { return grasps > 0 ? 1000.0 * earlyStops / grasps : 0.0; }
};

struct GraspMetrics;  // eval/evaluator.h

// Sums grasps into QualityFigures, in placement order: the one sum behind measureQuality() and a
// scene's figures on the object held (eval/scene_quality.h).
class QualityTally {
 public:
  void add(int placement, const GraspMetrics& grasp);
  QualityFigures figures() const;  // the percentiles over what was added

 private:
  QualityFigures sums_;
  std::vector<double> residuals_;     // per finger in contact
  std::vector<double> penetrations_;  // per grasp
  int touching_ = 0;
};

// `mesh` scaled and centred as normalizedToDiagonal(reference, diagonal) scales the reference:
// the same arithmetic on the same coordinates, so a position `mesh` shares with the reference
// stays bit-identical. (normalizedToDiagonal(mesh) would use the mesh's own bounds, which differ
// where the reference has a vertex no triangle of `mesh` uses.) For QualityRun::reference and
// the benchmark's variants.
TriangleMesh normalizedLike(const TriangleMesh& mesh, const TriangleMesh& reference,
                            float diagonal);

// Runs `run` on `mesh` (any size and place: it is scaled to kBenchObjectDiagonal). Errors: an
// invalid mesh or reference, an unknown or non-SDF strategy, invalid options, fewer placements
// found than asked (a mesh with no room for an open hand), or a failed build or solve (named).
Result<QualityFigures> measureQuality(const TriangleMesh& mesh, const QualityRun& run);

}  // namespace sdfg
