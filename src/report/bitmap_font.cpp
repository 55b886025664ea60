/// \file bitmap_font.cpp
/// \brief The 5 × 7 font of bitmap_font.hpp (glyphs drawn for this project, in the style of the classic
/// HD44780 character ROM: each row a 5-bit mask, bit 4 the leftmost column).
#include "scanhead/report/bitmap_font.hpp"

#include <algorithm>
#include <vector>

namespace scanhead
{
namespace
{
struct Glyph
{
  const char* key;  ///< one character, or the UTF-8 bytes of "²"
  std::uint8_t rows[kGlyphHeight];
};

const Glyph kGlyphs[] = {
    {"0", {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}},        {"1", {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {"2", {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}},        {"3", {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {"4", {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}},        {"5", {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {"6", {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}},        {"7", {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {"8", {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}},        {"9", {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {".", {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}},        {"-", {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
    {"+", {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}},        {"e", {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E}},
    {"E", {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}},        {"J", {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}},
    {"/", {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},        {"m", {0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11}},
    {"\xC2\xB2", {0x0C, 0x12, 0x04, 0x08, 0x1E, 0x00, 0x00}},  // "²"
    {" ", {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
};
const std::uint8_t kMissing[kGlyphHeight] = {0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F};

/// \brief The glyphs of \p text in order (multi-byte keys first).
std::vector<const std::uint8_t*> glyphsOf(const std::string& text)
{
  std::vector<const std::uint8_t*> out;
  for (std::size_t i = 0; i < text.size();)
  {
    const std::uint8_t* rows = kMissing;
    std::size_t length = 1;
    for (const Glyph& g : kGlyphs)
    {
      const std::string key = g.key;
      if (text.compare(i, key.size(), key) == 0)
      {
        rows = g.rows;
        length = key.size();
        break;
      }
    }
    if (rows == kMissing && (static_cast<unsigned char>(text[i]) & 0xC0) == 0xC0)
      while (i + length < text.size() && (static_cast<unsigned char>(text[i + length]) & 0xC0) == 0x80)
        ++length;  // one box for a whole unknown UTF-8 character
    out.push_back(rows);
    i += length;
  }
  return out;
}
}  // namespace

int textWidth(const std::string& text, int scale)
{
  const int n = static_cast<int>(glyphsOf(text).size());
  return n == 0 ? 0 : (n * kGlyphAdvance - 1) * scale;
}

void drawText(RgbImage& image, int x, int y, const std::string& text, int scale,
              const std::array<std::uint8_t, 3>& colour)
{
  int gx = x;
  for (const std::uint8_t* rows : glyphsOf(text))
  {
    for (int r = 0; r < kGlyphHeight; ++r)
      for (int c = 0; c < kGlyphWidth; ++c)
        if (rows[r] & (0x10 >> c))
          for (int py = y + r * scale; py < y + (r + 1) * scale; ++py)
            for (int px = gx + c * scale; px < gx + (c + 1) * scale; ++px)
              if (px >= 0 && py >= 0 && px < image.width && py < image.height)
                std::copy(colour.begin(), colour.end(), image.pixel(px, py));
    gx += kGlyphAdvance * scale;
  }
}
}  // namespace scanhead
