#!/usr/bin/env bash
# Issue 17, item 3: rviz framed on the job. Under a virtual X server (Xvfb), the graph runs a job of two 10 mm
# THESIS squares with rviz:=true (the head in 3D, and rviz_job_view: the job from above, framed on its bounding box);
# once the energy stage is done, a screenshot of the screen must show the job drawn in the job view: energy-map
# pixels over a large share of its render area, spread over both halves (two squares side by side, centred).
# usage: rviz_screenshot.sh [SCREENSHOT.png]    exit 77: no Xvfb, xwd or rviz here (install_deps.sh installs them)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
launch_dir="$(cd "$here/../../launch" && pwd)"  # full paths: the package may be found twice
for tool in Xvfb xwd rviz roslaunch; do
  command -v "$tool" > /dev/null || { echo "SKIP: no $tool (scripts/install_deps.sh installs it)"; exit 77; }
done
tmp=$(mktemp -d /tmp/scanhead_rviz.XXXXXX)
xvfb_pid="" launch_pid=""
cleanup() {
  [ -z "$launch_pid" ] || { kill -INT "$launch_pid" 2> /dev/null || true; wait "$launch_pid" 2> /dev/null || true; }
  [ -z "$xvfb_pid" ] || { kill "$xvfb_pid" 2> /dev/null || true; wait "$xvfb_pid" 2> /dev/null || true; }
  [ -n "${SCANHEAD_KEEP_TMP:-}" ] || rm -rf "$tmp"
}
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; [ ! -f "$tmp/launch.log" ] || tail -20 "$tmp/launch.log" >&2; exit 1; }

# A display of our own: the first free number from 90.
display=90
while [ -e "/tmp/.X$display-lock" ] || [ -e "/tmp/.X11-unix/X$display" ]; do display=$((display + 1)); done
Xvfb ":$display" -screen 0 1680x800x24 -nolisten tcp > "$tmp/xvfb.log" 2>&1 &
xvfb_pid=$!
for _ in $(seq 50); do [ -e "/tmp/.X11-unix/X$display" ] && break; sleep 0.1; done
[ -e "/tmp/.X11-unix/X$display" ] || fail "Xvfb did not start: $(cat "$tmp/xvfb.log")"

export DISPLAY=":$display" LIBGL_ALWAYS_SOFTWARE=1 ROS_IP=127.0.0.1
export ROS_MASTER_URI="http://127.0.0.1:${SCANHEAD_ROS_PORT:-$((40000 + $$ % 10000))}"
roslaunch "$launch_dir/virtual_machine.launch" job:=squares:rows=1,columns=2 rviz:=true > "$tmp/launch.log" 2>&1 &
launch_pid=$!
# The job is done when energy/metrics (latched) has its message; the master may not be up yet at first.
for _ in $(seq 60); do
  timeout 10 rostopic echo -n 1 /energy/metrics > /dev/null 2>&1 && break
  kill -0 "$launch_pid" 2> /dev/null || fail "the graph ended before the job was done"
  sleep 1
done
timeout 10 rostopic echo -n 1 /energy/metrics > /dev/null 2>&1 || fail "the job was not done within 2 min"
grep -q "rviz_job_view: the job spans 25.000 x 10.000 mm around (0.000, 0.000) mm" "$tmp/launch.log" \
  || fail "rviz_job_view did not frame the job: $(grep rviz_job_view "$tmp/launch.log" || true)"
# The job view (rviz/job_view.rviz.in: window at x 910, 760 x 760) without its menu and tool bar: the energy map's
# colours (saturated, unlike rviz's greys) over the job's two squares. Screenshots until it shows (rviz starts, gets
# the map and draws it in software: seconds on a loaded machine), at most 90 s.
cat > "$tmp/check.py" << 'PY'
import sys
import numpy as np
from PIL import Image
rgb = np.asarray(Image.open(sys.argv[1]).convert("RGB")).astype(int)
view = rgb[80:740, 930:1650]
saturated = (view.max(axis=2) - view.min(axis=2)) > 60
share = saturated.mean()
left, right = saturated[:, : view.shape[1] // 2].mean(), saturated[:, view.shape[1] // 2 :].mean()
rows = np.nonzero(saturated.any(axis=1))[0]
print("job view: %.1f %% coloured (left half %.1f %%, right half %.1f %%), rows %d-%d of %d"
      % (100 * share, 100 * left, 100 * right, rows.min() if len(rows) else -1, rows.max() if len(rows) else -1,
         view.shape[0]))
# Two 10 mm squares 25 mm wide framed at 85 %: about 0.55 x 0.34 of the view is map.
ok = share > 0.10 and left > 0.05 and right > 0.05 and len(rows) > 0 and rows.min() > 20 and rows.max() < view.shape[0] - 20
sys.exit(0 if ok else 1)
PY
shown=false
for _ in $(seq 30); do
  sleep 3
  xwd -root -silent > "$tmp/screen.xwd" || fail "xwd could not dump the screen"
  /usr/bin/python3 "$here/xwd_to_png.py" "$tmp/screen.xwd" "$tmp/screen.png"
  if /usr/bin/python3 "$tmp/check.py" "$tmp/screen.png" > "$tmp/check.out"; then shown=true; break; fi
done
cat "$tmp/check.out"
[ -z "${1:-}" ] || cp "$tmp/screen.png" "$1"
$shown || fail "the screenshot does not show the job within 90 s (saved with: rviz_screenshot.sh FILE.png)"
echo "rviz: the job is drawn, framed, in the job view"
