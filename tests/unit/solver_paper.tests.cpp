// The "paper" strategy: Algorithm 3 with eq. 3, on analytic SDFs where the answer is known.
#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <iostream>
#include <limits>
#include <new>
#include <vector>

#include "grasp/solver_paper.h"
#include "grasp_scenes.h"

// Counts every allocation of the test program, so a test can show that solve() makes none.
namespace {
std::atomic<size_t> gAllocations{0};
}  // namespace

// Every non-aligned form is replaced, so all of them pair malloc with free (sanitizers check).
void* operator new(std::size_t size) {
  ++gAllocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  return operator new(size);
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  ++gAllocations;
  return std::malloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept {
  return operator new(size, tag);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}

namespace {

using namespace sdfg;
using sdfg::test::fillGrid;
using sdfg::test::firstContactCurl;

// A straight synthetic curve for the pure functions: from y = +5 cm down to y = -5 cm at
// constant speed, x = z = 0, sampled at a_k = min(k * da, 1).
struct LineCurve {
  std::vector<float> params;
  std::vector<glm::vec3> points;
  std::vector<float> back;
};

LineCurve lineCurve(float da) {
  LineCurve c;
  for (int k = 0;; ++k) {
    const float a = std::min(float(k) * da, 1.0f);
    c.params.push_back(a);
    c.points.emplace_back(0.0f, 0.05f - 0.1f * a, 0.0f);
    c.back.push_back(k == 0 ? 0.0f : glm::distance(c.points[k], c.points[k - 1]));
    if (a >= 1.0f) break;
  }
  return c;
}

// A box centred on the hand, big enough that no sample is clamped.
GridBox roomyBox() {
  GridBox box;
  box.size = glm::vec3(0.6f);
  box.resolution = glm::uvec3(8u);
  return box;
}

// SDF of the half-space y < level (a plane, so trilinear sampling reproduces it exactly).
auto planeBelow(float level) {
  return [level](const glm::vec3& p) { return p.y - level; };
}

std::vector<glm::vec3> toNormalized(const GridBox& box, const std::vector<glm::vec3>& points) {
  std::vector<glm::vec3> out;
  for (const glm::vec3& p : points) out.push_back(box.handToNormalized(p));
  return out;
}

}  // namespace

TEST_CASE("paper fine-tune follows eq. 3 over the segment just travelled", "[solver][paper]") {
  SECTION("pulls back by (d - r) / |AB| of the step") {
    // 5 mm past a 1 cm threshold over a 2 cm segment: back a quarter of the 0.1 step.
    CHECK(paperFineTune(0.2f, 0.3f, 0.005f, 0.01f, 0.02f) == Approx(0.275f).margin(1e-6));
  }
  SECTION("never goes behind the last free sample") {
    CHECK(paperFineTune(0.2f, 0.3f, -0.5f, 0.01f, 0.02f) == Approx(0.2f).margin(1e-7));
  }
  SECTION("a zero, negative or non-finite segment leaves the sample unchanged") {
    CHECK(paperFineTune(0.9f, 1.0f, 0.0f, 0.01f, 0.0f) == 1.0f);
    CHECK(paperFineTune(0.9f, 1.0f, 0.0f, 0.01f, -1.0f) == 1.0f);
    CHECK(paperFineTune(0.9f, 1.0f, 0.0f, 0.01f, std::numeric_limits<float>::quiet_NaN()) == 1.0f);
    CHECK(paperFineTune(0.9f, 1.0f, 0.0f, 0.01f, std::numeric_limits<float>::infinity()) == 1.0f);
  }
  SECTION("a NaN distance leaves the sample unchanged") {
    CHECK(paperFineTune(0.2f, 0.3f, std::numeric_limits<float>::quiet_NaN(), 0.01f, 0.02f) == 0.3f);
  }
}

TEST_CASE("paperSolveFinger stops at the first sample under the threshold", "[solver][paper]") {
  const GridBox box = roomyBox();
  SdfGrid grid(box);
  const float r = 0.01f;
  const float da = GENERATE(0.1f, 0.3f, 0.01f, 1.0f);
  CAPTURE(da);
  const LineCurve c = lineCurve(da);
  const std::vector<glm::vec3> uvw = toNormalized(box, c.points);

  SECTION("on a plane crossed mid-curve, eq. 3 lands on the exact contact of a straight path") {
    // Tip y = 0.05 - 0.1 a reaches distance r from the plane y = -0.013 at a = 0.53.
    fillGrid(grid, planeBelow(-0.013f));
    const PaperFingerStop stop = paperSolveFinger(grid, uvw, c.params, c.back, r);
    REQUIRE(stop.contact);
    REQUIRE(stop.sample > 0);
    CHECK(stop.distance < r);
    CHECK(stop.curl >= c.params[stop.sample - 1]);
    CHECK(stop.curl <= c.params[stop.sample]);
    // A straight path at constant speed is where the linear correction is exact.
    CHECK(stop.curl == Approx(0.53f).margin(1e-4));
    // The sample before the stop was free: no early sample was skipped.
    CHECK(grid.sampleNormalized(uvw[stop.sample - 1]) >= r);
  }
  SECTION("touching in the open pose stops at 0") {
    fillGrid(grid, planeBelow(0.049f));
    const PaperFingerStop stop = paperSolveFinger(grid, uvw, c.params, c.back, r);
    CHECK(stop.contact);
    CHECK(stop.sample == 0);
    CHECK(stop.curl == 0.0f);
  }
  SECTION("a stop on the last sample (a = 1) is finite and fine-tuned") {
    // The plane is within r of the tip only past the middle of the last segment.
    const float aPrev = c.params[c.params.size() - 2];
    const float contact = 0.5f * (aPrev + 1.0f);
    fillGrid(grid, planeBelow(0.05f - 0.1f * contact - r));
    const PaperFingerStop stop = paperSolveFinger(grid, uvw, c.params, c.back, r);
    REQUIRE(stop.contact);
    CHECK(stop.sample == c.params.size() - 1);
    CHECK(std::isfinite(stop.curl));
    CHECK(stop.curl == Approx(contact).margin(1e-4));
  }
  SECTION("nothing within reach closes the finger after testing a = 1") {
    fillGrid(grid, planeBelow(-0.2f));
    const PaperFingerStop stop = paperSolveFinger(grid, uvw, c.params, c.back, r);
    CHECK_FALSE(stop.contact);
    CHECK(stop.curl == 1.0f);
    CHECK(stop.sample == c.params.size() - 1);
    CHECK(stop.distance == Approx(0.15f).margin(1e-5));
  }
}

TEST_CASE("paper solver closes each finger onto a plane under the palm", "[solver][paper]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const GridBox box = GridBox::referenceDefault();
  SdfGrid grid(box);

  // The plane's height is chosen from the hand so fingers reach it mid-curl whatever the
  // model's proportions: 40% of the way from the lowest tip of the long fingers to their open
  // height.
  float lowest = 1.0f, open = -1.0f;
  for (Finger f : {Finger::index, Finger::middle, Finger::ring}) {
    open = std::max(open, hand.tipPosition(f, 0.0f).y);
    for (int s = 0; s <= 100; ++s) lowest = std::min(lowest, hand.tipPosition(f, s / 100.0f).y);
  }
  const float level = lowest + 0.4f * (open - lowest);
  const auto plane = planeBelow(level);
  fillGrid(grid, plane);

  const float da = GENERATE(0.1f, 0.01f, 0.3f, 0.07f);
  CAPTURE(da, level);
  SolverOptions options;
  options.da = da;
  PaperSolver solver;
  REQUIRE(solver.prepare(hand, box, options) == Status::ok);
  CHECK(solver.prepareError().empty());
  const std::span<const float> params = solver.sampleCurls();
  REQUIRE(solver.sampleCount() == kFingerCount * params.size());
  // No sample ceiling: da = 0.01 is 101 samples per finger, 505 per grasp.
  if (da == 0.01f) CHECK(solver.sampleCount() == 505);

  GraspScene scene;
  scene.field = &grid;
  GraspResult result;
  REQUIRE(solver.solve(scene, result) == Status::ok);

  int touching = 0;
  for (int f = 0; f < kFingerCount; ++f) {
    const Finger finger = Finger(f);
    const float r = hand.tipRadius(finger);
    const FingerState& state = result.fingers[f];
    const std::optional<float> truth = firstContactCurl(hand, finger, plane, r);
    CAPTURE(fingerName(finger), state.curl, truth.value_or(-1.0f));
    CHECK(state.jointCurls[0] == state.curl);
    CHECK(state.jointCurls[3] == state.curl);
    CHECK(glm::distance(state.contactPoint, hand.tipPosition(finger, state.curl)) < 1e-5f);
    if (!truth) {
      CHECK_FALSE(state.contact);
      CHECK(state.curl == 1.0f);
      continue;
    }
    ++touching;
    REQUIRE(state.contact);
    // The stopping sample k: the first whose tip is closer than r (a plane samples exactly).
    size_t k = 0;
    while (k < params.size() && plane(hand.tipPosition(finger, params[k])) >= r) ++k;
    REQUIRE(k < params.size());
    CHECK(state.distance == Approx(plane(hand.tipPosition(finger, params[k]))).margin(1e-5));
    if (k == 0) {
      CHECK(state.curl == 0.0f);
      continue;
    }
    const float aPrev = params[k - 1], a = params[k];
    // The true contact lies between the last free sample and the touching one; so does the
    // fine-tuned curl, and it is exactly eq. 3 over the segment just travelled.
    CHECK(*truth >= aPrev - 1e-5f);
    CHECK(*truth <= a + 1e-5f);
    CHECK(state.curl >= aPrev);
    CHECK(state.curl <= a);
    const float segment =
        glm::distance(hand.tipPosition(finger, a), hand.tipPosition(finger, aPrev));
    const float expected = std::clamp(a + (state.distance - r) / segment * (a - aPrev), aPrev, a);
    CHECK(state.curl == Approx(expected).margin(1e-4));
    CHECK(std::abs(state.curl - *truth) <= (a - aPrev) + 1e-5f);
  }
  // The scene is meant to be touched: the long fingers at least reach the plane.
  CHECK(touching >= 3);
}

TEST_CASE("paper solver handles no object, an object at the open hand and custom thresholds",
          "[solver][paper]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const GridBox box = roomyBox();
  SdfGrid grid(box);
  PaperSolver solver;
  SolverOptions options;
  REQUIRE(solver.prepare(hand, box, options) == Status::ok);
  GraspScene scene;
  scene.field = &grid;
  GraspResult result;

  SECTION("nothing in the box: every finger closes fully without contact") {
    fillGrid(grid, [](const glm::vec3&) { return 1.0f; });
    REQUIRE(solver.solve(scene, result) == Status::ok);
    for (const FingerState& state : result.fingers) {
      CHECK(state.curl == 1.0f);
      CHECK_FALSE(state.contact);
      CHECK(state.distance == Approx(1.0f));
    }
  }
  SECTION("an object already at the open fingertips stops every finger at 0") {
    float top = -1.0f;
    for (int f = 0; f < kFingerCount; ++f) top = std::max(top, hand.tipPosition(Finger(f), 0.0f).y);
    fillGrid(grid, planeBelow(top + 0.001f));
    REQUIRE(solver.solve(scene, result) == Status::ok);
    for (int f = 0; f < kFingerCount; ++f) {
      CAPTURE(f);
      CHECK(result.fingers[f].curl == 0.0f);
      CHECK(result.fingers[f].contact);
      CHECK(glm::distance(result.fingers[f].contactPoint, hand.tipPosition(Finger(f), 0.0f)) <
            1e-6f);
    }
  }
  SECTION("a stop on the last sample gives a finite curl between 0.9 and 1") {
    // The distance to the index tip's closed position, on a fine grid over the index curve:
    // with a threshold of half the last segment, only a = 1 is within it (checked on the grid,
    // since the curve's shape is the hand model's).
    const glm::vec3 end = hand.tipPosition(Finger::index, 1.0f);
    const float threshold = 0.5f * glm::distance(hand.tipPosition(Finger::index, 0.9f), end);
    glm::vec3 lo(1e9f), hi(-1e9f);
    for (int s = 0; s <= 100; ++s) {
      lo = glm::min(lo, hand.tipPosition(Finger::index, s / 100.0f));
      hi = glm::max(hi, hand.tipPosition(Finger::index, s / 100.0f));
    }
    GridBox tight;
    tight.handFromBox.position = 0.5f * (lo + hi);
    tight.size = hi - lo + 0.04f;
    tight.resolution = glm::uvec3(96u);
    SdfGrid point(tight);
    fillGrid(point, [&](const glm::vec3& p) { return glm::distance(p, end); });
    REQUIRE(point.sample(end) < threshold);
    for (int s = 0; s <= 9; ++s) {
      CAPTURE(s);
      REQUIRE(point.sample(hand.tipPosition(Finger::index, s / 10.0f)) >= threshold);
    }
    options.threshold = threshold;
    REQUIRE(solver.prepare(hand, tight, options) == Status::ok);
    scene.field = &point;
    REQUIRE(solver.solve(scene, result) == Status::ok);
    const FingerState& index = result.fingers[int(Finger::index)];
    CHECK(index.contact);
    CHECK(std::isfinite(index.curl));
    CHECK(index.curl >= 0.9f);
    CHECK(index.curl < 1.0f);
  }
  SECTION("a larger threshold stops fingers no later") {
    const float top = hand.tipPosition(Finger::middle, 0.0f).y;
    fillGrid(grid, planeBelow(top - 0.04f));
    REQUIRE(solver.solve(scene, result) == Status::ok);
    GraspResult wide;
    options.threshold = 0.03f;
    REQUIRE(solver.prepare(hand, box, options) == Status::ok);
    REQUIRE(solver.solve(scene, wide) == Status::ok);
    for (int f = 0; f < kFingerCount; ++f) {
      CAPTURE(f);
      CHECK(wide.fingers[f].curl <= result.fingers[f].curl);
    }
  }
}

TEST_CASE("paper solver rejects invalid options and incomplete scenes", "[solver][paper]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const GridBox box = GridBox::referenceDefault();
  SdfGrid grid(box);
  PaperSolver solver;
  GraspScene scene;
  scene.field = &grid;
  GraspResult result;

  SECTION("solve before prepare fails") {
    CHECK(solver.solve(scene, result) == Status::invalid_argument);
  }
  SECTION("bad steps and thresholds fail prepare and leave it unprepared") {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const float badDa = GENERATE_COPY(0.0f, -0.1f, 1.5f, nan, inf);
    CAPTURE(badDa);
    SolverOptions options;
    REQUIRE(solver.prepare(hand, box, options) == Status::ok);
    options.da = badDa;
    CHECK(solver.prepare(hand, box, options) == Status::invalid_argument);
    CHECK(solver.prepareError().find("da") != std::string_view::npos);
    CHECK(solver.sampleCount() == 0);
    CHECK(solver.solve(scene, result) == Status::invalid_argument);

    options = SolverOptions{};
    options.threshold = nan;
    CHECK(solver.prepare(hand, box, options) == Status::invalid_argument);
    options = SolverOptions{};
    options.refineStep = 0.0f;
    CHECK(solver.prepare(hand, box, options) == Status::invalid_argument);
  }
  SECTION("an invalid box fails prepare") {
    GridBox bad = box;
    bad.resolution.x = 1;
    CHECK(solver.prepare(hand, bad, SolverOptions{}) == Status::invalid_argument);
    CHECK_FALSE(solver.prepareError().empty());
  }
  SECTION("solve needs a field on the prepared box") {
    REQUIRE(solver.prepare(hand, box, SolverOptions{}) == Status::ok);
    GraspScene empty;
    CHECK(solver.solve(empty, result) == Status::invalid_argument);
    SdfGrid unfilled;  // default-constructed: no values
    empty.field = &unfilled;
    CHECK(solver.solve(empty, result) == Status::invalid_argument);
    GridBox moved = box;
    moved.handFromBox.position.y += 0.01f;
    SdfGrid elsewhere(moved);
    empty.field = &elsewhere;
    CHECK(solver.solve(empty, result) == Status::invalid_argument);
    // Another resolution on the same box is fine: the cache is in normalized coordinates.
    GridBox finer = box;
    finer.resolution = glm::uvec3(32u);
    SdfGrid fine(finer);
    empty.field = &fine;
    CHECK(solver.solve(empty, result) == Status::ok);
  }
}

TEST_CASE("paper solve does not allocate, and its time per grasp is printed", "[solver][paper]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const GridBox box = GridBox::referenceDefault();
  SdfGrid grid(box);
  // Half the fingers stop mid-curl (fine-tuned contact points go through the hand model).
  fillGrid(grid, planeBelow(hand.tipPosition(Finger::middle, 0.0f).y - 0.03f));
  PaperSolver solver;
  REQUIRE(solver.prepare(hand, box, SolverOptions{}) == Status::ok);
  GraspScene scene;
  scene.field = &grid;
  GraspResult result;

  const size_t before = gAllocations.load();
  const Status status = solver.solve(scene, result);
  const size_t allocations = gAllocations.load() - before;
  REQUIRE(status == Status::ok);
  CHECK(allocations == 0);

  constexpr int kGrasps = 20000;
  const std::clock_t start = std::clock();  // CPU time: the CI machine is shared
  float sink = 0.0f;
  for (int i = 0; i < kGrasps; ++i) {
    solver.solve(scene, result);
    sink += result.fingers[i % kFingerCount].curl;
  }
  const double us = 1e6 * double(std::clock() - start) / CLOCKS_PER_SEC;
  std::cout << "paper solve, da 0.1, 5 fingers (" << solver.sampleCount()
            << " samples): " << us / kGrasps << " us CPU per grasp (checksum " << sink << ")\n";
  CHECK(std::isfinite(sink));
}
