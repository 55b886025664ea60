/// \file rviz_job_view_main.cpp
/// \brief rviz framed on the job (issue 17): reads the job and the settings the graph runs with (parameters ~job,
/// config, config_overrides: placement included), takes its bounding box on the work plane, writes
/// rviz/job_view.rviz.in with the view centred on it (orthographic, from above; the box filling 85 % of the view) and
/// replaces itself with rviz on that file, passing on its ROS arguments (__name:= …). A job that cannot be read is
/// framed as the whole field.
#include <ros/ros.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "ros_config.hpp"
#include "scanhead/common/text_file.hpp"
#include "scanhead/job/job_files.hpp"
#include "scanhead/job/job_placement.hpp"

namespace
{
constexpr double kViewPixels = 640.0;  ///< the render panel's smaller side in job_view.rviz.in's window [px]
constexpr double kFill = 0.85;         ///< share of the view the job's box takes
}  // namespace

int main(int argc, char** argv)
{
  std::vector<std::string> ros_args;  // __name:=, __log:= and remappings, for rviz
  for (int i = 1; i < argc; ++i)
    if (std::strstr(argv[i], ":=") != nullptr)
      ros_args.push_back(argv[i]);
  ros::init(argc, argv, "rviz_job_view", ros::init_options::NoRosout);
  ros::NodeHandle nh, private_nh("~");
  std::string job_argument = "corner", template_path;
  private_nh.param("job", job_argument, job_argument);
  private_nh.param("template", template_path, template_path);
  Eigen::Vector2d lo(-0.175, -0.175), hi(0.175, 0.175);  // the field, if the job cannot be read
  try
  {
    const scanhead::ChainConfig config = scanhead::chainConfigFromParams(nh);
    const scanhead::Job job = scanhead::loadJob(job_argument, config.cam);
    if (!scanhead::rotatedBoundingBox(job, 0.0, lo, hi))
      lo = hi = Eigen::Vector2d::Zero();
  }
  catch (const std::exception& e)
  {
    ROS_WARN("rviz_job_view: %s; the view frames the whole field", e.what());
  }
  const Eigen::Vector2d size = (hi - lo).cwiseMax(Eigen::Vector2d::Constant(1e-3));  // a point job: 1 mm
  const double scale = kFill * kViewPixels / std::max(size.x(), size.y());
  std::string text = scanhead::readFileOrEmpty(template_path);
  if (text.empty())
  {
    ROS_ERROR("rviz_job_view: cannot read ~template '%s' (rviz/job_view.rviz.in)", template_path.c_str());
    return 1;
  }
  scanhead::replaceAll(text, "@VIEW_X@", std::to_string(0.5 * (lo.x() + hi.x())));
  scanhead::replaceAll(text, "@VIEW_Y@", std::to_string(0.5 * (lo.y() + hi.y())));
  scanhead::replaceAll(text, "@VIEW_SCALE@", std::to_string(scale));
  const char* ros_home = std::getenv("ROS_HOME");
  const char* home = std::getenv("HOME");
  const std::string path =
      (ros_home != nullptr ? std::string(ros_home) : std::string(home != nullptr ? home : "/tmp") + "/.ros") +
      "/scanhead_job_view.rviz";
  scanhead::writeTextFile(path, text);
  ROS_INFO("rviz_job_view: the job spans %.3f x %.3f mm around (%.3f, %.3f) mm", size.x() * 1e3, size.y() * 1e3,
           0.5e3 * (lo.x() + hi.x()), 0.5e3 * (lo.y() + hi.y()));
  ros::shutdown();
  std::fflush(nullptr);  // the log lines above, before exec drops the buffers
  std::vector<std::string> words = {"rviz", "-d", path};
  words.insert(words.end(), ros_args.begin(), ros_args.end());
  std::vector<char*> args;
  for (std::string& w : words)
    args.push_back(w.data());
  args.push_back(nullptr);
  ::execvp("rviz", args.data());
  ROS_ERROR("rviz_job_view: cannot start rviz: %s", std::strerror(errno));
  return 1;
}
