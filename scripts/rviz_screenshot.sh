#!/usr/bin/env bash
# Runs the road scene with rviz under a virtual display (Xvfb) and saves what a user sees:
#   ./scripts/rviz_screenshot.sh [OUT.png] [seconds into the run] [roslaunch args...]
source "$(dirname "$0")/lib.sh"
out="${1:-$DM_ROOT/docs/rviz-road-slope.png}"; at="${2:-12}"; shift $(( $# > 2 ? 2 : $# ))
ensure_packages "${DM_ROS_PACKAGES[@]}" "${DM_CHECK_PACKAGES[@]}"
build_catkin >/dev/null
ros_env
display=":$(( 90 + RANDOM % 9 ))"
Xvfb "$display" -screen 0 1280x760x24 >/dev/null 2>&1 &
xvfb=$!
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])')
tmp="$(mktemp -d)"
trap 'kill $launch $xvfb 2>/dev/null; rm -rf "$tmp"' EXIT
DISPLAY="$display" LIBGL_ALWAYS_SOFTWARE=1 ROS_MASTER_URI="http://localhost:$port" \
  roslaunch -p "$port" dem_mobility road_slope.launch rviz:=true pace:=1 duration:=30 bag:="$tmp/run.bag" "$@" \
  >"$tmp/launch.log" 2>&1 &
launch=$!
sleep "$at"
DISPLAY="$display" import -window root "$out"
echo "$out"
