// Run configuration: defaults file, overrides, errors naming the key and origin, exact round trip.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scanhead/chain/config_io.hpp"
#include "scanhead/common/errors.hpp"

using namespace scanhead;

namespace
{
const std::string kConfig = std::string(SCANHEAD_SOURCE_DIR) + "/config/scanhead.yaml";

template <class F>
std::string errorOf(F&& f)
{
  try
  {
    f();
  }
  catch (const std::exception& e)
  {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(ConfigIo, DefaultsFileEqualsStructDefaults)
{
  // The shipped YAML and the struct defaults must not drift apart.
  const ChainConfig defaults;
  EXPECT_EQ(chainConfigToYaml(loadChainConfig(kConfig, {})), chainConfigToYaml(defaults));
}

TEST(ConfigIo, OverridesApply)
{
  const ChainConfig c = loadChainConfig(
      kConfig, {"nc.fir_t1_s=300e-6", "energy.pixel_m=2.5e-6", "stream.chunk_samples=7", "servo.y.bandwidth_hz=900"});
  EXPECT_EQ(c.nc.fir_t1_s, 300e-6);
  EXPECT_EQ(c.energy.pixel_m, 2.5e-6);
  EXPECT_EQ(c.stream.chunk_samples, 7u);
  EXPECT_EQ(c.servo.y.bandwidth_hz, 900.0);
}

TEST(ConfigIo, RoundTripIsBitExact)
{
  const ChainConfig a = loadChainConfig(kConfig, {"nc.fir_t2_s=0.000123456789012345678"});
  const ChainConfig b = chainConfigFromFlat(flattenYaml(chainConfigToYaml(a), "round trip"));
  EXPECT_EQ(a.nc.fir_t2_s, b.nc.fir_t2_s);
  EXPECT_EQ(chainConfigToYaml(a), chainConfigToYaml(b));
}

TEST(ConfigIo, ErrorsNameTheKeyAndOrigin)
{
  EXPECT_NE(errorOf([] { loadChainConfig(kConfig, {"nc.fir_t9_s=1"}); }).find("unknown key 'nc.fir_t9_s'"),
            std::string::npos);
  EXPECT_NE(
      errorOf([] { loadChainConfig(kConfig, {"nc.period_s=abc"}); }).find("nc.period_s (--set): 'abc' is not a number"),
      std::string::npos);
  EXPECT_NE(errorOf([] { loadChainConfig(kConfig, {"nc.period_s=nan"}); }).find("not a finite number"),
            std::string::npos);
  EXPECT_NE(errorOf([] { loadChainConfig(kConfig, {"stream.chunk_samples=2.5"}); }).find("not a non-negative integer"),
            std::string::npos);
  EXPECT_NE(errorOf([] { loadChainConfig(kConfig, {"nc.fir_t1_s=-1e-5"}); }).find("nc.fir_t1_s"), std::string::npos);
  EXPECT_NE(errorOf([] { loadChainConfig(kConfig, {"noequals"}); }).find("expected section.key=value"),
            std::string::npos);
  const std::string unknown =
      errorOf([] { chainConfigFromFlat(flattenYaml("nc:\n  period_s: 1e-5\n  bogus: 3\n", "c.yaml")); });
  EXPECT_NE(unknown.find("nc.bogus (c.yaml:3): unknown setting"), std::string::npos) << unknown;
  EXPECT_NE(errorOf([] { flattenYaml("nc: [1, 2\n", "m.yaml"); }).find("m.yaml"), std::string::npos);
  EXPECT_NE(errorOf([] { loadChainConfig("/nonexistent.yaml", {}); }).find("cannot open"), std::string::npos);
}

TEST(ConfigIo, DifferingSettingsNamesEachKeyInTheGivenSections)
{
  // What the energy node says when it is configured differently from the NC node.
  const std::string a = chainConfigToYaml(loadChainConfig(kConfig, {}));
  const std::string b = chainConfigToYaml(
      loadChainConfig(kConfig, {"nc.fir_t1_s=300e-6", "servo.y.bandwidth_hz=900", "energy.pixel_m=2.5e-6"}));
  EXPECT_TRUE(differingSettings(a, a, {"nc", "servo", "energy"}).empty());
  const std::vector<std::string> differ = differingSettings(a, b, {"nc", "servo"});
  ASSERT_EQ(differ.size(), 2u);
  EXPECT_EQ(differ[0].rfind("nc.fir_t1_s: 0.00025999999999999998 vs 0.00029999999999999997", 0), 0u) << differ[0];
  EXPECT_EQ(differ[1].rfind("servo.y.bandwidth_hz: ", 0), 0u) << differ[1];
  EXPECT_EQ(differingSettings(a, b, {"energy"}).size(), 1u);  // only the sections asked for
}

// Physically impossible settings are errors naming the key and the range: each bound at just inside
// (accepted) and just outside (refused), for the defaults' neighbours (d = 70 µm, Ts = 10 µs).
TEST(ConfigIo, PhysicalBoundsAtTheirEdges)
{
  struct Bound
  {
    std::string inside, outside, key;
  };
  const std::vector<Bound> bounds = {
      {"nc.period_s=1e-6", "nc.period_s=0.999e-6", "nc.period_s must be in [1e-06, 0.001] s"},
      {"nc.period_s=1e-3", "nc.period_s=1.001e-3", "nc.period_s must be in [1e-06, 0.001] s"},
      {"nc.fir_t1_s=0.1", "nc.fir_t1_s=0.10001", "nc.fir_t1_s must be <= 10000·nc.period_s"},
      {"nc.fir_t2_s=0.1", "nc.fir_t2_s=0.10001", "nc.fir_t2_s must be <= 10000·nc.period_s"},
      {"servo.controller_rate_hz=1e6", "servo.controller_rate_hz=1.001e6", "servo.controller_rate_hz must be in"},
      {"servo.controller_rate_hz=1e3", "servo.controller_rate_hz=999", "servo.controller_rate_hz must be in"},
      {"energy.pixel_m=35e-6", "energy.pixel_m=35.001e-6", "energy.pixel_m must be <= energy.spot_diameter_m/2"},
      {"energy.pixel_m=0.7e-6", "energy.pixel_m=0.6999e-6", "energy.pixel_m must be >= energy.spot_diameter_m/100"},
      {"energy.truncation_radii=5", "energy.truncation_radii=5.001", "energy.truncation_radii must be <= 5"},
      {"energy.max_substep_radii=0.01", "energy.max_substep_radii=0.00999", "energy.max_substep_radii must be >= 0.01"},
      {"stream.chunk_samples=1000000", "stream.chunk_samples=1000001", "stream.chunk_samples must be <= 1000000"},
      {"recipe.contour_power_w=1e6", "recipe.contour_power_w=1.0001e6", "recipe.contour_power_w must be <= 1e+06 W"},
      {"cam.mark_power_w=1e6", "cam.mark_power_w=1.0001e6", "cam.mark_power_w must be <= 1e+06 W"},
      {"nc.igt.table_nodes=1025", "nc.igt.table_nodes=1026", "nc.igt.table_nodes must be in 2...1025"},
      {"limits.max_memory_fraction=1", "limits.max_memory_fraction=1.001", "limits.max_memory_fraction must be in"},
  };
  for (const Bound& b : bounds)
  {
    EXPECT_EQ(errorOf([&] { loadChainConfig(kConfig, {b.inside}); }), "") << b.inside;
    const std::string error = errorOf([&] { loadChainConfig(kConfig, {b.outside}); });
    EXPECT_EQ(error.rfind(b.key, 0), 0u) << b.outside << ": " << error;
  }
  // The diffraction limit 2·M²·λ/π (0.749 µm at 1.07 µm, M² 1.1); the pixel follows the spot.
  const double limit = 2.0 * 1.1 * 1.07e-6 / M_PI;
  auto num = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", v);
    return std::string(text);
  };
  EXPECT_EQ(errorOf([&] {
              loadChainConfig(kConfig,
                              {"energy.spot_diameter_m=" + num(limit * 1.0001), "energy.pixel_m=" + num(limit * 0.1)});
            }),
            "");
  EXPECT_NE(errorOf([&] {
              loadChainConfig(kConfig,
                              {"energy.spot_diameter_m=" + num(limit * 0.999), "energy.pixel_m=" + num(limit * 0.1)});
            }).find("the diffraction limit"),
            std::string::npos);
}
