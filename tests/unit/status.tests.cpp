#include <catch2/catch.hpp>

#include <memory>
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
  CHECK(std::string(sdfg::toString(sdfg::Status::ok)) == "ok");
  CHECK(std::string(sdfg::toString(sdfg::Status::device_lost)) == "device lost");
}
