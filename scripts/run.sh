#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs the paper's road scene through ROS (the
# terrain, vehicle and driver nodelets in lock-step in one manager, headless), writing one bag and
# printing the speed-made-good. Extra arguments are roslaunch arguments of road_slope.launch,
# e.g.  ./scripts/run.sh grade:=12 duration:=20
source "$(dirname "$0")/lib.sh"
ensure_packages "${DM_CORE_PACKAGES[@]}" "${DM_ROS_PACKAGES[@]}"
build_core >/dev/null
build_catkin
ros_env
out="$DM_ROOT/results/road_slope"
mkdir -p "$out"
bag="$out/road_slope.bag"
result="$out/road_slope.result.yaml"
rm -f "$result"
say "run: roslaunch dem_mobility road_slope.launch (bag: $bag)"
# a master of its own, on a free port, so that a running roscore is left alone
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])')
ROS_MASTER_URI="http://localhost:$port" roslaunch -p "$port" dem_mobility road_slope.launch bag:="$bag" "$@"
[ -f "$result" ] || { echo "run.sh: the run wrote no result ($result)" >&2; exit 1; }
say "result: $result"
cat "$result"
status=$(yaml_get "$result" status)
smg=$(yaml_get "$result" speed_made_good)
if [ "$status" = error ]; then
  echo "run.sh: the run failed: $(yaml_get "$result" error)" >&2
  exit 1
fi
printf '\nspeed_made_good: %.3f m/s (%s)\n' "$smg" "$status"
echo "plot: python3 scripts/plot_speed.py $bag"
