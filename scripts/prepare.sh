# Sourced by run_virtual_machine.sh and run_tests.sh (from the repository root): installs what is
# missing, builds, and sets up the ROS environment on loopback.
scripts/install_deps.sh
# SCANHEAD_CMAKE_ARGS: extra CMake options (run_tests.sh asks for the benchmarks and fuzzers).
scripts/build.sh ${SCANHEAD_CMAKE_ARGS:-}
set +u  # colcon's setup scripts read unset variables
. install/setup.sh
set -u
export PATH="/usr/bin:$PATH"  # the system python3 has the ROS modules
export ROS_IP=127.0.0.1
