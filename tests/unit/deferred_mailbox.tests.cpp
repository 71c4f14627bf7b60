// DeferredMailbox: the owner's side never calls the device; pump() does, one pump at a time and
// never waiting for another; exclusive() and shutdown() wait for a pump in progress.
#include <catch2/catch.hpp>

#include <array>
#include <atomic>
#include <chrono>
#include <future>
#include <memory>
#include <string>
#include <thread>
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
    std::vector<std::thread::id> callers;  // written by the pumping thread only
    std::vector<std::string> order;
  };
  explicit FakeDevice(std::shared_ptr<Log> log) : log_(std::move(log)) {}
  ~FakeDevice() override { log_->destroyed = true; }
  std::string_view name() const override { return "fake"; }
  Status request(size_t slot, uint64_t id, uint64_t, const TriangleMesh*, const Pose&,
                 const GridBox& box) override {
    note("request");
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
    log_->inReady = true;
    while (log_->gateClosed) std::this_thread::sleep_for(1ms);
    log_->inReady = false;
    return true;
  }
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
  bool failed_ = false;
};

struct Fixture {
  std::shared_ptr<FakeDevice::Log> log = std::make_shared<FakeDevice::Log>();
  FakeDevice* device = nullptr;
  std::shared_ptr<DeferredMailbox> mailbox;
  std::unique_ptr<DeferredSdfBackend> owner;
  Fixture() {
    auto d = std::make_unique<FakeDevice>(log);
    device = d.get();
    mailbox = std::make_shared<DeferredMailbox>(std::move(d));
    owner = DeferredMailbox::ownerSide(mailbox);
  }
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
  f.mailbox->shutdown();
  CHECK(f.log->destroyed);
  CHECK_FALSE(f.mailbox->pump(true));
  bool ran = false;
  f.mailbox->exclusive([&](DeferredSdfBackend&) { ran = true; });
  CHECK_FALSE(ran);
}
