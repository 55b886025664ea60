#!/usr/bin/env bash
# Builds the package with colcon into build/ and install/ at the repository root.
set -euo pipefail
cd "$(dirname "$0")/.."
# The system python3 has the ROS modules; a pyenv python3 on PATH does not.
export PATH="/usr/bin:$PATH"
colcon build --event-handlers console_direct- --cmake-args -DPYTHON_EXECUTABLE=/usr/bin/python3 \
  -DCMAKE_BUILD_TYPE=Release "$@"
