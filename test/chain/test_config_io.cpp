// Run configuration: defaults file, overrides, errors naming the key and origin, exact round trip.
#include <gtest/gtest.h>

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
