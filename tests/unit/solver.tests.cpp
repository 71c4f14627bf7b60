// The solver registry: names and creation by name.
#include <catch2/catch.hpp>

#include <string>

#include "eval/strategies.h"

TEST_CASE("every listed solver name creates a solver of that name", "[solver]") {
  using namespace sdfg;
  const std::vector<std::string> names = allSolverNames();
  REQUIRE(names.size() >= 4);
  CHECK(names[0] == "ours");  // the default
  CHECK(names[1] == "paper");
  CHECK(names[2] == "physics-convex");
  CHECK(names[3] == "physics-mesh");
  for (const std::string& name : names) {
    CAPTURE(name);
    auto solver = createAnySolver(name);
    REQUIRE(solver.ok());
    REQUIRE(solver.value() != nullptr);
    CHECK(solver.value()->name() == name);
    CHECK(solver.value()->needsField() != solver.value()->needsCollider());
  }
}

TEST_CASE("an unknown solver name is an error that lists the known ones", "[solver]") {
  using namespace sdfg;
  auto solver = createAnySolver("magic");
  REQUIRE_FALSE(solver.ok());
  CHECK(solver.error().code == Status::invalid_argument);
  CHECK(solver.error().message.find("magic") != std::string::npos);
  for (const std::string& name : allSolverNames()) {
    CHECK(solver.error().message.find(name) != std::string::npos);
  }
}

TEST_CASE("solver options are validated in one place", "[solver]") {
  using namespace sdfg;
  CHECK_FALSE(validateSolverOptions(SolverOptions{}).has_value());
  SolverOptions options;
  options.da = 1.0f;
  options.refineStep = 1.0f;
  options.threshold = 0.0f;
  CHECK_FALSE(validateSolverOptions(options).has_value());
  options.refineStep = -0.01f;
  REQUIRE(validateSolverOptions(options).has_value());
  CHECK(validateSolverOptions(options)->message.find("refineStep") != std::string::npos);
}
