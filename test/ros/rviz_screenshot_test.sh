#!/usr/bin/env bash
# rviz, as a user sees it: starts launch/mobility.launch (node, robot_state_publisher, mobility_viewer + rviz)
# under Xvfb for each model below, takes a screenshot of the whole screen and asserts that an over-constrained
# model shows red (redundant elements, colour (1, 0, 0)) and an exactly-constrained one shows none, and that every
# label and the title project inside rviz's 3D view with the camera mobility_viewer framed
# (check_label_projection.py); then the deployment of the SLE mast (deployment_screenshot.sh). PNGs are kept in
# BUILD_DIR/rviz_screenshots/.
#
#   test/ros/rviz_screenshot_test.sh [BUILD_DIR]      (default: build; needs a built package in BUILD_DIR/devel)
#
# Exit 0 when every case passes, 1 otherwise; one PASS/FAIL line per case. Starts its own Xvfb and ROS master on
# free numbers and stops exactly those processes (by pid) on exit.
set -uo pipefail
cd "$(dirname "$0")/../.."
SOURCE_DIR=$PWD
BUILD_DIR=$(realpath "${1:-build}")
OUT_DIR="$BUILD_DIR/rviz_screenshots"
mkdir -p "$OUT_DIR"
export PATH="/usr/bin:$PATH"  # the pyenv python3 shim has no ROS modules
# shellcheck disable=SC1091
set +u; source "$BUILD_DIR/devel/setup.bash"; set -u
export ROS_HOME="$OUT_DIR/ros_home"

# case name | URDF | mode | expect red (1) or none (0). MA_URDF_DIR overrides where the models are read from.
# The models of issue 11 whose view used to fail (door, SLE mast, Hoberman ring, millimetre Bennett), and the
# Bennett of the README; the SLE mast is the exactly-constrained one (no red).
URDF_DIR=${MA_URDF_DIR:-$SOURCE_DIR/urdf}
CASES=(
  "bennett|$URDF_DIR/bennett.urdf|auto|1"
  "door|$URDF_DIR/door.urdf|auto|1"
  "sle_mast|$URDF_DIR/sle_mast.urdf|planar|0"
  "hoberman_ring|$URDF_DIR/hoberman_ring.urdf|planar|1"
  "bennett_mm|$URDF_DIR/bennett_mm.urdf|auto|1"
)
# A pixel is "red" when it is the marker red, lit or not (test/ros/count_pixels.py says exactly what counts).
MIN_RED_PIXELS=40   # a redundant joint or link drawn at this view covers hundreds of pixels

# shellcheck source=test/ros/xvfb_session.sh
source "$SOURCE_DIR/test/ros/xvfb_session.sh"

failures=0
for entry in "${CASES[@]}"; do
  IFS='|' read -r name urdf mode expect_red <<<"$entry"
  png="$OUT_DIR/$name.png"
  log="$OUT_DIR/$name.log"
  if [ ! -f "$urdf" ]; then
    echo "FAIL rviz screenshot $name: no $urdf"
    failures=$((failures + 1))
    continue
  fi
  rm -f "$ROS_HOME/mobility_view.rviz"
  start_xvfb 1280x900 "$OUT_DIR/$name.xvfb.log"
  launch_mobility "$log" urdf:="$urdf" mode:="$mode" rviz:=true rviz_args:="--opengl 210"
  # Bounded waits: the service (the node analysed and published), then the rviz window, then frames to settle.
  ok=0
  wait_for_service /mobility_server/get_dof && ok=1
  window=0
  wait_for_rviz_window && window=1
  # rviz draws markers once the latched array and tf arrive; wait until two screenshots 1 s apart agree.
  previous=""
  for _ in $(seq 1 30); do
    sleep 1
    import -window root "$png" 2>/dev/null || continue
    current=$(md5sum <"$png")
    [ "$current" = "$previous" ] && break
    previous=$current
  done

  # Count only inside rviz's 3D view, not the panels, whose icons have red in them.
  view=$(rviz_view_geometry)
  if [ -n "$view" ]; then
    convert "$png" -crop "$view" +repage "$OUT_DIR/$name.view.png" 2>/dev/null
  else
    cp "$png" "$OUT_DIR/$name.view.png"
  fi
  red=$(/usr/bin/python3 "$SOURCE_DIR/test/ros/count_pixels.py" "$OUT_DIR/$name.view.png" red || echo -1)
  # Every label inside the 3D view, projected with the camera the viewer wrote.
  size=${view%%+*}
  [ -n "$size" ] || size=1280x900
  labels_ok=0
  if /usr/bin/python3 "$SOURCE_DIR/test/ros/check_label_projection.py" "$ROS_HOME/mobility_view.rviz" "$size" \
      >"$OUT_DIR/$name.labels.txt" 2>&1; then
    labels_ok=1
  fi
  labels_summary=$(tail -n 1 "$OUT_DIR/$name.labels.txt")
  stop_session
  if [ "$ok" != 1 ] || [ "$window" != 1 ] || [ "$red" -lt 0 ]; then
    echo "FAIL rviz screenshot $name: service=$ok window=$window red=$red (see $log)"
    failures=$((failures + 1))
  elif [ "$labels_ok" != 1 ]; then
    echo "FAIL rviz screenshot $name: $labels_summary (see $OUT_DIR/$name.labels.txt, $png)"
    failures=$((failures + 1))
  elif [ "$expect_red" = 1 ] && [ "$red" -lt "$MIN_RED_PIXELS" ]; then
    echo "FAIL rviz screenshot $name: over-constrained but only $red red pixels ($png)"
    failures=$((failures + 1))
  elif [ "$expect_red" = 0 ] && [ "$red" -gt 0 ]; then
    echo "FAIL rviz screenshot $name: exactly constrained but $red red pixels ($png)"
    failures=$((failures + 1))
  else
    echo "PASS rviz screenshot $name: $red red pixels in the 3D view $view, expected $([ "$expect_red" = 1 ] && echo "some" || echo "none"); $labels_summary ($png)"
  fi
done
# The deployment: the folded SLE mast deployed by ~deploy, forces shown (test/ros/deployment_screenshot.sh).
if "$SOURCE_DIR/test/ros/deployment_screenshot.sh" "$OUT_DIR/deployment.png" "$BUILD_DIR" >"$OUT_DIR/deployment.log" 2>&1; then
  tail -n 1 "$OUT_DIR/deployment.log"
else
  tail -n 1 "$OUT_DIR/deployment.log"
  failures=$((failures + 1))
fi
exit $((failures > 0))
