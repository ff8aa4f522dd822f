#!/usr/bin/env bash
# The deployment picture of the README: starts launch/mobility.launch on the folded four-unit SLE mast
# (urdf/sle_deployable_folded.urdf) with rviz under Xvfb and the `forces` namespace shown, deploys it with
# ~deploy by its base cable (locked at the end, so the structure is prestressed), waits until mobility_viewer has
# refit the view on the deployed mast, and saves rviz's 3D view as a PNG.
#
#   test/ros/deployment_screenshot.sh [OUT.png] [BUILD_DIR]   (defaults: build/deployment_rviz.png, build)
#
# Also asserts what the picture must show: the ~deploy answer (success, final DOF 0, prestressable) and blue
# (tension) pixels of the prestressed cables in the 3D view. Exit 0 on success, 1 otherwise. Starts its own Xvfb
# and ROS master on free numbers and stops exactly those processes (by pid) on exit.
set -uo pipefail
cd "$(dirname "$0")/../.."
SOURCE_DIR=$PWD
BUILD_DIR=$(realpath "${2:-build}")
OUT=$(realpath -m "${1:-$BUILD_DIR/deployment_rviz.png}")
WORK="$BUILD_DIR/deployment_screenshot"
mkdir -p "$WORK" "$(dirname "$OUT")"
export PATH="/usr/bin:$PATH"  # the pyenv python3 shim has no ROS modules
# shellcheck disable=SC1091
set +u; source "$BUILD_DIR/devel/setup.bash"; set -u
export ROS_HOME="$WORK/ros_home"

# shellcheck source=test/ros/xvfb_session.sh
source "$SOURCE_DIR/test/ros/xvfb_session.sh"

start_xvfb 1500x1400 "$WORK/xvfb.log"
rm -f "$ROS_HOME/mobility_view.rviz"
launch_mobility "$WORK/launch.log" urdf:="$SOURCE_DIR/urdf/sle_deployable_folded.urdf" mode:=planar rviz:=true \
  forces:=true rviz_args:="--opengl 210"

ok=0
wait_for_service /mobility_server/deploy && ok=1
wait_for_rviz_window
sleep 4  # rviz shows the folded mast
import -window root "$WORK/folded.png" 2>/dev/null

rosservice call /mobility_server/deploy \
  "{cable: active_base, steps: 100, duration: 3.0, lock_active_cables: true}" >"$WORK/deploy.txt" 2>&1
cat "$WORK/deploy.txt" | grep -E "^(success|message|final_length|final_dof|stopped_by|reason|steps):"
grep -q "prestressable: True" "$WORK/deploy.txt" || ok=0
grep -q "^success: True" "$WORK/deploy.txt" || ok=0
grep -q "^final_dof: 0" "$WORK/deploy.txt" || ok=0

# mobility_viewer refits the view once the deployed markers are still (rviz restarts); wait for stable frames.
sleep 3
previous=""
for _ in $(seq 1 40); do
  sleep 1
  import -window root "$WORK/deployed.png" 2>/dev/null || continue
  current=$(md5sum <"$WORK/deployed.png")
  [ "$current" = "$previous" ] && grep -q "moved out of the view" "$WORK/launch.log" && break
  previous=$current
done

view=$(rviz_view_geometry)
if [ -n "$view" ]; then
  convert "$WORK/deployed.png" -crop "$view" +repage "$WORK/deployed.view.png"
else
  cp "$WORK/deployed.png" "$WORK/deployed.view.png"
fi
# Blue of tension (toForceColor: b well above r and g).
blue=$(/usr/bin/python3 "$SOURCE_DIR/test/ros/count_pixels.py" "$WORK/deployed.view.png" blue || echo -1)
# Trimmed to what differs from the background by more than the grid does, with a margin.
convert "$WORK/deployed.view.png" -fuzz 25% -trim +repage -bordercolor 'rgb(48,48,48)' -border 24 \
  -resize '900x900>' -strip -colors 128 "PNG8:$OUT"
stop_session
size=$(stat -c %s "$OUT" 2>/dev/null || echo 0)
if [ "$ok" = 1 ] && [ "$blue" -gt 100 ] && [ "$size" -gt 0 ] && [ "$size" -lt 200000 ]; then
  echo "PASS deployment screenshot: $blue blue pixels, $size bytes -> $OUT"
  exit 0
fi
echo "FAIL deployment screenshot: service/deploy ok=$ok, blue=$blue, size=$size (see $WORK)"
exit 1
