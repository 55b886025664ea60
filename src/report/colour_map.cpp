/// \file colour_map.cpp
#include "scanhead/report/colour_map.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "scanhead/common/number_text.hpp"
#include "scanhead/report/bitmap_font.hpp"

namespace scanhead
{
namespace
{
/// \brief matplotlib's inferno table (_cm_listed.py, CC0) at entries 0, 16, …, 240 and 255.
constexpr int kAnchors = 17;
constexpr double kInferno[kAnchors][3] = {
    {0.001462, 0.000466, 0.013866}, {0.042253, 0.028139, 0.141141}, {0.129285, 0.047293, 0.290788},
    {0.238273, 0.036621, 0.396353}, {0.341500, 0.062325, 0.429425}, {0.441207, 0.099338, 0.431594},
    {0.540920, 0.134729, 0.415123}, {0.640135, 0.171438, 0.381065}, {0.735683, 0.215906, 0.330245},
    {0.822386, 0.275197, 0.266085}, {0.894305, 0.353399, 0.193584}, {0.946965, 0.449191, 0.115272},
    {0.978422, 0.557937, 0.034931}, {0.987874, 0.675267, 0.065257}, {0.974638, 0.797692, 0.206332},
    {0.947594, 0.917399, 0.410665}, {0.988362, 0.998364, 0.644924},
};

/// \brief Position of anchor i on [0, 1]: table entry 16·i of 0..255 (the last one is entry 255).
double anchorT(int i)
{
  return i == kAnchors - 1 ? 1.0 : 16.0 * i / 255.0;
}

double scaleOf(const EnergyMap& map, double scale_max_jpm2)
{
  if (scale_max_jpm2 > 0.0 && std::isfinite(scale_max_jpm2))
  {
    return scale_max_jpm2;
  }
  const double peak = map.peak();
  return peak > 0.0 ? peak : 1.0;
}

void fill(RgbImage& image, int x0, int y0, int x1, int y1, const std::array<std::uint8_t, 3>& c)
{
  for (int y = std::max(0, y0); y < std::min(image.height, y1); ++y)
  {
    for (int x = std::max(0, x0); x < std::min(image.width, x1); ++x)
    {
      std::uint8_t* p = image.pixel(x, y);
      p[0] = c[0];
      p[1] = c[1];
      p[2] = c[2];
    }
  }
}
}  // namespace

std::array<std::uint8_t, 3> inferno(double t)
{
  if (!(t > 0.0))
  {
    t = 0.0;  // also NaN
  }
  t = std::min(t, 1.0);
  int i = std::min(kAnchors - 2, static_cast<int>(t * 255.0 / 16.0));
  while (i > 0 && t < anchorT(i))
  {
    --i;  // guard against rounding at an anchor
  }
  const double f = std::min(1.0, std::max(0.0, (t - anchorT(i)) / (anchorT(i + 1) - anchorT(i))));
  std::array<std::uint8_t, 3> rgb;
  for (int c = 0; c < 3; ++c)
  {
    const double v = kInferno[i][c] + f * (kInferno[i + 1][c] - kInferno[i][c]);
    rgb[static_cast<std::size_t>(c)] = static_cast<std::uint8_t>(std::lround(255.0 * std::min(1.0, std::max(0.0, v))));
  }
  return rgb;
}

RgbImage renderEnergyMap(const EnergyMap& map, double scale_max_jpm2, int max_side_px, EnergyImageLayout* layout)
{
  const double scale = scaleOf(map, scale_max_jpm2);
  const int w = map.width(), h = map.height();
  int block = 1;
  if (max_side_px > 0 && std::max(w, h) > max_side_px)
  {
    block = (std::max(w, h) + max_side_px - 1) / max_side_px;
  }
  const int mw = (w + block - 1) / block, mh = (h + block - 1) / block;
  const int gap = std::max(2, mw / 50);
  const int bar = std::max(8, mw / 20);
  const int tick = std::max(4, bar / 2);
  const int height = std::max(mh, 16);
  // Tick labels in J/mm² (the top one with the unit), in the 5 × 7 font at a scale that stays readable on a
  // large overview (a glyph ≈ 1/17 of the bar's height, at least 7 px).
  const int font = std::max(1, std::min(8, mh / 120));
  std::string labels[5];
  int label_width = 0;
  for (int q = 0; q <= 4; ++q)
  {
    labels[q] = significantText(scale * 1e-6 * q / 4.0, 3) + (q == 4 ? " J/mm\xC2\xB2" : "");
    label_width = std::max(label_width, textWidth(labels[q], font));
  }
  const int pad = 2 * font;
  RgbImage image(mw + gap + bar + tick + pad + label_width + pad, height);
  std::fill(image.rgb.begin(), image.rgb.end(), std::uint8_t(255));  // white background

  // Map, +y up: image row Y shows map block row mh − 1 − Y.
  for (int y = 0; y < mh; ++y)
  {
    const int r0 = (mh - 1 - y) * block, r1 = std::min(h, r0 + block);
    for (int x = 0; x < mw; ++x)
    {
      const int c0 = x * block, c1 = std::min(w, c0 + block);
      float m = map.at(c0, r0);
      for (int r = r0; r < r1; ++r)
        for (int c = c0; c < c1; ++c)
          m = std::max(m, map.at(c, r));
      const std::array<std::uint8_t, 3> rgb = inferno(m / scale);
      std::uint8_t* p = image.pixel(x, y);
      p[0] = rgb[0];
      p[1] = rgb[1];
      p[2] = rgb[2];
    }
  }

  // Scale bar in the map's bottom-left corner: a round length (1, 2 or 5 × 10^k mm) near a fifth of the width,
  // white with its length above it, when the map is large enough to hold it.
  const double mm_per_px = map.pixel() * 1e3 * block;
  if (mw >= 40 * font && mh >= 20 * font && mm_per_px > 0.0)
  {
    const double target = 0.2 * mw * mm_per_px;
    const double base = std::pow(10.0, std::floor(std::log10(target)));
    const double length = 5.0 * base <= target ? 5.0 * base : 2.0 * base <= target ? 2.0 * base : base;
    const int px = static_cast<int>(std::lround(length / mm_per_px));
    const std::string label = significantText(length, 3) + " mm";
    const int x0 = 3 * font, y1 = mh - 3 * font, label_top = y1 - 4 * font - kGlyphHeight * font;
    // On a black backing, so that it reads over hot tracks too.
    fill(image, x0 - font, label_top - font, x0 + std::max(px, textWidth(label, font)) + font, y1 + font, {0, 0, 0});
    fill(image, x0, y1 - 2 * font, x0 + px, y1, {255, 255, 255});
    drawText(image, x0, label_top, label, font, {255, 255, 255});
  }

  // Colour bar over the map's rows: top = scale, bottom = 0; ticks at quarters.
  const int bar_x0 = mw + gap;
  for (int y = 0; y < mh; ++y)
  {
    const double f = mh == 1 ? 1.0 : 1.0 - static_cast<double>(y) / (mh - 1);
    fill(image, bar_x0, y, bar_x0 + bar, y + 1, inferno(f));
  }
  // Labels at every quarter where they fit (else at 0 and the top only), centred on their tick, kept inside.
  const bool all_labels = mh / 4 >= (kGlyphHeight + 2) * font;
  for (int q = 0; q <= 4; ++q)
  {
    const int y = static_cast<int>(std::lround((1.0 - q / 4.0) * (mh - 1)));
    fill(image, bar_x0 + bar, y, bar_x0 + bar + tick - 1, y + 1, {0, 0, 0});
    if (!all_labels && q != 0 && q != 4)
      continue;
    const int top = std::min(std::max(0, y - kGlyphHeight * font / 2), height - kGlyphHeight * font);
    drawText(image, bar_x0 + bar + tick + pad, top, labels[q], font);
  }
  if (layout)
  {
    layout->map_width = mw;
    layout->bar_x0 = bar_x0;
    layout->bar_width = bar;
    layout->block = block;
  }
  return image;
}

Gray16Image energyMapToGray16(const EnergyMap& map, double scale_max_jpm2)
{
  const double scale = scaleOf(map, scale_max_jpm2);
  Gray16Image image(map.width(), map.height());
  for (int y = 0; y < map.height(); ++y)
  {
    const int r = map.height() - 1 - y;
    for (int x = 0; x < map.width(); ++x)
    {
      double f = map.at(x, r) / scale;
      f = f > 0.0 ? std::min(f, 1.0) : 0.0;
      image.at(x, y) = static_cast<std::uint16_t>(std::lround(65535.0 * f));
    }
  }
  return image;
}
}  // namespace scanhead
