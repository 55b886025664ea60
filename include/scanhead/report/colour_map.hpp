/// \file colour_map.hpp
/// \brief A perceptual colour map (inferno) and the rendering of an energy map to images.
#pragma once

#include <array>
#include <cstdint>

#include "scanhead/energy/energy_map.hpp"
#include "scanhead/report/image.hpp"

namespace scanhead
{
/// \brief Inferno (matplotlib, van der Walt & Smith, CC0): black → purple → orange → pale yellow,
/// lightness increasing monotonically. 17 anchors (the 256-entry table at i·16, and its last
/// entry) joined linearly; \p t is clamped to [0, 1] (NaN gives the t = 0 colour).
std::array<std::uint8_t, 3> inferno(double t);

/// \brief Layout of renderEnergyMap().
struct EnergyImageLayout
{
  int map_width = 0;  ///< columns of the map part (the image starts with it) [px]
  int bar_x0 = 0;     ///< first column of the colour bar [px]
  int bar_width = 0;  ///< [px]
  int block = 1;      ///< map pixels per image pixel along each axis (block maximum)
};

/// \brief Renders an energy map with inferno, +y up (row 0 of the image is the map's top row),
/// and a vertical colour bar on the right: bottom = 0, top = \p scale_max_jpm2, with tick marks
/// at 0, 25, 50, 75 and 100 % labelled in J/mm² (bitmap_font.hpp; the top one with the unit; on a
/// bar too short for five labels, 0 and the top only), and a scale bar in the map's bottom-left
/// corner (a round length of 1, 2 or 5 × 10^k mm near a fifth of the width, labelled).
/// \param[in] scale_max_jpm2 top of the scale [J/m²]; ≤ 0 or NaN: the map's peak (1 if the map is empty)
/// \param[in] max_side_px    if > 0 and the map is larger, each image pixel shows the maximum of a
///                           block × block square of map pixels (hot spots stay visible), block the
///                           smallest integer that brings the larger side down to max_side_px
/// \param[out] layout        optional: where the parts are
RgbImage renderEnergyMap(const EnergyMap& map, double scale_max_jpm2 = 0.0, int max_side_px = 0,
                         EnergyImageLayout* layout = nullptr);

/// \brief The map as 16-bit gray, +y up, value = round(65535·clamp(E / scale_max_jpm2, 0, 1))
/// (scale_max_jpm2 ≤ 0 or NaN: the map's peak). Full resolution.
Gray16Image energyMapToGray16(const EnergyMap& map, double scale_max_jpm2 = 0.0);
}  // namespace scanhead
