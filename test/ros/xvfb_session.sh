# Sourced by the rviz screenshot scripts (rviz_screenshot_test.sh, deployment_screenshot.sh): one Xvfb display and
# one ROS master on free numbers, rviz's 3D view found on screen, and cleanup of exactly the processes started here
# (by pid, on exit). Needs the package's devel/setup.bash sourced by the caller.
#
#   start_xvfb WxH LOG        Xvfb on a free display, DISPLAY exported, waits until it answers
#   launch_mobility LOG ARGS  roslaunch mobility_analysis mobility.launch ARGS on a free master port
#   wait_for_service NAME     until rosservice lists NAME (bounded by WAIT_SECONDS); status 0 when it did
#   wait_for_rviz_window      until a window named rviz exists (bounded by WAIT_SECONDS); status 0 when it did
#   rviz_view_geometry        "WxH+X+Y" of rviz's 3D view (the largest unnamed window: the Ogre render window)
#   stop_session              stops the launch and Xvfb started here

export LIBGL_ALWAYS_SOFTWARE=1
WAIT_SECONDS=${WAIT_SECONDS:-60}
XVFB_PID=""
LAUNCH_PID=""

stop_session() {
  [ -n "$LAUNCH_PID" ] && kill -INT "$LAUNCH_PID" 2>/dev/null && wait "$LAUNCH_PID" 2>/dev/null
  [ -n "$XVFB_PID" ] && kill "$XVFB_PID" 2>/dev/null && wait "$XVFB_PID" 2>/dev/null
  LAUNCH_PID=""
  XVFB_PID=""
}
trap stop_session EXIT

free_display() {
  local n
  for n in $(seq 90 140); do
    [ -e "/tmp/.X11-unix/X$n" ] || [ -e "/tmp/.X$n-lock" ] || { echo "$n"; return; }
  done
  echo 99
}

start_xvfb() {
  local display
  display=$(free_display)
  Xvfb ":$display" -screen 0 "$1x24" -nolisten tcp >"$2" 2>&1 &
  XVFB_PID=$!
  export DISPLAY=":$display"
  for _ in $(seq 1 50); do xwininfo -root >/dev/null 2>&1 && break; sleep 0.1; done
}

launch_mobility() {
  local log=$1 port
  shift
  port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
  export ROS_MASTER_URI="http://localhost:$port"
  roslaunch -p "$port" mobility_analysis mobility.launch "$@" >"$log" 2>&1 &
  LAUNCH_PID=$!
}

wait_for_service() {
  for _ in $(seq 1 $((WAIT_SECONDS * 2))); do
    rosservice list 2>/dev/null | grep -q "^$1\$" && return 0
    sleep 0.5
  done
  return 1
}

wait_for_rviz_window() {
  for _ in $(seq 1 $((WAIT_SECONDS * 2))); do
    xwininfo -root -tree 2>/dev/null | grep -qi "rviz" && return 0
    sleep 0.5
  done
  return 1
}

# `xwininfo -tree` lines read "WxH+x+y  +X+Y" (absolute X, Y last); the panels are named, the render window not.
rviz_view_geometry() {
  xwininfo -root -tree 2>/dev/null | awk '/\(has no name\)/ && match($0, /[0-9]+x[0-9]+\+[-0-9]+\+[-0-9]+ +\+[-0-9]+\+[-0-9]+/) {
    split(substr($0, RSTART, RLENGTH), f, /[x+ ]+/); if (f[1] * f[2] > best) { best = f[1] * f[2];
    g = f[1] "x" f[2] "+" f[5] "+" f[6] } } END { print g }'
}
