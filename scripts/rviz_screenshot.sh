#!/usr/bin/env bash
# Runs a scene with rviz under a virtual display (Xvfb) and saves what a user sees:
#   ./scripts/rviz_screenshot.sh [OUT.png] [seconds into the run] [LAUNCH.launch] [roslaunch args...]
# LAUNCH defaults to road_slope.launch (run paced at real time, rviz on). Examples:
#   ./scripts/rviz_screenshot.sh docs/rviz-cone.png 40 cone_penetrometer.launch fidelity:=tiny cohesion_factor:=5
#   ./scripts/rviz_screenshot.sh docs/rviz-cone-replay.png 8 replay.launch bag:=$HOME/.ros/dem_mobility/cone_penetrometer.bag view:=cone
#   ./scripts/rviz_screenshot.sh docs/rviz-soil-slope.png 25 replay.launch bag:=$HOME/.ros/dem_mobility/soil_slope.bag view:=soil_slope rate:=0.1
#     (the soil scene: its preparation takes minutes, so the picture comes from its bag)
source "$(dirname "$0")/lib.sh"
out="${1:-$DM_ROOT/docs/rviz-road-slope.png}"; at="${2:-12}"; shift $(( $# > 2 ? 2 : $# ))
launch_file=road_slope.launch
if [[ "${1:-}" == *.launch ]]; then launch_file="$1"; shift; fi
case "$launch_file" in
  road_slope.launch) extra=(rviz:=true pace:=1 duration:=30) ;;
  replay.launch) extra=() ;;
  *) extra=(rviz:=true) ;;
esac
ensure_packages "${DM_CORE_PACKAGES[@]}" "${DM_ROS_PACKAGES[@]}" "${DM_CHECK_PACKAGES[@]}"
build_catkin >/dev/null
ros_env
display=":$(( 90 + RANDOM % 9 ))"
Xvfb "$display" -screen 0 1280x760x24 >/dev/null 2>&1 &
xvfb=$!
port=$(PYTHONPATH="$DM_ROOT/python" python3 -c 'from dem_mobility_tools.runs import free_port; print(free_port())')
tmp="$(mktemp -d)"
trap 'kill $launch $xvfb 2>/dev/null; rm -rf "$tmp"' EXIT
bag_arg=(bag:="$tmp/run.bag")  # unless the caller names one (to replay it later)
[[ "$launch_file" == replay.launch || " $* " == *" bag:="* ]] && bag_arg=()
DISPLAY="$display" LIBGL_ALWAYS_SOFTWARE=1 ROS_MASTER_URI="http://localhost:$port" \
  roslaunch -p "$port" dem_mobility "$launch_file" "${extra[@]}" "${bag_arg[@]}" "$@" \
  >"$tmp/launch.log" 2>&1 &
launch=$!
sleep "$at"
DISPLAY="$display" import -window root "$out"
echo "$out"
