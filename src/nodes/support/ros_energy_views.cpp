#include "ros_energy_views.hpp"

#include "scanhead/report/colour_map.hpp"

namespace scanhead
{
namespace
{
constexpr const char* kPlaneFrame = "work_plane_defect";

geometry_msgs::Point point(const Eigen::Vector2d& p, double z)
{
  geometry_msgs::Point q;
  q.x = p.x();
  q.y = p.y();
  q.z = z;
  return q;
}

}  // namespace

visualization_msgs::Marker lineStripMarker(const std::string& frame, const std::string& ns, int id, double width,
                                           float r, float g, float b)
{
  visualization_msgs::Marker m;
  m.header.frame_id = frame;
  m.ns = ns;
  m.id = id;
  m.type = visualization_msgs::Marker::LINE_STRIP;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = width;
  m.color.r = r;
  m.color.g = g;
  m.color.b = b;
  m.color.a = 1.0;
  return m;
}

sensor_msgs::Image energyImage(const EnergyMap& map)
{
  const RgbImage rgb = renderEnergyMap(map, 0.0, 2000);
  sensor_msgs::Image image;
  image.header.frame_id = kPlaneFrame;
  image.width = rgb.width;
  image.height = rgb.height;
  image.encoding = "rgb8";
  image.step = 3 * rgb.width;
  image.data = rgb.rgb;
  return image;
}

/// The map downsampled to at most 1000 cells a side, 0..100 of the peak, for rviz's Map display.
nav_msgs::OccupancyGrid energyGrid(const EnergyMap& map)
{
  const int factor = std::max(1, (std::max(map.width(), map.height()) + 999) / 1000);
  nav_msgs::OccupancyGrid grid;
  grid.header.frame_id = kPlaneFrame;
  grid.info.resolution = static_cast<float>(map.pixel() * factor);
  grid.info.width = (map.width() + factor - 1) / factor;
  grid.info.height = (map.height() + factor - 1) / factor;
  grid.info.origin.position.x = map.origin().x();
  grid.info.origin.position.y = map.origin().y();
  grid.info.origin.orientation.w = 1.0;
  const double peak = std::max(map.peak(), 1e-300);
  grid.data.assign(static_cast<std::size_t>(grid.info.width) * grid.info.height, 0);
  for (int r = 0; r < map.height(); ++r)
    for (int c = 0; c < map.width(); ++c)
    {
      auto& cell = grid.data[static_cast<std::size_t>(r / factor) * grid.info.width + c / factor];
      cell = std::max<std::int8_t>(cell, static_cast<std::int8_t>(100.0 * map.at(c, r) / peak));
    }
  return grid;
}

/// Commanded path (marks green, jumps grey) and the actual spot path (red), 1 µm above the plane.
visualization_msgs::MarkerArray pathMarkers(const Job& job, const TraceRecorder& trace)
{
  visualization_msgs::MarkerArray markers;
  int id = 0;
  for (const Polyline& line : job.polylines)
  {
    const bool mark = line.type == PolylineType::Mark;
    auto m = lineStripMarker(kPlaneFrame, "commanded", id++, 10e-6, mark ? 0.1f : 0.6f, mark ? 0.8f : 0.6f,
                             mark ? 0.2f : 0.6f);
    for (const Eigen::Vector2d& p : line.points)
      m.points.push_back(point(p, 1e-6));
    markers.markers.push_back(m);
  }
  auto actual = lineStripMarker(kPlaneFrame, "actual", 0, 5e-6, 0.9f, 0.1f, 0.1f);
  for (const TraceRow& row : trace.rows())
    actual.points.push_back(point(row.spot.actual, 2e-6));
  markers.markers.push_back(actual);
  return markers;
}
}  // namespace scanhead
