/// \file ros_launch_end.hpp
/// \brief Ending a roslaunch graph cleanly once its job is done: the roslaunch process that started this node (or the
/// nodelet manager holding it) is asked to stop with SIGINT, as a user's Ctrl-C does. roslaunch then stops every
/// node itself and exits 0, without the red "REQUIRED process has died" banner that a required node's own exit
/// prints (that path stays for failures, so a failed job still reads as one).
#pragma once

#include <sys/types.h>

namespace scanhead
{
/// \brief The pid of the roslaunch process among this process's ancestors (its command line runs roslaunch; rostest
/// and a shell are not it), or -1.
pid_t roslaunchAncestor();
}  // namespace scanhead
