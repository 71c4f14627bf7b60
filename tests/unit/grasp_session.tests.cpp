// GraspSession with a deferred SDF backend (the layer's Vulkan path, here a CPU stand-in that
// counts its calls): builds are requested in update(), run only at submitDeferred(), collected
// by a later update() and solved on the session's worker; a device failure has the worker redo
// the build on the CPU at once. Every wait for the worker is for an outcome, with a time bound.
#include <catch2/catch.hpp>

#include <chrono>
#include <thread>

#include "grasp/grasp_session.h"
#include "io/shapes.h"
#include "sdf/sdf_cpu.h"

namespace {

using namespace sdfg;

class FakeDeferred final : public DeferredSdfBackend {
 public:
  std::string_view name() const override { return "fake"; }
  Status request(size_t slot, uint64_t, uint64_t, const TriangleMesh* mesh, const Pose& pose,
                 const GridBox& box) override {
    if (failed_) return Status::device_lost;
    if (slot >= kSlots || mesh == nullptr) return Status::invalid_argument;
    Slot& s = slots_[slot];
    if (s.recorded || s.submitted) return Status::unsupported;
    auto distance = MeshDistance::create(*mesh);
    if (!distance) return Status::invalid_argument;
    s.distance = std::move(distance.value());
    s.pose = pose;
    s.box = box;
    s.recorded = true;
    ++requests;
    return Status::ok;
  }
  bool hasDeviceMesh(uint64_t id) const override { return id != 0 && id == deviceMeshId; }
  bool needsSubmit(bool) const override {
    return !failed_ && (slots_[0].recorded || slots_[1].recorded);
  }
  Status submit(bool) override {
    for (Slot& s : slots_) {
      if (!s.recorded) continue;
      s.recorded = false;
      s.submitted = true;
      ++submits;
    }
    return Status::ok;
  }
  BuildPoll poll(size_t slot, SdfGrid& out) override {
    if (failed_) return BuildPoll::failed;
    Slot& s = slots_[slot];
    if (s.recorded) return BuildPoll::pending;
    if (!s.submitted) return BuildPoll::idle;
    if (busy) return BuildPoll::pending;
    if (failAtPoll) {
      failed_ = true;
      return BuildPoll::failed;
    }
    s.submitted = false;
    if (s.discard) {
      s.discard = false;
      return BuildPoll::idle;
    }
    REQUIRE(cpu.build(*s.distance, s.pose, s.box, out) == Status::ok);
    return BuildPoll::ready;
  }
  void cancel(size_t slot) override {
    slots_[slot].recorded = false;
    if (slots_[slot].submitted) slots_[slot].discard = true;
    ++cancels;
  }
  bool failed() const override { return failed_; }
  bool ready() override {
    ++readyCalls;
    if (failPreparation) failed_ = true;
    return !preparing && !failed_;
  }

  bool preparing = false;        // still making its pipelines (ready() false)
  bool failPreparation = false;  // the preparation fails at the next ready()
  uint64_t deviceMeshId = 0;     // a target registered as living on the device
  int readyCalls = 0;
  bool failAtPoll = false;
  bool busy = false;  // the device has not finished yet
  int requests = 0, submits = 0, cancels = 0;

 private:
  struct Slot {
    std::unique_ptr<MeshDistance> distance;
    Pose pose;
    GridBox box;
    bool recorded = false, submitted = false, discard = false;
  };
  std::array<Slot, kSlots> slots_;
  CpuSdfBuilder cpu{1};
  bool failed_ = false;
};

// A right hand whose grab box is centred on a 4 cm sphere at the origin, squeezing.
HandFrame squeezing(float squeeze) {
  HandFrame f;
  f.valid = true;
  f.squeeze = squeeze;
  f.worldFromWrist = GridBox::referenceDefault().handFromBox.inverse();
  return f;
}

// Updates the squeezing hand until `done` holds, at most 20 s; true when it held.
template <class F>
bool updateUntil(GraspSession& session, const TargetFrame& target, F done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < deadline) {
    REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

// Adds a 4 cm sphere as target 7 and waits for its set-up on the worker.
void addSphere(GraspSession& session) {
  REQUIRE(session.addTarget(7, makeSphere(0.04f, 3)) == Status::ok);
  REQUIRE(session.waitWorkerIdle(std::chrono::seconds(20)));
  REQUIRE(session.targetSetup(7) == TargetSetup::ready);
}

}  // namespace

TEST_CASE("GraspSession with a deferred backend solves only after the owner submits",
          "[grasp_session][deferred]") {
  auto owned = std::make_unique<FakeDeferred>();
  FakeDeferred& gpu = *owned;
  GraspSession session(makeCpuSdfBackend(1), std::move(owned));
  addSphere(session);
  const TargetFrame target{7, true, Pose{}};

  REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
  CHECK(session.grasp(Hand::right).holding);
  CHECK(session.grasp(Hand::right).solves == 0);
  CHECK(gpu.requests == 1);
  CHECK(session.pendingBuilds() == 1);
  CHECK(session.needsSubmit(true));

  SECTION("nothing is built until submitDeferred") {
    REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    CHECK(session.grasp(Hand::right).solves == 0);
    CHECK(gpu.requests == 1);  // one request at a time
    CHECK(gpu.submits == 0);
  }
  SECTION("the result is collected at the next update and solved on the worker") {
    REQUIRE(session.submitDeferred(true) == Status::ok);
    CHECK(gpu.submits == 1);
    REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    CHECK(session.pendingBuilds() == 0);  // collected
    REQUIRE(updateUntil(session, target, [&] { return session.grasp(Hand::right).shown(); }));
    const HandGrasp& g = session.grasp(Hand::right);
    CHECK(g.solves == 1);
    CHECK(g.builtOnGpu);
    CHECK(session.buildStats().gpuBuilds == 1);
    CHECK(session.buildStats().cpuBuilds == 0);
    int contacts = 0;
    for (const FingerState& f : g.result.fingers) contacts += f.contact ? 1 : 0;
    CHECK(contacts >= 3);
    // Nothing moved: no new request.
    REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    CHECK(gpu.requests == 1);
  }
  SECTION("a device failure at the poll has the worker redo the build on the CPU at once") {
    REQUIRE(session.submitDeferred(true) == Status::ok);
    gpu.failAtPoll = true;
    REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    CHECK(session.buildStats().gpuFailed);
    REQUIRE(updateUntil(session, target, [&] { return session.grasp(Hand::right).shown(); }));
    const HandGrasp& g = session.grasp(Hand::right);
    CHECK(g.solves == 1);
    CHECK_FALSE(g.builtOnGpu);
    CHECK(session.buildStats().gpuFailed);
    CHECK(session.buildStats().cpuBuilds == 1);
    CHECK_FALSE(session.deferredUsable());
    // Later builds go to the CPU at once.
    session.release(Hand::right);
    REQUIRE(updateUntil(session, target, [&] { return session.grasp(Hand::right).shown(); }));
    CHECK(session.grasp(Hand::right).solves == 1);
    CHECK(session.buildStats().cpuBuilds == 2);
    CHECK(gpu.requests == 1);
  }
  SECTION("releasing the squeeze cancels the build in flight") {
    REQUIRE(session.submitDeferred(true) == Status::ok);
    gpu.busy = true;
    REQUIRE(session.update(Hand::right, squeezing(0.0f), {&target, 1}) == Status::ok);
    CHECK_FALSE(session.grasp(Hand::right).holding);
    CHECK(gpu.cancels == 1);
    CHECK(session.pendingBuilds() == 0);
    // Its result, when the device finishes, is dropped; a new grab asks again.
    gpu.busy = false;
    REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    CHECK(session.grasp(Hand::right).solves == 0);
    CHECK(session.buildStats().gpuBuilds == 0);
  }
  SECTION("a device build not done within the time bound is given up until a release") {
    GraspSettings settings;
    settings.buildTimeLimit = std::chrono::milliseconds(30);
    REQUIRE(session.configure(settings) == Status::ok);  // drops the build in flight
    REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    REQUIRE(session.submitDeferred(true) == Status::ok);
    gpu.busy = true;  // the device never finishes
    const int cancels = gpu.cancels;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    Status seen = Status::ok;
    while (seen == Status::ok && std::chrono::steady_clock::now() < deadline)
      seen = session.update(Hand::right, squeezing(1.0f), {&target, 1});
    CHECK(seen == Status::timed_out);
    CHECK_FALSE(session.grasp(Hand::right).holding);
    CHECK(gpu.cancels == cancels + 1);
    // Still squeezing: no new request; after a release, a new grab asks again.
    const int requests = gpu.requests;
    REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    CHECK(gpu.requests == requests);
    gpu.busy = false;
    REQUIRE(session.update(Hand::right, squeezing(0.0f), {&target, 1}) == Status::ok);
    REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    CHECK(session.grasp(Hand::right).holding);
  }
  SECTION("a device target needs a backend that holds its mesh") {
    CHECK(session.addDeviceTarget(9, Aabb{glm::vec3(-0.1f), glm::vec3(0.1f)}) ==
          Status::unsupported);
    CHECK_FALSE(session.hasTarget(9));
  }
}

TEST_CASE("While the deferred backend prepares, array targets build on the CPU at once",
          "[grasp_session][deferred]") {
  auto owned = std::make_unique<FakeDeferred>();
  FakeDeferred& gpu = *owned;
  gpu.preparing = true;
  gpu.deviceMeshId = 9;
  GraspSession session(makeCpuSdfBackend(1), std::move(owned));
  addSphere(session);
  const TargetFrame target{7, true, Pose{}};
  CHECK_FALSE(session.deferredReady());
  CHECK(session.deferredUsable());

  SECTION("an array target is built on the CPU at once, not kept waiting for the device") {
    REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    CHECK(session.grasp(Hand::right).holding);
    REQUIRE(updateUntil(session, target, [&] { return session.grasp(Hand::right).shown(); }));
    CHECK(session.grasp(Hand::right).solves == 1);
    CHECK_FALSE(session.grasp(Hand::right).builtOnGpu);
    CHECK(session.buildStats().cpuBuilds == 1);
    CHECK(gpu.requests == 0);
    CHECK_FALSE(session.buildStats().gpuFailed);
    // Once ready, the next grab goes to the device.
    session.release(Hand::right);
    gpu.preparing = false;
    REQUIRE(session.update(Hand::right, squeezing(1.0f), {&target, 1}) == Status::ok);
    CHECK(gpu.requests == 1);
    CHECK(session.buildStats().cpuBuilds == 1);
  }
  SECTION("a device target waits for the backend, holding with no solve") {
    Aabb bounds;
    bounds.min = glm::vec3(-0.04f);
    bounds.max = glm::vec3(0.04f);
    REQUIRE(session.removeTarget(7));
    REQUIRE(session.addDeviceTarget(9, bounds) == Status::ok);
    const TargetFrame device{9, true, Pose{}};
    for (int i = 0; i < 3; ++i)
      REQUIRE(session.update(Hand::right, squeezing(1.0f), {&device, 1}) == Status::ok);
    CHECK(session.grasp(Hand::right).holding);
    CHECK(session.grasp(Hand::right).solves == 0);
    CHECK(gpu.requests == 0);
    CHECK(session.buildStats().cpuBuilds == 0);
    CHECK(gpu.readyCalls >= 3);  // asked again at every update
  }
  SECTION("a failed preparation counts as a GPU failure; the CPU builds from then on") {
    gpu.failPreparation = true;
    REQUIRE(updateUntil(session, target, [&] { return session.grasp(Hand::right).shown(); }));
    CHECK(session.grasp(Hand::right).solves == 1);
    CHECK(session.buildStats().gpuFailed);
    CHECK_FALSE(session.deferredUsable());
    CHECK(gpu.requests == 0);
  }
}
