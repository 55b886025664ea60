/// \file ros_beam_view.hpp
/// \brief What rviz draws of the optics while a job runs (issue 17): the laser beam through the chain (source,
/// mirror X, mirror Y, the two windows, the spot: OpticalModel::beamPoints of the latest joint angles, in
/// scanhead_base, red while the laser is on, grey while off) and the spot's trail (the last trail_s of actual spots
/// on the work plane), as the MarkerArray optics/beam at a display rate (30 Hz), only while someone subscribes.
/// A view: the streams and the results do not depend on it.
#pragma once

#include <ros/ros.h>

#include <Eigen/Core>
#include <deque>
#include <mutex>

#include "scanhead/common/chunk.hpp"
#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
class BeamView
{
public:
  /// \param[in] optics outlives this
  BeamView(ros::NodeHandle& nh, const OpticalModel& optics, double rate_hz = 30.0, double trail_s = 0.3);

  /// \brief Records the latest state of a processed chunk (called from the stage's thread).
  void record(const JointChunk& joints, const SpotChunk& spots);

private:
  void publish();

  const OpticalModel& optics_;
  ros::Publisher publisher_;
  ros::Timer timer_;
  double trail_s_;
  std::mutex mutex_;
  Eigen::Vector2d angles_ = Eigen::Vector2d::Zero();  ///< last joint angles [rad]
  bool laser_on_ = false;
  bool fresh_ = false;                 ///< something new since the last publish
  std::deque<Eigen::Vector2d> trail_;  ///< actual spots, one per kTrailStride samples [m]
  std::uint64_t trail_samples_ = 0;    ///< samples recorded (for the stride)
};
}  // namespace scanhead
