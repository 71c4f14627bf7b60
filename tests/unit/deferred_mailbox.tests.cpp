// DeferredMailbox: the owner's side never calls the device; pump() does, one pump at a time and
// never waiting for another; exclusive() and shutdown() wait for a pump in progress, at most their
// bound; a device call that throws gives the device back.
#include <catch2/catch.hpp>

#include <array>
#include <atomic>
#include <chrono>
#include <future>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "io/shapes.h"
#include "sdf/deferred_mailbox.h"

namespace {

using namespace sdfg;
using namespace std::chrono_literals;

// A device that records its calls and the thread each came from. A build is recorded by
// request(), submitted by submit() and done when the test says so (finish()). ready() can be made
// to block on a gate, to hold a pump inside a device call.
class FakeDevice final : public DeferredSdfBackend {
 public:
  struct Log {
    std::atomic<int> requests{0}, submits{0}, cancels{0}, polls{0}, readyCalls{0};
    std::atomic<bool> destroyed{false};
    std::atomic<bool> gateClosed{false};
    std::atomic<bool> inReady{false};
    std::atomic<bool> failNext{false};
    std::atomic<bool> throwInReady{false};  // the next ready() throws
    std::atomic<bool> readbacks{false};     // requestReadback answers (else: unsupported)
    std::vector<glm::vec3> lastMesh;        // the positions of the last request with a mesh
    std::vector<std::thread::id> callers;   // written by the pumping thread only
    std::vector<std::string> order;
  };
  explicit FakeDevice(std::shared_ptr<Log> log) : log_(std::move(log)) {}
  ~FakeDevice() override { log_->destroyed = true; }
  std::string_view name() const override { return "fake"; }
  Status request(size_t slot, uint64_t id, uint64_t, const TriangleMesh* mesh, const Pose&,
                 const GridBox& box) override {
    note("request");
    if (mesh != nullptr) log_->lastMesh = mesh->positions;
    if (log_->failNext) {
      failed_ = true;
      return Status::device_lost;
    }
    if (slots_[slot].recorded || slots_[slot].submitted) return Status::unsupported;
    slots_[slot] = Slot{true, false, false, false, id, box};
    ++log_->requests;
    return Status::ok;
  }
  bool hasDeviceMesh(uint64_t) const override { return false; }
  bool needsSubmit(bool sharedQueueFree) const override {
    return sharedQueueFree && (slots_[0].recorded || slots_[1].recorded);
  }
  Status submit(bool sharedQueueFree) override {
    note("submit");
    if (!sharedQueueFree) return Status::ok;
    for (Slot& s : slots_) {
      if (!s.recorded) continue;
      s.recorded = false;
      s.submitted = true;
      ++log_->submits;
    }
    return Status::ok;
  }
  BuildPoll poll(size_t slot, SdfGrid& out) override {
    note("poll");
    ++log_->polls;
    if (failed_) return BuildPoll::failed;
    Slot& s = slots_[slot];
    if (s.recorded || (s.submitted && !s.done)) return BuildPoll::pending;
    if (!s.submitted) return BuildPoll::idle;
    const bool discard = s.discard;
    s = Slot{};
    if (discard) return BuildPoll::idle;
    out = SdfGrid(GridBox::referenceDefault());
    return BuildPoll::ready;
  }
  void cancel(size_t slot) override {
    note("cancel");
    ++log_->cancels;
    slots_[slot].recorded = false;
    if (slots_[slot].submitted) slots_[slot].discard = true;
  }
  bool failed() const override { return failed_; }
  bool ready() override {
    note("ready");
    ++log_->readyCalls;
    if (log_->throwInReady.exchange(false)) throw std::runtime_error("the fake device threw");
    log_->inReady = true;
    while (log_->gateClosed) std::this_thread::sleep_for(1ms);
    log_->inReady = false;
    return true;
  }
  Status requestReadback(uint64_t id, uint64_t generation) override {
    note("readback");
    if (!log_->readbacks) return Status::unsupported;
    readbacks_.push_back(MeshReadback{id, generation, {glm::vec3(1.0f)}, {}});
    return Status::ok;
  }
  std::vector<MeshReadback> takeReadbacks() override { return std::exchange(readbacks_, {}); }
  void finish(size_t slot) { slots_[slot].done = true; }

 private:
  struct Slot {
    bool recorded = false, submitted = false, done = false, discard = false;
    uint64_t id = 0;
    GridBox box;
  };
  void note(const char* what) {
    log_->callers.push_back(std::this_thread::get_id());
    log_->order.emplace_back(what);
  }
  std::shared_ptr<Log> log_;
  std::array<Slot, kSlots> slots_;
  std::vector<MeshReadback> readbacks_;
  bool failed_ = false;
};

struct Fixture {
  std::shared_ptr<FakeDevice::Log> log = std::make_shared<FakeDevice::Log>();
  FakeDevice* device = nullptr;
  std::shared_ptr<DeferredMailbox> mailbox;
  std::unique_ptr<DeferredSdfBackend> owner;
  explicit Fixture(std::chrono::milliseconds claimWait = DeferredMailbox::kClaimWait) {
    auto d = std::make_unique<FakeDevice>(log);
    device = d.get();
    mailbox = std::make_shared<DeferredMailbox>(std::move(d), claimWait);
    owner = DeferredMailbox::ownerSide(mailbox);
  }
  // Starts a pump on another thread and waits (bounded) until it is inside the device, held
  // there until the gate opens.
  std::future<bool> holdPump() {
    log->gateClosed = true;
    auto held = std::async(std::launch::async, [m = mailbox] { return m->pump(true); });
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    while (!log->inReady && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(1ms);
    REQUIRE(log->inReady);
    return held;
  }
};

// Runs `f` on a thread of its own and waits for it at most `bound` (generous: a loaded machine
// under the sanitizers): its result, or nothing when it did not return. A call that never returns
// is left behind (detached, with what `f` captured by value) so that the test fails instead of
// hanging.
template <class F>
auto returnsWithin(std::chrono::seconds bound, F f) -> std::optional<decltype(f())> {
  auto result = std::make_shared<std::promise<decltype(f())>>();
  auto returned = result->get_future();
  std::thread([result, call = std::optional<F>(std::move(f))]() mutable {
    auto value = (*call)();
    call.reset();  // what it captured goes before the caller hears of the result
    result->set_value(std::move(value));
  }).detach();
  if (returned.wait_for(bound) != std::future_status::ready) return std::nullopt;
  return returned.get();
}

// Opens the fake device's gate when the test leaves, also through a failed REQUIRE: a pump held
// there would otherwise never end.
struct GateOpener {
  std::shared_ptr<FakeDevice::Log> log;
  ~GateOpener() { log->gateClosed = false; }
};

const TriangleMesh& sphere() {
  static const TriangleMesh m = makeSphere(0.04f, 2);
  return m;
}

}  // namespace

TEST_CASE("The owner's side never calls the device: pumps do, and carry results back",
          "[core][deferred_mailbox]") {
  Fixture f;
  const GridBox box = GridBox::referenceDefault();
  // Not ready until a pump has asked the device.
  CHECK_FALSE(f.owner->ready());
  REQUIRE(f.mailbox->pump(false));
  CHECK(f.owner->ready());
  const size_t callsBefore = f.log->order.size();

  REQUIRE(f.owner->request(1, 7, 1, &sphere(), Pose{}, box) == Status::ok);
  SdfGrid grid;
  CHECK(f.owner->poll(1, grid) == BuildPoll::pending);
  f.owner->cancel(0);                         // nothing on the device there: nothing to tell it
  CHECK(f.log->order.size() == callsBefore);  // not one device call from the owner's side
  CHECK(f.log->requests == 0);

  // A pump outside the frame records the build; only a pump inside it submits.
  REQUIRE(f.mailbox->pump(false));
  CHECK(f.log->requests == 1);
  CHECK(f.log->submits == 0);
  CHECK(f.log->cancels == 0);
  REQUIRE(f.mailbox->pump(true));
  CHECK(f.log->submits == 1);
  CHECK(f.owner->poll(1, grid) == BuildPoll::pending);
  f.device->finish(1);
  REQUIRE(f.mailbox->pump(false));
  CHECK(f.owner->poll(1, grid) == BuildPoll::ready);
  CHECK(grid.box().resolution == box.resolution);
  CHECK(f.owner->poll(1, grid) == BuildPoll::idle);
  // Every device call came from a pumping thread: here, this one.
  for (const auto& id : f.log->callers) CHECK(id == std::this_thread::get_id());
}

TEST_CASE("A pump that finds another running returns at once instead of waiting",
          "[core][deferred_mailbox]") {
  Fixture f;
  f.log->gateClosed = true;
  auto held = std::async(std::launch::async, [&] { return f.mailbox->pump(true); });
  // Wait (bounded) until the other pump is inside the device.
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (!f.log->inReady && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(1ms);
  REQUIRE(f.log->inReady);
  // The gate is still closed: this pump can only return because it did not wait.
  CHECK_FALSE(f.mailbox->pump(true));
  CHECK(f.log->inReady);
  // Recording and polling on the owner's side do not wait either.
  REQUIRE(f.owner->request(0, 7, 1, &sphere(), Pose{}, GridBox::referenceDefault()) == Status::ok);
  SdfGrid grid;
  CHECK(f.owner->poll(0, grid) == BuildPoll::pending);
  f.log->gateClosed = false;
  CHECK(held.get());
  // The request recorded meanwhile goes down at the next pump.
  REQUIRE(f.mailbox->pump(true));
  CHECK(f.log->requests == 1);
  CHECK(f.log->submits == 1);
}

TEST_CASE("A cancel reaches the device at the next pump and its result is dropped",
          "[core][deferred_mailbox]") {
  Fixture f;
  REQUIRE(f.mailbox->pump(false));
  REQUIRE(f.owner->request(0, 7, 1, &sphere(), Pose{}, GridBox::referenceDefault()) == Status::ok);
  REQUIRE(f.mailbox->pump(true));  // recorded and submitted
  f.owner->cancel(0);
  // The device is still busy with the cancelled build: a new request waits for it.
  CHECK(f.owner->request(0, 7, 1, &sphere(), Pose{}, GridBox::referenceDefault()) ==
        Status::unsupported);
  REQUIRE(f.mailbox->pump(true));
  CHECK(f.log->cancels == 1);
  f.device->finish(0);
  REQUIRE(f.mailbox->pump(true));
  SdfGrid grid;
  CHECK(f.owner->poll(0, grid) == BuildPoll::idle);
  CHECK(f.owner->request(0, 7, 1, &sphere(), Pose{}, GridBox::referenceDefault()) == Status::ok);
}

TEST_CASE("exclusive runs the posted calls first, after the pump in progress",
          "[core][deferred_mailbox]") {
  Fixture f;
  std::vector<std::string> seen;
  f.mailbox->post([&](DeferredSdfBackend&) { seen.push_back("posted"); });
  f.log->gateClosed = true;
  auto held = std::async(std::launch::async, [&] { return f.mailbox->pump(false); });
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (!f.log->inReady && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(1ms);
  REQUIRE(f.log->inReady);
  // The pump took the posted call before entering the device.
  REQUIRE(seen == std::vector<std::string>{"posted"});
  f.mailbox->post([&](DeferredSdfBackend&) { seen.push_back("posted later"); });
  auto exclusive = std::async(std::launch::async, [&] {
    f.mailbox->exclusive([&](DeferredSdfBackend&) { seen.push_back("exclusive"); });
  });
  // It waits for the pump: nothing more has run while the gate is closed.
  CHECK(exclusive.wait_for(50ms) == std::future_status::timeout);
  f.log->gateClosed = false;
  CHECK(held.get());
  exclusive.get();
  CHECK(seen == std::vector<std::string>{"posted", "posted later", "exclusive"});
}

TEST_CASE("A device failure shows on the owner's side, and shutdown destroys the device",
          "[core][deferred_mailbox]") {
  Fixture f;
  REQUIRE(f.mailbox->pump(false));
  f.log->failNext = true;
  REQUIRE(f.owner->request(0, 7, 1, &sphere(), Pose{}, GridBox::referenceDefault()) == Status::ok);
  REQUIRE(f.mailbox->pump(false));
  CHECK(f.owner->failed());
  SdfGrid grid;
  CHECK(f.owner->poll(0, grid) == BuildPoll::failed);
  CHECK(f.owner->request(0, 7, 1, &sphere(), Pose{}, GridBox::referenceDefault()) ==
        Status::device_lost);
  CHECK(f.mailbox->shutdown());
  CHECK(f.log->destroyed);
  CHECK_FALSE(f.mailbox->pump(true));
  bool ran = false;
  CHECK(f.mailbox->exclusive([&](DeferredSdfBackend&) { ran = true; }) ==
        DeferredMailbox::Access::shut_down);
  CHECK_FALSE(ran);
}

TEST_CASE(
    "A device call that throws in a pump gives the device back, and what it did not reach "
    "runs at the next pump",
    "[core][deferred_mailbox]") {
  Fixture f;
  REQUIRE(f.mailbox->pump(false));
  std::vector<std::string> seen;
  std::vector<std::string> afterNextPump;
  REQUIRE(f.owner->request(0, 7, 1, &sphere(), Pose{}, GridBox::referenceDefault()) == Status::ok);
  SECTION("the device throws") {
    f.mailbox->post([&](DeferredSdfBackend&) { seen.push_back("posted"); });
    f.log->throwInReady = true;
    CHECK_THROWS_AS(f.mailbox->pump(true), std::runtime_error);
    CHECK(seen == std::vector<std::string>{"posted"});
    afterNextPump = {"posted"};
  }
  SECTION("a posted call throws") {
    f.mailbox->post([](DeferredSdfBackend&) { throw std::runtime_error("posted call threw"); });
    f.mailbox->post([&](DeferredSdfBackend&) { seen.push_back("after it"); });
    CHECK_THROWS_AS(f.mailbox->pump(true), std::runtime_error);
    CHECK(seen.empty());
    f.mailbox->post([&](DeferredSdfBackend&) { seen.push_back("posted later"); });
    afterNextPump = {"after it", "posted later"};
  }
  CHECK(f.log->requests == 0);  // not reached: kept for the next pump
  SdfGrid grid;
  CHECK(f.owner->poll(0, grid) == BuildPoll::pending);
  CHECK_FALSE(f.owner->failed());
  // The next pump takes the device (it was given back) and does what the last one left.
  REQUIRE(f.mailbox->pump(true));
  CHECK(f.log->requests == 1);
  CHECK(f.log->submits == 1);
  CHECK(seen == afterNextPump);
  bool ran = false;
  CHECK(f.mailbox->exclusive([&](DeferredSdfBackend&) { ran = true; }) ==
        DeferredMailbox::Access::done);
  CHECK(ran);
  const auto destroyedInTime = returnsWithin(60s, [m = f.mailbox] { return m->shutdown(); });
  REQUIRE(destroyedInTime.has_value());
  CHECK(*destroyedInTime);
  CHECK(f.log->destroyed);
}

TEST_CASE("A call that throws in exclusive gives the device back", "[core][deferred_mailbox]") {
  Fixture f;
  std::vector<std::string> seen;
  f.mailbox->post([](DeferredSdfBackend&) { throw std::runtime_error("posted call threw"); });
  f.mailbox->post([&](DeferredSdfBackend&) { seen.push_back("after it"); });
  CHECK_THROWS_AS(f.mailbox->exclusive([&](DeferredSdfBackend&) { seen.push_back("call"); }),
                  std::runtime_error);
  CHECK(seen.empty());
  CHECK_THROWS_AS(f.mailbox->exclusive([](DeferredSdfBackend&) {
    throw std::runtime_error("exclusive call threw");
  }),
                  std::runtime_error);
  // The posted call after the one that threw ran before the call that threw next.
  CHECK(seen == std::vector<std::string>{"after it"});
  CHECK(f.mailbox->exclusive([&](DeferredSdfBackend&) { seen.push_back("call"); }) ==
        DeferredMailbox::Access::done);
  CHECK(seen == std::vector<std::string>{"after it", "call"});
  CHECK(f.mailbox->pump(true));
  const auto destroyedInTime = returnsWithin(60s, [m = f.mailbox] { return m->shutdown(); });
  REQUIRE(destroyedInTime.has_value());
  CHECK(*destroyedInTime);
  CHECK(f.log->destroyed);
}

TEST_CASE("exclusive and shutdown stop waiting for a claim that outlasts their bound, and say so",
          "[core][deferred_mailbox]") {
  // A short bound keeps the test short; the outcome, not a time, is checked.
  constexpr auto bound = 200ms;
  Fixture f(bound);
  auto held = f.holdPump();  // never ends while the gate is closed
  const GateOpener opener{f.log};
  auto ran = std::make_shared<std::atomic<bool>>(false);
  const auto start = std::chrono::steady_clock::now();
  const auto access = returnsWithin(60s, [m = f.mailbox, ran] {
    return m->exclusive([ran](DeferredSdfBackend&) { *ran = true; });
  });
  REQUIRE(access.has_value());
  CHECK(std::chrono::steady_clock::now() - start >= bound);
  CHECK(*access == DeferredMailbox::Access::timed_out);
  CHECK_FALSE(*ran);

  const auto destroyedInTime = returnsWithin(60s, [m = f.mailbox] { return m->shutdown(); });
  REQUIRE(destroyedInTime.has_value());
  CHECK_FALSE(*destroyedInTime);
  CHECK_FALSE(f.log->destroyed);  // the pump still uses it
  CHECK(f.owner->failed());
  CHECK(f.mailbox->exclusive([ran](DeferredSdfBackend&) { *ran = true; }) ==
        DeferredMailbox::Access::shut_down);
  CHECK_FALSE(*ran);

  f.log->gateClosed = false;
  CHECK(held.get());
  CHECK_FALSE(f.mailbox->pump(true));
  // The last reference frees the device the pump was using.
  f.owner.reset();
  f.mailbox.reset();
  CHECK(f.log->destroyed);
}

TEST_CASE("A shared mesh is recorded without a copy and handed to the device at the pump",
          "[core][deferred_mailbox]") {
  Fixture f;
  REQUIRE(f.mailbox->pump(false));
  SharedMesh mesh;
  mesh.positions = std::make_shared<const std::vector<glm::vec3>>(sphere().positions);
  mesh.indices = std::make_shared<const std::vector<uint32_t>>(sphere().indices);
  REQUIRE(f.owner->requestShared(0, 7, 1, mesh, Pose{}, GridBox::referenceDefault()) == Status::ok);
  // The request holds the owner's arrays themselves.
  CHECK(mesh.positions.use_count() == 2);
  CHECK(mesh.indices.use_count() == 2);
  REQUIRE(f.mailbox->pump(false));
  CHECK(f.log->requests == 1);
  CHECK(f.log->lastMesh == sphere().positions);
  // Handed down, the request no longer holds them.
  CHECK(mesh.positions.use_count() == 1);
  CHECK(mesh.indices.use_count() == 1);
  CHECK(f.owner->requestShared(1, 7, 1, SharedMesh{}, Pose{}, GridBox::referenceDefault()) ==
        Status::invalid_argument);
}

TEST_CASE("Readbacks go through the pump, and one the device refuses comes back empty",
          "[core][deferred_mailbox]") {
  Fixture f;
  CHECK(f.owner->requestReadback(5, 1) == Status::invalid_argument);  // no such device mesh
  f.mailbox->noteDeviceMesh(5, true);
  f.log->readbacks = true;
  REQUIRE(f.owner->requestReadback(5, 1) == Status::ok);
  REQUIRE(f.owner->requestReadback(5, 2) == Status::ok);  // the newer replaces the older
  CHECK(f.owner->needsSubmit(true));
  CHECK(f.owner->takeReadbacks().empty());  // nothing before a pump
  REQUIRE(f.mailbox->pump(true));
  std::vector<MeshReadback> got = f.owner->takeReadbacks();
  REQUIRE(got.size() == 1);
  CHECK(got[0].id == 5);
  CHECK(got[0].generation == 2);
  CHECK(got[0].positions.size() == 1);
  // A device that cannot read meshes back: the request comes back empty (the owner must not wait
  // for it), and later ones are refused at once.
  f.log->readbacks = false;
  REQUIRE(f.owner->requestReadback(5, 3) == Status::ok);
  REQUIRE(f.mailbox->pump(true));
  got = f.owner->takeReadbacks();
  REQUIRE(got.size() == 1);
  CHECK(got[0].generation == 3);
  CHECK(got[0].positions.empty());
  CHECK(f.owner->requestReadback(5, 4) == Status::unsupported);
}
