/// \file bitmap_font.hpp
/// \brief A 5 × 7 pixel font for the numbers and units the native images print (colour-bar labels): digits,
/// ". - + e E", the letters of "J/mm²" and a blank; drawn at an integer scale, in black or any colour.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "scanhead/report/image.hpp"

namespace scanhead
{
constexpr int kGlyphWidth = 5;    ///< [font pixels]
constexpr int kGlyphHeight = 7;   ///< [font pixels]
constexpr int kGlyphAdvance = 6;  ///< glyph width + one blank column

/// \brief Width of \p text drawn at \p scale [image pixels] (UTF-8 "²" counts as one glyph).
int textWidth(const std::string& text, int scale);

/// \brief Draws \p text with its top-left corner at (x, y), each font pixel a scale × scale square, clipped to the
/// image. Characters without a glyph are drawn as a hollow box (never silently dropped).
void drawText(RgbImage& image, int x, int y, const std::string& text, int scale,
              const std::array<std::uint8_t, 3>& colour = {0, 0, 0});
}  // namespace scanhead
