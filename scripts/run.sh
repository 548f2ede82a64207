#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs the paper's central scene through ROS:
# the vehicle accelerating up a grade on the moving DEM soil patch (soil_slope.launch at the soil
# level below; the terrain, vehicle and driver nodelets in lock-step in one manager, headless),
# writing one bag and printing the speed-made-good with its error estimate. The road scene is one
# argument away. Extra arguments are roslaunch arguments of the launch file:
#   ./scripts/run.sh                                 the soil scene (grade 12 deg, CI 100 psi, level below)
#   ./scripts/run.sh grade:=20 cone_index:=60        the same with other launch arguments
#   ./scripts/run.sh road [grade:=12 duration:=20]   the road scene (road_slope.launch)
source "$(dirname "$0")/lib.sh"
# the soil's level for the main job (coarse by default; medium, coarse and tiny have a cone index
# calibration table, paper and fine none yet); fidelity:=... overrides it
SOIL_FIDELITY="${DM_SOIL_FIDELITY:-coarse}"

scene=soil_slope
case "${1:-}" in
  road) scene=road_slope; shift ;;
  soil) shift ;;
esac
ensure_packages "${DM_CORE_PACKAGES[@]}" "${DM_ROS_PACKAGES[@]}"
build_core >/dev/null
build_catkin
ros_env
out="$DM_ROOT/results/$scene"
mkdir -p "$out"
bag="$out/$scene.bag"
result="$out/$scene.result.yaml"
rm -f "$result"
args=(bag:="$bag")
[ "$scene" = soil_slope ] && args+=(fidelity:="$SOIL_FIDELITY")
say "run: roslaunch dem_mobility $scene.launch ${args[*]} $* (the soil is prepared first: minutes at coarse)"
# a master of its own, on a free port, so that a running roscore is left alone
port=$(PYTHONPATH="$DM_ROOT/python" python3 -c 'from dem_mobility_tools.runs import free_port; print(free_port())')
ROS_MASTER_URI="http://localhost:$port" roslaunch -p "$port" dem_mobility "$scene.launch" "${args[@]}" "$@"
[ -f "$result" ] || { echo "run.sh: the run wrote no result ($result)" >&2; exit 1; }
say "result: $result"
cat "$result"
status=$(yaml_get "$result" status)
if [ "$status" = error ]; then
  echo "run.sh: the run failed: $(yaml_get "$result" error)" >&2
  exit 1
fi
python3 - "$result" <<'EOF'
import sys, yaml
r = yaml.safe_load(open(sys.argv[1]))
smg = r['speed_made_good']
err = r.get('speed_error_estimate')
print()
if isinstance(err, (int, float)):
    print('speed_made_good: %.3f +- %.3f m/s (%.2f +- %.2f mph), %s' % (smg, err, smg / 0.44704, err / 0.44704, r['status']))
else:  # the level's own words (e.g. "not measured for level 'coarse'"), or none at all
    why = err if isinstance(err, str) and err else 'not measured (the result has no speed_error_estimate)'
    print('speed_made_good: %.3f m/s (%.2f mph), %s; error estimate: %s' % (smg, smg / 0.44704, r['status'], why))
if r.get('terrain_model') == 'dem_soil':
    ci = r.get('cone_index_psi')
    print('soil: level %s, cone index %s, f %s; slip %s, sinkage %s m, drawbar margin %.3f' % (
        r.get('fidelity'), '%.4g psi' % ci if isinstance(ci, (int, float)) and ci == ci else 'unknown', r.get('cohesion_factor'),
        ' '.join('%.3f' % s for s in r['slip']), ' '.join('%.3f' % s for s in r['sinkage']), r['drawbar_margin']))
EOF
echo "plot: source $DM_WS/devel/setup.bash && rosrun dem_mobility dm-plot-speed $bag"
