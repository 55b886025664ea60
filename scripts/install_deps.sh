#!/usr/bin/env bash
# Installs everything scanhead needs from Debian 12's archive (ROS 1 lives under /usr).
# Idempotent: does nothing when every package is already installed.
set -euo pipefail
packages=(
  build-essential cmake catkin colcon python3-colcon-ros python3-colcon-bash
  ros-core-dev libroscpp-dev libtf2-ros-dev liburdfdom-dev libtinyxml-dev libeigen3-dev libyaml-cpp-dev zlib1g-dev
  libcli11-dev
  libnodeletlib-dev libnodeletlib-tools
  libgtest-dev librosbag-dev ros-message-generation libstd-msgs-dev libgeometry-msgs-dev
  libsensor-msgs-dev libtrajectory-msgs-dev libvisualization-msgs-dev libnav-msgs-dev
  python3-rosbag python3-roslaunch python3-rostest python3-rosnode python3-rostopic rosbash
  ros-robot-state-publisher python3-matplotlib python3-numpy python3-yaml python3-pil rviz
  clang libclang-rt-14-dev
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "installing ${#missing[@]} Debian packages: ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
