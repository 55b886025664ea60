/// \file ros_beam_view.cpp
/// \brief The beam and the spot trail for rviz (ros_beam_view.hpp).
#include "ros_beam_view.hpp"

#include <visualization_msgs/MarkerArray.h>

#include "ros_energy_views.hpp"
#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
constexpr std::uint64_t kTrailStride = 20;  ///< one trail point per 20 samples (0.2 ms: 0.2 mm at 1 m/s)

geometry_msgs::Point toPoint(double x, double y, double z)
{
  geometry_msgs::Point p;
  p.x = x;
  p.y = y;
  p.z = z;
  return p;
}
}  // namespace

BeamView::BeamView(ros::NodeHandle& nh, const OpticalModel& optics, double rate_hz, double trail_s)
  : optics_(optics)
  , publisher_(nh.advertise<visualization_msgs::MarkerArray>("optics/beam", 1))
  , period_(1.0 / rate_hz)
  , trail_s_(trail_s)
{
}

void BeamView::record(const JointChunk& joints, const SpotChunk& spots)
{
  if (publisher_.getNumSubscribers() == 0 || joints.samples.empty())
    return;
  const std::size_t keep = static_cast<std::size_t>(trail_s_ / (kTrailStride * spots.period_s)) + 1;
  for (std::size_t k = 0; k < spots.samples.size(); ++k, ++trail_samples_)
    if (trail_samples_ % kTrailStride == 0)
      trail_.push_back(spots.samples[k].actual);
  while (trail_.size() > keep)
    trail_.pop_front();
  const ros::WallTime now = ros::WallTime::now();
  if (now - last_publish_ < period_)
    return;
  last_publish_ = now;
  publish(joints.samples.back().position, !spots.samples.empty() && spots.samples.back().power_w > 0.0);
}

void BeamView::publish(const Eigen::Vector2d& angles, bool laser_on)
{
  visualization_msgs::MarkerArray markers;
  // The beam: 2 mm wide so that it shows at the head's scale; red with the laser on.
  visualization_msgs::Marker beam = lineStripMarker("scanhead_base", "beam", 0, 2e-3, laser_on ? 1.0f : 0.6f,
                                                    laser_on ? 0.1f : 0.6f, laser_on ? 0.1f : 0.6f);
  try
  {
    for (const Eigen::Vector3d& p : optics_.beamPoints(angles))
      beam.points.push_back(toPoint(p.x(), p.y(), p.z()));
    markers.markers.push_back(beam);
  }
  catch (const NumericalError&)
  {
    // Angles the beam cannot take (a diverging servo): no beam drawn.
  }
  visualization_msgs::Marker trail = lineStripMarker("work_plane_defect", "spot_trail", 1, 1e-4, 1.0f, 0.9f, 0.2f);
  for (const Eigen::Vector2d& p : trail_)
    trail.points.push_back(toPoint(p.x(), p.y(), 2e-4));  // just above the energy map
  if (trail.points.size() >= 2)
    markers.markers.push_back(trail);
  if (!markers.markers.empty())
    publisher_.publish(markers);
}
}  // namespace scanhead
