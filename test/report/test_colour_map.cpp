/// \file test_colour_map.cpp
/// \brief Inferno colour map and the energy-map renderings.
#include <gtest/gtest.h>

#include <cmath>

#include "scanhead/report/colour_map.hpp"

using scanhead::EnergyImageLayout;
using scanhead::EnergyMap;
using scanhead::inferno;

namespace
{
double linear(std::uint8_t c)
{
  const double s = c / 255.0;
  return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
}
/// \brief Relative luminance (sRGB / ITU-R BT.709).
double luminance(const std::array<std::uint8_t, 3>& c)
{
  return 0.2126 * linear(c[0]) + 0.7152 * linear(c[1]) + 0.0722 * linear(c[2]);
}
}  // namespace

TEST(ColourMap, InfernoEndsAndMonotonicLuminance)
{
  // Table ends (matplotlib inferno entries 0 and 255), and the midpoint entry 128.
  EXPECT_EQ(inferno(0.0), (std::array<std::uint8_t, 3>{0, 0, 4}));
  EXPECT_EQ(inferno(1.0), (std::array<std::uint8_t, 3>{252, 255, 164}));
  EXPECT_EQ(inferno(128.0 / 255.0), (std::array<std::uint8_t, 3>{188, 55, 84}));
  EXPECT_EQ(inferno(-1.0), inferno(0.0));
  EXPECT_EQ(inferno(NAN), inferno(0.0));
  EXPECT_EQ(inferno(7.0), inferno(1.0));
  // Perceptual property: luminance rises with t. Checked every 1/64 (4 table entries): at finer
  // steps the byte rounding of single channels makes drops of < 0.002 (one byte step).
  double prev = -1.0;
  for (int i = 0; i <= 64; ++i)
  {
    const double y = luminance(inferno(i / 64.0));
    EXPECT_GT(y, prev) << "t = " << i / 64.0;
    prev = y;
  }
  EXPECT_GT(luminance(inferno(1.0)), 0.9);
}

TEST(ColourMap, RenderEnergyMap)
{
  EnergyMap map(Eigen::Vector2d(0, 0), Eigen::Vector2d(100e-6, 50e-6), 1e-6);  // 100 x 50
  ASSERT_EQ(map.width(), 100);
  ASSERT_EQ(map.height(), 50);
  map.row(40)[10] = 8.0f;  // peak near the top-left in the +y-up picture
  map.row(5)[90] = 2.0f;   // a quarter of the peak, bottom right
  EnergyImageLayout layout;
  const scanhead::RgbImage img = scanhead::renderEnergyMap(map, 0.0, 0, &layout);
  EXPECT_EQ(layout.map_width, 100);
  EXPECT_EQ(layout.block, 1);
  EXPECT_EQ(img.height, 50);
  EXPECT_GT(img.width, layout.bar_x0 + layout.bar_width);
  auto colour = [&](int x, int y) {
    return std::array<std::uint8_t, 3>{img.pixel(x, y)[0], img.pixel(x, y)[1], img.pixel(x, y)[2]};
  };
  EXPECT_EQ(colour(10, 49 - 40), inferno(1.0));  // flipped: map row 40 is image row 9
  EXPECT_EQ(colour(90, 49 - 5), inferno(0.25));
  EXPECT_EQ(colour(0, 0), inferno(0.0));
  EXPECT_EQ(colour(layout.bar_x0, 0), inferno(1.0));   // bar top = scale
  EXPECT_EQ(colour(layout.bar_x0, 49), inferno(0.0));  // bar bottom = 0
  // Explicit scale: the peak saturates at the top colour, the quarter becomes a half.
  const scanhead::RgbImage half = scanhead::renderEnergyMap(map, 4.0);
  EXPECT_EQ(half.pixel(90, 44)[0], inferno(0.5)[0]);

  // Block maximum keeps the hot pixel visible at a quarter of the size.
  const scanhead::RgbImage small = scanhead::renderEnergyMap(map, 0.0, 25, &layout);
  EXPECT_EQ(layout.block, 4);
  EXPECT_EQ(layout.map_width, 25);
  EXPECT_EQ(small.height, 16);  // 50 / 4 → 13 rows, image at least 16 high
  // map row 40 → block row 10 → image row 13 − 1 − 10 = 2; column 10 → block 2
  const std::uint8_t* hot = small.pixel(2, 2);
  EXPECT_EQ((std::array<std::uint8_t, 3>{hot[0], hot[1], hot[2]}), inferno(1.0));

  const scanhead::Gray16Image gray = scanhead::energyMapToGray16(map);
  EXPECT_EQ(gray.width, 100);
  EXPECT_EQ(gray.at(10, 9), 65535);
  EXPECT_EQ(gray.at(90, 44), 16384);  // round(65535 / 4)
  EXPECT_EQ(gray.at(0, 0), 0);
}
