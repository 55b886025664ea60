/// \file test_colour_map.cpp
/// \brief Inferno colour map and the energy-map renderings.
#include <gtest/gtest.h>

#include <cmath>

#include "scanhead/report/bitmap_font.hpp"
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

// The colour bar is labelled: at each quarter tick its value in J/mm² (the top one with the unit), drawn exactly
// where the layout says (compared with the same text drawn alone); a bar without labels fails here.
TEST(ColourMap, ColourBarLabels)
{
  EnergyMap map(Eigen::Vector2d(0, 0), Eigen::Vector2d(600e-6, 600e-6), 1e-6);  // 600 x 600: font scale 5
  map.row(300)[300] = 1.0f;
  EnergyImageLayout layout;
  const scanhead::RgbImage img = scanhead::renderEnergyMap(map, 2.0e6, 0, &layout);  // scale 2 J/mm²
  const int font = 5, h = 600;
  const int tick = std::max(4, std::max(8, 600 / 20) / 2);
  const int x = layout.bar_x0 + layout.bar_width + tick + 2 * font;
  const char* expected[5] = {"0", "0.5", "1", "1.5", "2 J/mm\xC2\xB2"};
  for (int q = 0; q <= 4; ++q)
  {
    const int y = static_cast<int>(std::lround((1.0 - q / 4.0) * (h - 1)));
    const int top = std::min(std::max(0, y - scanhead::kGlyphHeight * font / 2), h - scanhead::kGlyphHeight * font);
    scanhead::RgbImage alone(img.width, img.height);
    std::fill(alone.rgb.begin(), alone.rgb.end(), std::uint8_t(255));
    scanhead::drawText(alone, x, top, expected[q], font);
    int dark = 0, differ = 0;
    for (int py = top; py < top + scanhead::kGlyphHeight * font; ++py)
      for (int px = x; px < img.width; ++px)
      {
        dark += img.pixel(px, py)[0] == 0;
        differ += img.pixel(px, py)[0] != alone.pixel(px, py)[0];
      }
    EXPECT_GE(dark, 8 * font * font) << "no label at tick " << q;  // "1", the leanest, has 10 font pixels
    EXPECT_EQ(differ, 0) << "tick " << q << " is not labelled '" << expected[q] << "'";
  }
  EXPECT_GE(img.width, x + scanhead::textWidth("2 J/mm\xC2\xB2", font));
  // The scale bar: 0.1 mm (a round length near a fifth of the 0.6 mm width) = 100 px, white, bottom left,
  // its length written above it.
  EXPECT_EQ(img.pixel(15, 580)[0], 255);
  EXPECT_EQ(img.pixel(114, 580)[1], 255);
  EXPECT_EQ(img.pixel(116, 580)[1], 0);
  scanhead::RgbImage label(img.width, img.height);
  scanhead::drawText(label, 15, 585 - 20 - 35, "0.1 mm", font, {255, 255, 255});
  int label_differ = 0;
  for (int py = 530; py < 565; ++py)
    for (int px = 15; px < 15 + scanhead::textWidth("0.1 mm", font); ++px)
      label_differ += (img.pixel(px, py)[0] == 255) != (label.pixel(px, py)[0] == 255);
  EXPECT_EQ(label_differ, 0) << "the scale bar is not labelled '0.1 mm'";
  // An unknown character is drawn as a box, never dropped; "²" is one glyph.
  EXPECT_EQ(scanhead::textWidth("m\xC2\xB2", 1), 2 * scanhead::kGlyphAdvance - 1);
  scanhead::RgbImage box(10, 10);
  scanhead::drawText(box, 0, 0, "%", 1, {255, 255, 255});
  EXPECT_EQ(box.pixel(0, 0)[0], 255);
  EXPECT_EQ(box.pixel(4, 6)[0], 255);
  EXPECT_EQ(box.pixel(2, 3)[0], 0);
}
