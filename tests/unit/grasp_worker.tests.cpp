// GraspSession and its worker: the caller's update() hands poses over and takes the newest
// finished result; set-ups, refits, builds and solves run on the worker. No test counts updates
// until a result exists: each waits for the outcome with a generous time bound (waitWorkerIdle, or
// a deadline).
#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <new>
#include <thread>

#include <glm/gtc/quaternion.hpp>

#include "grasp/grasp_session.h"
#include "grasp/grasp_worker.h"
#include "grasp/solver.h"
#include "hand/hand_synthesis.h"
#include "io/shapes.h"
#include "mesh/mesh_distance.h"
#include "sdf/sdf_backend.h"

namespace {

using namespace sdfg;
using namespace std::chrono_literals;

// A right hand whose grab box is centred on the target at the origin, squeezing.
HandFrame squeezing(float squeeze) {
  HandFrame f;
  f.valid = true;
  f.squeeze = squeeze;
  f.worldFromWrist = GridBox::referenceDefault().handFromBox.inverse();
  return f;
}

GraspSettings oursSettings() {
  GraspSettings s;
  s.solver = "ours";
  return s;
}

// Updates the hand until `done` holds, at most 20 s; true when it held.
template <class F>
bool updateUntil(GraspSession& session, const HandFrame& frame, const TargetFrame& target, F done) {
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (std::chrono::steady_clock::now() < deadline) {
    REQUIRE(session.update(Hand::right, frame, {&target, 1}) == Status::ok);
    if (done()) return true;
    std::this_thread::sleep_for(1ms);
  }
  return false;
}

int contacts(const HandGrasp& g) {
  int n = 0;
  for (const FingerState& f : g.result.fingers) n += f.contact ? 1 : 0;
  return n;
}

// A CPU backend that blocks its builds until released, to hold a job on the worker. It honours
// the build's WorkLimit as the CPU builder does, polling it while it waits, and records whether
// it was the limit's stop flag (not its deadline) that ended a wait.
class GatedBackend final : public SdfBackend {
 public:
  explicit GatedBackend(std::shared_ptr<std::atomic<bool>> open,
                        std::shared_ptr<std::atomic<int>> calls = nullptr,
                        std::shared_ptr<std::atomic<bool>> stoppedByFlag = nullptr)
      : open_(std::move(open)),
        calls_(std::move(calls)),
        stoppedByFlag_(std::move(stoppedByFlag)),
        cpu_(makeCpuSdfBackend(1)) {}
  std::string_view name() const override { return "gated"; }
  using SdfBackend::build;
  Status build(const MeshDistance& target, const Pose& pose, const GridBox& box, SdfGrid& out,
               const WorkLimit& limit) override {
    if (calls_ != nullptr) ++*calls_;
    while (!open_->load()) {
      if (limit.reached()) {
        if (stoppedByFlag_ != nullptr && limit.stop != nullptr && limit.stop->load())
          stoppedByFlag_->store(true);
        return Status::timed_out;
      }
      std::this_thread::sleep_for(1ms);
    }
    return cpu_->build(target, pose, box, out, limit);
  }

 private:
  std::shared_ptr<std::atomic<bool>> open_;
  std::shared_ptr<std::atomic<int>> calls_;
  std::shared_ptr<std::atomic<bool>> stoppedByFlag_;
  std::unique_ptr<SdfBackend> cpu_;
};

}  // namespace

TEST_CASE("GraspSession sets targets up off the caller's thread", "[grasp_worker][core]") {
  GraspSession session(makeCpuSdfBackend(1));
  REQUIRE(session.addTarget(7, makeSphere(0.04f, 3)) == Status::ok);
  // Known at once, graspable once the worker has built its exact distance.
  CHECK(session.hasTarget(7));
  CHECK(session.targetSetup(7) != TargetSetup::unknown);
  REQUIRE(session.waitWorkerIdle(20s));
  CHECK(session.targetSetup(7) == TargetSetup::ready);
  CHECK(session.targetSetup(8) == TargetSetup::unknown);
  CHECK(session.takeSetupFailures().empty());
  // A second id is refused as before.
  CHECK(session.addTarget(7, makeSphere(0.04f, 3)) == Status::invalid_argument);
}

TEST_CASE("The worker's grasp is the one a build and solve made directly give",
          "[grasp_worker][core]") {
  const TargetFrame target{7, true, Pose{}};
  const TriangleMesh sphere = makeSphere(0.04f, 3);
  const GraspSettings settings = oursSettings();
  // Directly: the exact distance, the grab-box field, the solver with its exact check.
  const Pose objectFromHand = squeezing(1.0f).worldFromWrist;  // the target sits at the origin
  auto distance = MeshDistance::create(sphere);
  REQUIRE(distance.ok());
  SdfGrid grid;
  REQUIRE(makeCpuSdfBackend(1)->build(**distance, objectFromHand, settings.box, grid) ==
          Status::ok);
  auto solver = createSolver("ours");
  REQUIRE(solver.ok());
  REQUIRE((*solver)->prepare(HandModel::defaultAdult(Hand::right), settings.box,
                             settings.solverOptions) == Status::ok);
  GraspScene scene;
  scene.field = &grid;
  scene.objectFromHand = objectFromHand;
  MeshExactSource exact(**distance, objectFromHand);
  scene.exact = &exact;
  GraspResult expected;
  REQUIRE((*solver)->solve(scene, expected) == Status::ok);

  GraspSession session(makeCpuSdfBackend(1));
  REQUIRE(session.configure(settings) == Status::ok);
  REQUIRE(session.addTarget(7, sphere) == Status::ok);
  REQUIRE(session.waitWorkerIdle(20s));
  REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
  // Holding from the squeeze; the solve arrives later.
  CHECK(session.grasp(Hand::right).holding);
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.grasp(Hand::right).shown(); }));
  const HandGrasp& g = session.grasp(Hand::right);
  CHECK(g.solves == 1);
  CHECK(contacts(g) >= 3);
  CHECK(session.buildStats().cpuBuilds == 1);
  // Same solver, same field, same exact check: the same curls.
  for (int f = 0; f < kFingerCount; ++f) {
    CAPTURE(f);
    CHECK(g.result.fingers[f].curl == Approx(expected.fingers[f].curl).margin(1e-6));
    CHECK(g.result.fingers[f].contact == expected.fingers[f].contact);
  }
  // Nothing moved: no new job.
  REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
  REQUIRE(session.waitWorkerIdle(20s));
  REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
  CHECK(session.grasp(Hand::right).solves == 1);
}

TEST_CASE("A target still being set up is not grabbed", "[grasp_worker][core]") {
  auto open = std::make_shared<std::atomic<bool>>(true);
  GraspSession session(std::make_unique<GatedBackend>(open));
  REQUIRE(session.configure(oursSettings()) == Status::ok);
  // The worker is kept busy first: the left hand grabs target 5, whose build waits at the gate.
  // A set-up queued behind it cannot start, so target 7 is surely still pending below.
  REQUIRE(session.addTarget(5, makeSphere(0.04f, 2)) == Status::ok);
  REQUIRE(session.waitWorkerIdle(20s));
  open->store(false);
  HandFrame left = squeezing(1.0f);
  const TargetFrame five{5, true, Pose{}};
  REQUIRE(session.update(Hand::left, left, {&five, 1}) == Status::ok);
  REQUIRE(session.grasp(Hand::left).holding);
  REQUIRE(session.addTarget(7, makeSphere(0.04f, 3)) == Status::ok);
  const TargetFrame target{7, true, Pose{}};
  REQUIRE(session.targetSetup(7) == TargetSetup::pending);
  REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
  CHECK_FALSE(session.grasp(Hand::right).holding);
  CHECK(session.targetSetup(7) == TargetSetup::pending);
  // Once the worker is free the set-up runs, and the same squeeze grabs.
  open->store(true);
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.grasp(Hand::right).shown(); }));
  CHECK(session.targetSetup(7) == TargetSetup::ready);
}

TEST_CASE("A hand keeps its last solve while the next one runs, re-posed onto the target",
          "[grasp_worker][core]") {
  auto open = std::make_shared<std::atomic<bool>>(true);
  GraspSession session(std::make_unique<GatedBackend>(open));
  REQUIRE(session.configure(oursSettings()) == Status::ok);
  REQUIRE(session.addTarget(7, makeSphere(0.04f, 3)) == Status::ok);
  REQUIRE(session.waitWorkerIdle(20s));
  TargetFrame target{7, true, Pose{}};
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.grasp(Hand::right).shown(); }));
  const GraspResult first = session.grasp(Hand::right).result;
  CHECK_FALSE(session.reposeCorrection(Hand::right).has_value());

  // The target moves 1 cm; its re-solve is held on the worker.
  open->store(false);
  target.worldFromObject.position = glm::vec3(0.0f, 0.0f, 0.01f);
  REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
  for (int i = 0; i < 5; ++i) {
    REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    const HandGrasp& g = session.grasp(Hand::right);
    // Still holding, still the first solve: no open-hand flicker...
    REQUIRE(g.holding);
    REQUIRE(g.solves == 1);
    CHECK(g.result.fingers[1].curl == first.fingers[1].curl);
  }
  // ...shown where the hand was relative to the target at that solve: the correction maps the
  // solved hand frame into the current one, i.e. it moves the hand with the target.
  const auto c = session.reposeCorrection(Hand::right);
  REQUIRE(c.has_value());
  const Pose worldFromWrist = squeezing(1.0f).worldFromWrist;
  const glm::vec3 shifted = (worldFromWrist * *c).position - worldFromWrist.position;
  CHECK(shifted.x == Approx(0.0f).margin(1e-5));
  CHECK(shifted.y == Approx(0.0f).margin(1e-5));
  CHECK(shifted.z == Approx(0.01f).margin(1e-5));

  open->store(true);
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.grasp(Hand::right).solves >= 2; }));
  CHECK_FALSE(session.reposeCorrection(Hand::right).has_value());
}

TEST_CASE("New vertices are refit on the worker and re-solved", "[grasp_worker][core]") {
  GraspSession session(makeCpuSdfBackend(1));
  REQUIRE(session.configure(oursSettings()) == Status::ok);
  TriangleMesh sphere = makeSphere(0.04f, 3);
  REQUIRE(session.addTarget(7, sphere) == Status::ok);
  REQUIRE(session.waitWorkerIdle(20s));
  const TargetFrame target{7, true, Pose{}};
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.grasp(Hand::right).shown(); }));
  const float before = session.grasp(Hand::right).result.fingers[2].curl;
  // A smaller sphere: the fingers close further.
  std::vector<glm::vec3> smaller = sphere.positions;
  for (glm::vec3& p : smaller) p *= 0.75f;
  REQUIRE(session.updateTargetVertices(7, smaller) == Status::ok);
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.grasp(Hand::right).solves >= 2; }));
  CHECK(session.grasp(Hand::right).result.fingers[2].curl > before + 0.01f);
  CHECK(session.updateTargetVertices(7, std::vector<glm::vec3>(3)) != Status::ok);
}

TEST_CASE("Releasing, removing the target or destroying the session while a job runs is safe",
          "[grasp_worker][core]") {
  auto open = std::make_shared<std::atomic<bool>>(true);
  const TargetFrame target{7, true, Pose{}};
  auto makeHeld = [&] {
    auto session = std::make_unique<GraspSession>(std::make_unique<GatedBackend>(open));
    REQUIRE(session->configure(oursSettings()) == Status::ok);
    REQUIRE(session->addTarget(7, makeSphere(0.04f, 3)) == Status::ok);
    REQUIRE(session->waitWorkerIdle(20s));
    open->store(false);  // the grab's build waits on the worker
    REQUIRE(session->update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    REQUIRE(session->grasp(Hand::right).holding);
    return session;
  };
  SECTION("releasing drops the result of the job in flight") {
    auto session = makeHeld();
    REQUIRE(session->update(Hand::right, squeezing(0.0f), {&target, 1}) == Status::ok);
    CHECK_FALSE(session->grasp(Hand::right).holding);
    open->store(true);
    REQUIRE(session->waitWorkerIdle(20s));
    REQUIRE(session->update(Hand::right, squeezing(0.0f), {&target, 1}) == Status::ok);
    CHECK_FALSE(session->grasp(Hand::right).holding);
    CHECK(session->grasp(Hand::right).solves == 0);
  }
  SECTION("removing the target lets go; the job ends on its own reference") {
    auto session = makeHeld();
    CHECK(session->removeTarget(7));
    CHECK_FALSE(session->grasp(Hand::right).holding);
    open->store(true);
    REQUIRE(session->waitWorkerIdle(20s));
    REQUIRE(session->update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    CHECK_FALSE(session->grasp(Hand::right).holding);
  }
  SECTION("destroying the session stops the build in flight and joins the worker") {
    auto stopped = std::make_shared<std::atomic<bool>>(false);
    auto calls = std::make_shared<std::atomic<int>>(0);
    auto session =
        std::make_unique<GraspSession>(std::make_unique<GatedBackend>(open, calls, stopped));
    GraspSettings settings = oursSettings();
    settings.buildTimeLimit = std::chrono::minutes(10);  // the deadline cannot be what ends it
    REQUIRE(session->configure(settings) == Status::ok);
    REQUIRE(session->addTarget(7, makeSphere(0.04f, 3)) == Status::ok);
    REQUIRE(session->waitWorkerIdle(20s));
    open->store(false);  // the grab's build waits on the worker until something stops it
    REQUIRE(session->update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    REQUIRE(session->grasp(Hand::right).holding);
    // Destroyed once the build is surely running (the gate has been reached).
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    while (calls->load() == 0 && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(1ms);
    REQUIRE(calls->load() == 1);
    session.reset();  // returns once the worker has ended; nothing runs after
    // The gate never opened and the deadline is ten minutes off: the destructor's stop flag is
    // what ended the build.
    CHECK(stopped->load());
  }
  SECTION("destroying the session with set-ups queued drops them") {
    open->store(true);
    auto session = std::make_unique<GraspSession>(std::make_unique<GatedBackend>(open));
    for (uint64_t id = 1; id <= 8; ++id)
      REQUIRE(session->addTarget(id, makeSphere(0.04f, 5)) == Status::ok);
    session.reset();
    SUCCEED("destroyed");
  }
}

TEST_CASE("A failing job leaves the hand open and the worker working", "[grasp_worker][core]") {
  // A backend that fails its first build, as a build over its time bound or out of memory would.
  class FailingOnce final : public SdfBackend {
   public:
    std::string_view name() const override { return "failing-once"; }
    using SdfBackend::build;
    Status build(const MeshDistance& t, const Pose& p, const GridBox& b, SdfGrid& out,
                 const WorkLimit&) override {
      if (!failed_) {
        failed_ = true;
        throw std::bad_alloc();
      }
      return cpu_->build(t, p, b, out);
    }

   private:
    bool failed_ = false;
    std::unique_ptr<SdfBackend> cpu_ = makeCpuSdfBackend(1);
  };
  GraspSession session(std::make_unique<FailingOnce>());
  REQUIRE(session.configure(oursSettings()) == Status::ok);
  REQUIRE(session.addTarget(7, makeSphere(0.04f, 3)) == Status::ok);
  REQUIRE(session.waitWorkerIdle(20s));
  const TargetFrame target{7, true, Pose{}};
  REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
  REQUIRE(session.waitWorkerIdle(20s));
  CHECK(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::out_of_memory);
  CHECK_FALSE(session.grasp(Hand::right).holding);
  // The next squeeze grabs again.
  session.release(Hand::right);
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.grasp(Hand::right).shown(); }));
}

TEST_CASE("A mesh the worker cannot set up is reported once and never grabbed",
          "[grasp_worker][core]") {
  GraspWorker worker(makeCpuSdfBackend(1));
  TriangleMesh bad;  // no triangles: MeshDistance refuses it
  bad.positions = {glm::vec3(0.0f), glm::vec3(1.0f, 0, 0), glm::vec3(0, 1.0f, 0)};
  worker.addTarget(3, bad);
  REQUIRE(worker.waitIdle(20s));
  const GraspWorker::TargetInfo info = worker.targetInfo(3);
  CHECK(info.setup == TargetSetup::failed);
  CHECK_FALSE(info.error.empty());
  CHECK(worker.setupsDone() == 1);
}

TEST_CASE("A rigid motion of a held target re-solves on the field already built",
          "[grasp_worker][core]") {
  const TriangleMesh sphere = makeSphere(0.04f, 3);
  GraspSession session(makeCpuSdfBackend(1));
  REQUIRE(session.configure(oursSettings()) == Status::ok);
  REQUIRE(session.addTarget(7, sphere) == Status::ok);
  REQUIRE(session.waitWorkerIdle(20s));
  TargetFrame target{7, true, Pose{}};
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.grasp(Hand::right).shown(); }));
  REQUIRE(session.buildStats().cpuBuilds == 1);

  // The target starts moving in the hand: its next field is built in a grown box...
  target.worldFromObject.position = glm::vec3(0.002f, 0.0f, 0.0f);
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.grasp(Hand::right).solves >= 2; }));
  CHECK(session.buildStats().cpuBuilds == 2);
  // ...which the next rigid motion (3 mm more and 2 degrees) solves on without a build.
  target.worldFromObject.position = glm::vec3(0.005f, 0.0f, 0.0f);
  target.worldFromObject.orientation = glm::angleAxis(glm::radians(2.0f), glm::vec3(0, 1, 0));
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.grasp(Hand::right).solves >= 3; }));
  CHECK(session.buildStats().cpuBuilds == 2);
  CHECK(session.buildStats().reusedFields == 1);
  const GraspResult reused = session.grasp(Hand::right).result;

  // The same placement solved on a field built for it: the same contacts, within what the exact
  // check guarantees (its stops are on the mesh itself, 0.1 mm).
  GraspSession fresh(makeCpuSdfBackend(1));
  REQUIRE(fresh.configure(oursSettings()) == Status::ok);
  REQUIRE(fresh.addTarget(7, sphere) == Status::ok);
  REQUIRE(fresh.waitWorkerIdle(20s));
  REQUIRE(updateUntil(fresh, squeezing(1.0f), target,
                      [&] { return fresh.grasp(Hand::right).shown(); }));
  const GraspResult& expected = fresh.grasp(Hand::right).result;
  REQUIRE(fresh.grasp(Hand::right).solves == 1);
  REQUIRE(fresh.buildStats().reusedFields == 0);
  for (int f = 0; f < kFingerCount; ++f) {
    CAPTURE(f);
    CHECK(reused.fingers[f].contact == expected.fingers[f].contact);
    if (!expected.fingers[f].contact) continue;
    CHECK(glm::length(reused.fingers[f].contactPoint - expected.fingers[f].contactPoint) < 0.0005f);
  }

  // 15 cm away the field built does not hold the box: a new build.
  target.worldFromObject = Pose{};
  target.worldFromObject.position = glm::vec3(0.0f, 0.0f, 0.15f);
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.buildStats().cpuBuilds == 3; }));
  CHECK(session.buildStats().reusedFields == 1);

  // New vertices are a new object: a new build.
  std::vector<glm::vec3> smaller = sphere.positions;
  for (glm::vec3& p : smaller) p *= 0.9f;
  target.worldFromObject = Pose{};
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.buildStats().cpuBuilds >= 4; }));
  const uint64_t builds = session.buildStats().cpuBuilds;
  REQUIRE(session.updateTargetVertices(7, smaller) == Status::ok);
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.buildStats().cpuBuilds > builds; }));
}

TEST_CASE("A build over its time bound is given up once per squeeze", "[grasp_worker][core]") {
  // The gate never opens: every build runs into its bound (50 ms here, 1 s by default).
  auto open = std::make_shared<std::atomic<bool>>(false);
  auto calls = std::make_shared<std::atomic<int>>(0);
  GraspSession session(std::make_unique<GatedBackend>(open, calls));
  GraspSettings settings = oursSettings();
  settings.buildTimeLimit = 50ms;
  REQUIRE(session.configure(settings) == Status::ok);
  REQUIRE(session.addTarget(7, makeSphere(0.04f, 3)) == Status::ok);
  REQUIRE(session.waitWorkerIdle(20s));
  const TargetFrame target{7, true, Pose{}};
  REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
  REQUIRE(session.grasp(Hand::right).holding);
  REQUIRE(session.waitWorkerIdle(20s));
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  Status seen = Status::ok;
  while (seen == Status::ok && std::chrono::steady_clock::now() < deadline)
    seen = session.update(Hand::right, squeezing(1.0f), {&target, 1});
  CHECK(seen == Status::timed_out);
  CHECK_FALSE(session.grasp(Hand::right).holding);
  // Still squeezing: no new grab, so no new build and no new failure to log.
  CHECK(calls->load() == 1);
  for (int i = 0; i < 20; ++i) {
    CHECK(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    CHECK_FALSE(session.grasp(Hand::right).holding);
  }
  REQUIRE(session.waitWorkerIdle(20s));
  CHECK(calls->load() == 1);
  // Released and squeezed again, with the gate open: the grab succeeds. The bound goes back to a
  // generous one first: a real build of this sphere can take more than 50 ms on a loaded machine
  // under a sanitizer, which is the case above, not this one.
  REQUIRE(session.update(Hand::right, squeezing(0.0f), {&target, 1}) == Status::ok);
  settings.buildTimeLimit = 20s;
  REQUIRE(session.configure(settings) == Status::ok);
  open->store(true);
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.grasp(Hand::right).shown(); }));
}

TEST_CASE("Settings refuse a build time bound that is not positive", "[grasp_worker][core]") {
  GraspSettings settings = oursSettings();
  settings.buildTimeLimit = 0ms;
  CHECK(settings.validate().has_value());
  GraspSession session(makeCpuSdfBackend(1));
  CHECK(session.configure(settings) == Status::invalid_argument);
}

TEST_CASE("New vertices that collapse a triangle are refused on the worker, once per run",
          "[grasp_worker][core]") {
  GraspSession session(makeCpuSdfBackend(1));
  REQUIRE(session.configure(oursSettings()) == Status::ok);
  const TriangleMesh sphere = makeSphere(0.04f, 3);
  REQUIRE(session.addTarget(7, sphere) == Status::ok);
  REQUIRE(session.waitWorkerIdle(20s));
  const TargetFrame target{7, true, Pose{}};
  REQUIRE(updateUntil(session, squeezing(1.0f), target,
                      [&] { return session.grasp(Hand::right).shown(); }));
  const float curl = session.grasp(Hand::right).result.fingers[2].curl;
  // Triangle 0's corners all at one point; the sphere otherwise shrunk, which the hand would
  // close further on if the update were taken.
  std::vector<glm::vec3> collapsed = sphere.positions;
  for (glm::vec3& p : collapsed) p *= 0.75f;
  for (int k = 0; k < 3; ++k) collapsed[sphere.indices[size_t(k)]] = collapsed[sphere.indices[0]];
  auto applyAndWait = [&](const std::vector<glm::vec3>& positions) {
    const uint64_t solves = session.grasp(Hand::right).solves;
    REQUIRE(session.updateTargetVertices(7, positions) == Status::ok);
    REQUIRE(updateUntil(session, squeezing(1.0f), target,
                        [&] { return session.grasp(Hand::right).solves > solves; }));
  };
  applyAndWait(collapsed);
  // The hand still holds, on the last accepted shape.
  CHECK(session.grasp(Hand::right).holding);
  CHECK(session.grasp(Hand::right).result.fingers[2].curl == Approx(curl).margin(1e-4));
  auto refused = session.takeRefusedUpdates();
  REQUIRE(refused.size() == 1);
  CHECK(refused[0].first == 7);
  CHECK(refused[0].second.find("zero area") != std::string::npos);
  applyAndWait(collapsed);  // the same run: not reported again
  CHECK(session.takeRefusedUpdates().empty());
  // Accepted positions end the run; the next refusal is reported again.
  std::vector<glm::vec3> smaller = sphere.positions;
  for (glm::vec3& p : smaller) p *= 0.75f;
  applyAndWait(smaller);
  CHECK(session.grasp(Hand::right).result.fingers[2].curl > curl + 0.01f);
  CHECK(session.takeRefusedUpdates().empty());
  applyAndWait(collapsed);
  CHECK(session.takeRefusedUpdates().size() == 1);
}

TEST_CASE("An outer-hand job runs before set-ups queued ahead of it", "[grasp_worker][core]") {
  // Held, the worker starts nothing: three mesh set-ups are queued, then one frame's outer job
  // for a hand resting on a table top. Let go, the outer job runs first: it waits for no set-up.
  GraspWorker worker(makeCpuSdfBackend(1));
  worker.hold(true);
  const AnalyticShape table{ShapeKind::box, glm::vec3(0.5f, 0.02f, 0.5f)};
  worker.addShape(1, table);
  for (uint64_t id = 2; id <= 4; ++id) worker.addTarget(id, makeTorus());
  GraspWorker::OuterJob job;
  job.ticket = 1;
  GraspWorker::JobMember member;
  member.target = 1;
  member.objectFromHand = Pose{glm::quat(1, 0, 0, 0), glm::vec3(0.0f, 0.02f, 0.0f)};
  job.members.push_back(member);
  job.worldFromWrist = Pose{glm::quat(1, 0, 0, 0), glm::vec3(0.0f, 0.05f, 0.0f)};
  const HandModel model = HandModel::defaultAdult(Hand::right);
  JointRadii radii{};
  placeJoints(model, FingerCurls{}, Pose{}, job.joints, radii);
  job.radii = radii;
  job.model = model;
  worker.requestOuter(0, std::move(job));
  // Held: nothing runs, so waiting for idle times out.
  CHECK_FALSE(worker.waitIdle(std::chrono::milliseconds(50)));
  CHECK(worker.setupsDone() == 0);
  CHECK(worker.outerMailbox(0)->latest.load() == nullptr);
  worker.hold(false);
  REQUIRE(worker.waitIdle(std::chrono::seconds(60)));
  const auto done = worker.outerMailbox(0)->latest.load();
  REQUIRE(done != nullptr);
  CHECK(done->ticket == 1);
  CHECK(done->status == Status::ok);
  CHECK(done->setupsBefore == 0);
  CHECK(worker.setupsDone() == 3);
  for (uint64_t id = 2; id <= 4; ++id) CHECK(worker.targetInfo(id).setup == TargetSetup::ready);
}
