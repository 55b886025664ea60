/// \file tiff_writer.hpp
/// \brief Minimal 32-bit float TIFF writer (baseline TIFF 6.0 + GeoTIFF scale tags) for maps in
/// physical units (energy density, errors): the values bit for bit, and the pixel size and position.
///
/// Layout (TIFF 6.0, little-endian "II"): the 8-byte header, one IFD, its out-of-line values, then
/// the pixel strips (about 64 KiB each, rows top to bottom, uncompressed). Tags, in ascending order:
/// ImageWidth (256), ImageLength (257), BitsPerSample (258) = 32, Compression (259) = 1,
/// PhotometricInterpretation (262) = 1 (BlackIsZero), ImageDescription (270, if not empty),
/// StripOffsets (273), SamplesPerPixel (277) = 1, RowsPerStrip (278), StripByteCounts (279),
/// XResolution / YResolution (282, 283) = pixels per centimetre (the last continued-fraction
/// convergent with 32-bit terms: 5 µm → 2000/1, 70 µm → 1000/7), PlanarConfiguration (284) = 1,
/// ResolutionUnit (296) = 3 (centimetre), SampleFormat (339) = 3 (IEEE float), and the GeoTIFF tags
/// ModelPixelScaleTag (33550) = (pixel_x, pixel_y, 0) [m], ModelTiepointTag (33922) = raster (0, 0, 0)
/// → model (x_left, y_top, 0) [m], GeoKeyDirectoryTag (34735): GTModelTypeGeoKey = 32767
/// (user-defined: GDAL reads it as a LOCAL_CS, the work plane), GTRasterTypeGeoKey = 1 (PixelIsArea:
/// the tiepoint is the top-left corner of the top-left pixel), ProjLinearUnitsGeoKey = 9001 (metre).
/// So pixel (col, row) covers model x ∈ [x_left + col·pixel_x, x_left + (col+1)·pixel_x],
/// y ∈ [y_top − (row+1)·pixel_y, y_top − row·pixel_y].
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace scanhead
{
/// \brief Physical scale of a float image.
struct TiffScale
{
  double pixel_x_m = 0.0;   ///< pixel width [m], finite and > 0
  double pixel_y_m = 0.0;   ///< pixel height [m], finite and > 0
  double x_left_m = 0.0;    ///< model x of the left edge of column 0 [m]
  double y_top_m = 0.0;     ///< model y of the top edge of row 0 [m] (y grows upwards, rows downwards)
  std::string description;  ///< ImageDescription, 7-bit ASCII without NUL, e.g. "energy density [J/m^2], pixel 5e-06
                            ///< m"; empty: no tag
};

/// \brief The TIFF file bytes of a width × height float image.
/// \param[in] data width·height values, row-major, row 0 = the top of the image (an EnergyMap,
///   whose row 0 is the lowest y, must be flipped; then y_top_m = origin.y + height·pixel)
/// \throws std::invalid_argument if the size is not positive, data is null, the scale is not finite
///   and positive, the description is not 7-bit ASCII, or the file would pass the 4 GiB of classic TIFF
std::vector<std::uint8_t> encodeFloatTiff(int width, int height, const float* data, const TiffScale& scale);

/// \brief Writes encodeFloatTiff(...) to \p path atomically: to path + ".tmp", then renamed over \p path
/// (a reader never sees a partial file; an old file stays if writing fails).
/// \throws std::invalid_argument as encodeFloatTiff
/// \throws InputError naming the path if the file cannot be written or renamed
void writeFloatTiff(const std::string& path, int width, int height, const float* data, const TiffScale& scale);
}  // namespace scanhead
