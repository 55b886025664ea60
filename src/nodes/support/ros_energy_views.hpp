/// \file ros_energy_views.hpp
/// \brief What rviz shows of a finished job: the energy image, the map on the work plane and the
/// commanded vs actual paths, all in the work_plane_defect frame.
#pragma once

#include <nav_msgs/OccupancyGrid.h>
#include <sensor_msgs/Image.h>
#include <visualization_msgs/MarkerArray.h>

#include "scanhead/chain/trace_recorder.hpp"
#include "scanhead/energy/energy_map.hpp"
#include "scanhead/job/scan_job.hpp"

namespace scanhead
{
/// \brief The map in the inferno colour map with its colour bar (at most 2000 px a side).
sensor_msgs::Image energyImage(const EnergyMap& map);

/// \brief The map downsampled to at most 1000 cells a side, 0..100 of the peak, for rviz's Map display.
nav_msgs::OccupancyGrid energyGrid(const EnergyMap& map);

/// \brief An opaque LINE_STRIP in \p frame, \p width [m] wide, colour (\p r, \p g, \p b); its points to be added.
visualization_msgs::Marker lineStripMarker(const std::string& frame, const std::string& ns, int id, double width,
                                           float r, float g, float b);

/// \brief Commanded path (marks green, jumps grey) and the actual spot path (red), just above the plane.
visualization_msgs::MarkerArray pathMarkers(const Job& job, const TraceRecorder& trace);
}  // namespace scanhead
