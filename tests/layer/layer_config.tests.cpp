// The layer's configuration keys (layer/config.h): each value is parsed or refused, and a
// refused value leaves the whole configuration as it was.
#include <catch2/catch.hpp>

#include "config.h"

using sdfg::layer::applyConfigValue;
using sdfg::layer::Config;

TEST_CASE("gpu takes auto, on and off (and booleans); anything else changes nothing",
          "[layer][config]") {
  Config c;
  CHECK(c.gpu == Config::Gpu::automatic);
  REQUIRE(applyConfigValue(c, "gpu", "off"));
  CHECK(c.gpu == Config::Gpu::off);
  REQUIRE(applyConfigValue(c, "gpu", "true"));
  CHECK(c.gpu == Config::Gpu::on);
  REQUIRE(applyConfigValue(c, "gpu", "auto"));
  CHECK(c.gpu == Config::Gpu::automatic);
  for (const char* bad : {"sometimes", "", "AUTO", "2"}) {
    CAPTURE(bad);
    CHECK_FALSE(applyConfigValue(c, "gpu", bad));
    CHECK(c.gpu == Config::Gpu::automatic);
  }
}

TEST_CASE("exact_check and sdf_far_band are parsed and range-checked", "[layer][config]") {
  Config c;
  CHECK(c.exactCheck);
  CHECK(c.sdfFarBand == 2.0f);
  REQUIRE(applyConfigValue(c, "exact_check", "off"));
  CHECK_FALSE(c.exactCheck);
  CHECK_FALSE(applyConfigValue(c, "exact_check", "maybe"));
  CHECK_FALSE(c.exactCheck);
  REQUIRE(applyConfigValue(c, "sdf_far_band", "0"));
  CHECK(c.sdfFarBand == 0.0f);
  REQUIRE(applyConfigValue(c, "sdf_far_band", "3.5"));
  CHECK(c.sdfFarBand == 3.5f);
  for (const char* bad : {"-1", "nan", "inf", "65", "two", ""}) {
    CAPTURE(bad);
    CHECK_FALSE(applyConfigValue(c, "sdf_far_band", bad));
    CHECK(c.sdfFarBand == 3.5f);
  }
  CHECK_FALSE(applyConfigValue(c, "no_such_key", "1"));
}
