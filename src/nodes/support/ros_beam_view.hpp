/// \file ros_beam_view.hpp
/// \brief What rviz draws of the optics while a job runs (issue 17): the laser beam through the chain (source, mirror
/// X, mirror Y, the two windows, the spot: OpticalModel::beamPoints of the latest joint angles, in scanhead_base, red
/// while the laser is on, grey while off) and the spot's trail (the last trail_s of actual spots on the work plane), as
/// the MarkerArray optics/beam at a display rate (at most 30 Hz), only while someone subscribes.
///
/// Published from the stage's own thread as its chunks are processed (no timer: nothing of it runs on the node's
/// callback threads, so unloading a nodelet never meets a callback in flight). A view: the streams and the results
/// do not depend on it.
#pragma once

#include <ros/ros.h>

#include <Eigen/Core>
#include <deque>

#include "scanhead/common/chunk.hpp"
#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
class BeamView
{
public:
  /// \param[in] optics outlives this
  BeamView(ros::NodeHandle& nh, const OpticalModel& optics, double rate_hz = 30.0, double trail_s = 0.3);

  /// \brief Records the latest state of a processed chunk and publishes it when a display period has passed (called
  /// from the stage's thread only).
  void record(const JointChunk& joints, const SpotChunk& spots);

private:
  void publish(const Eigen::Vector2d& angles, bool laser_on);

  const OpticalModel& optics_;
  ros::Publisher publisher_;
  ros::WallDuration period_;
  ros::WallTime last_publish_;
  double trail_s_;
  std::deque<Eigen::Vector2d> trail_;  ///< actual spots, one per kTrailStride samples [m]
  std::uint64_t trail_samples_ = 0;    ///< samples recorded (for the stride)
};
}  // namespace scanhead
