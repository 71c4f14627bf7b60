// WorkLimit's polling helpers: LimitPoll looks at the limit once per batch and stays reached;
// polledSort sorts as std::sort does and gives up once the limit is reached.
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <random>
#include <utility>
#include <vector>

#include "base/polled_sort.h"
#include "base/work_limit.h"

namespace {

using namespace sdfg;

WorkLimit stoppedBy(const std::atomic<bool>& flag) {
  return WorkLimit{WorkLimit::Clock::time_point::max(), &flag};
}

}  // namespace

TEST_CASE("LimitPoll looks at its limit once per batch and then stays reached",
          "[core][work_limit]") {
  std::atomic<bool> stop{true};
  const WorkLimit limit = stoppedBy(stop);
  LimitPoll poll(limit, 4);
  // The first three calls of a batch do not look; the fourth does.
  CHECK_FALSE(poll.reached());
  CHECK_FALSE(poll.reached());
  CHECK_FALSE(poll.reached());
  CHECK(poll.reached());
  CHECK(poll.stopped());
  // Clearing the flag does not undo it: the work was given up.
  stop = false;
  CHECK(poll.reached());
}

TEST_CASE("polledSort orders like std::sort, across many runs", "[core][work_limit]") {
  using Item = std::pair<uint64_t, uint32_t>;
  const auto byKey = [](const Item& a, const Item& b) { return a.first < b.first; };
  for (size_t n : {size_t(0), size_t(1), size_t(1000), size_t(70001), size_t(200000)}) {
    CAPTURE(n);
    std::mt19937 rng{uint32_t(n)};
    std::uniform_int_distribution<uint64_t> key(0, n / 3 + 1);  // many equal keys
    std::vector<Item> values(n);
    for (uint32_t i = 0; i < n; ++i) values[i] = {key(rng), i};
    std::vector<Item> expected = values;
    std::stable_sort(expected.begin(), expected.end(), byKey);
    REQUIRE(polledSort(values, byKey, WorkLimit::none()));
    // Same keys in the same order, and the same items (equal keys may come in any order).
    REQUIRE(values.size() == expected.size());
    CHECK(std::equal(values.begin(), values.end(), expected.begin(),
                     [](const Item& a, const Item& b) { return a.first == b.first; }));
    std::sort(values.begin(), values.end());
    std::sort(expected.begin(), expected.end());
    CHECK(values == expected);
  }
}

TEST_CASE("polledSort gives up once its limit is reached", "[core][work_limit]") {
  std::vector<uint32_t> values(100000);
  for (uint32_t i = 0; i < values.size(); ++i) values[i] = uint32_t(values.size()) - i;
  std::atomic<bool> stop{true};
  CHECK_FALSE(polledSort(values, std::less<uint32_t>(), stoppedBy(stop)));
  CHECK_FALSE(
      polledSort(values, std::less<uint32_t>(), WorkLimit::after(std::chrono::seconds(-1))));
}
