/// \file cli_internal.hpp
/// \brief Private pieces shared by the CLI reader sources (header, ASCII and binary geometry).
#pragma once

#include <cstddef>
#include <string>

#include "scanhead/job/formats/cli_format.hpp"

namespace scanhead
{
namespace cli
{
/// \brief What the header says, and where the geometry starts.
struct Header
{
  bool binary = false;
  bool aligned = false;             ///< $$ALIGN
  double units_mm = 0.0;            ///< mm per coordinate unit
  long declared_layers = -1;        ///< $$LAYERS, -1 if absent
  std::size_t geometry_offset = 0;  ///< first byte after $$HEADEREND (aligned if $$ALIGN)
  std::size_t geometry_line = 1;    ///< line number at geometry_offset (ASCII)
};

/// \brief Reads the header. \throws InputError "source:line: ..."
Header parseHeader(const std::string& bytes, const std::string& source);

/// \brief Builds the Job as the geometry is read: layer selection, CLI+ state, jumps, units.
class JobBuilder
{
public:
  JobBuilder(const CliReadOptions& options, double m_per_unit);

  void startLayer()
  {
    ++layers_;
    active_ = want_ < 0 || want_ == layers_ - 1;
  }
  bool inLayer() const { return layers_ > 0; }
  int layers() const { return layers_; }

  void setSpeed(double speed_mps) { speed_mps_ = speed_mps; }
  void setPower(double power_w) { power_w_ = power_w; }

  /// \pre \p n_points was checked against the remaining input
  void beginMark(std::size_t n_points, PolylineRole role);  ///< $$POLYLINE: Contour, $$HATCHES: Hatch
  void addPoint(double x_units, double y_units)
  {
    current_.points.emplace_back(x_units * m_per_unit_, y_units * m_per_unit_);
  }
  /// \brief Surveys the mark (every layer: Job::file) and, in the kept layer, stores it (dropped if < 2
  /// points), preceded by a jump if it does not start where the previous stored mark ended.
  void endMark();

  /// \brief The job. \throws InputError if the requested layer is not in the file
  Job finish(const std::string& source, long declared_layers);

private:
  Job job_;
  Polyline current_;
  Eigen::Vector2d last_end_ = Eigen::Vector2d::Zero();  ///< end of the last stored mark
  bool has_last_ = false;
  Eigen::Vector2d surveyed_end_ = Eigen::Vector2d::Zero();  ///< end of the last mark of any layer
  bool has_surveyed_ = false;
  int want_ = 0;
  int layers_ = 0;
  bool active_ = false;
  double m_per_unit_ = 1e-3;
  double speed_mps_ = 1.0;
  double power_w_ = 0.0;
  double jump_speed_mps_ = 1.0;
};

/// \brief ASCII geometry from \p header.geometry_offset to the end. \throws InputError
void parseAsciiGeometry(const std::string& bytes, const Header& header, const std::string& source, JobBuilder& builder);

/// \brief Binary geometry from \p header.geometry_offset to the end. \throws InputError
void parseBinaryGeometry(const std::string& bytes, const Header& header, const std::string& source,
                         JobBuilder& builder);

/// \brief \p text cut to \p max_chars with non-printable bytes as \\xNN (for messages).
std::string printable(const char* begin, const char* end, std::size_t max_chars = 24);
}  // namespace cli
}  // namespace scanhead
