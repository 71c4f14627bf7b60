#include <catch2/catch.hpp>

#include <iterator>
#include <memory>
#include <set>
#include <string>

#include "base/status.h"

TEST_CASE("Result holds either a value or an error", "[core][status]") {
  using sdfg::Result;

  SECTION("A value is ok and readable") {
    Result<int> r = 42;
    REQUIRE(r.ok());
    CHECK(*r == 42);
  }
  SECTION("An error is not ok and keeps its code and message") {
    Result<int> r = sdfg::makeError(sdfg::Status::invalid_argument, "count is zero");
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().code == sdfg::Status::invalid_argument);
    CHECK(r.error().message == "count is zero");
  }
  SECTION("Move-only values are supported") {
    Result<std::unique_ptr<int>> r = std::make_unique<int>(7);
    REQUIRE(r.ok());
    std::unique_ptr<int> taken = std::move(r).value();
    CHECK(*taken == 7);
  }
}

TEST_CASE("Every status has a readable name", "[core][status]") {
  using sdfg::Status;
  // Every enumerator, in declaration order (internal is the last): a new one must be added here,
  // and to toString, or the size check below fails.
  const Status all[] = {Status::ok,          Status::invalid_argument, Status::io_error,
                        Status::unsupported, Status::out_of_memory,    Status::device_lost,
                        Status::timed_out,   Status::internal};
  static_assert(int(Status::internal) + 1 == int(std::size(all)), "a status is missing here");
  std::set<std::string> names;
  for (Status s : all) {
    const std::string name = sdfg::toString(s);
    CAPTURE(int(s), name);
    CHECK_FALSE(name.empty());
    CHECK(name != "unknown status");  // toString's answer for a value it does not list
    names.insert(name);
  }
  CHECK(names.size() == std::size(all));  // no two alike
  CHECK(std::string(sdfg::toString(Status::ok)) == "ok");
  CHECK(std::string(sdfg::toString(Status::device_lost)) == "device lost");
}
