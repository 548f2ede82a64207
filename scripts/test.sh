#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test:
#  1. the core GoogleTest suite with plain CMake (no ROS master), in the background beside 2-4,
#  2. the catkin build of the whole package, then its catkin tests: roslaunch-check on every launch
#     file and the rostest of the lock-step exchange (test/ros/road_scene.test),
#  3. the bag recorder on its own (test/ros/test_bag_recorder.py), the end-to-end road runs
#     through roslaunch (test/ros/test_road_runs.py), the cone index
#     calibration sweep on tiny cases (test/ros/test_cone_sweep.py), the single-wheel rig
#     (test/ros/test_single_wheel.py), the vehicle on the DEM soil patch (test/ros/test_soil_slope.py) and
#     the speed-made-good map published as an OccupancyGrid (test/ros/test_map_publisher.py),
#  4. catkin_lint on the package (must report nothing),
#  5. the core built with clang under AddressSanitizer and UndefinedBehaviorSanitizer: the quick
#     core test programs, small configurations of the soil code (tire walls, preparation, wheel
#     rig, patch) and the libFuzzer harnesses of every configuration loader, their regression
#     inputs and a fixed number of new inputs each (scripts/sanitize.sh),
#  6. no test skipped unless test/allowed_skips.yaml lists it with its reason (test/check_skips.py).
source "$(dirname "$0")/lib.sh"
ensure_packages "${DM_CORE_PACKAGES[@]}" "${DM_ROS_PACKAGES[@]}" "${DM_MAP_PACKAGES[@]}" "${DM_SLURM_PACKAGES[@]}" "${DM_CHECK_PACKAGES[@]}" "${DM_SANITIZE_PACKAGES[@]}"
build_core
# The soils the tests prepare are prepared once for the whole run and read back by every other
# test that asks for the same soil (a folder of prepared soils, terrain/prepared_soil_cache.h: bit
# for bit the state the preparation gives). dm_run_scene, the terrain nodelet's launch file and
# the soil tests take the folder from DM_SOIL_CACHE (the core reads no environment); a folder of
# this run's own, emptied first, so that every run prepares afresh. The tests of the preparation
# itself (stopped while it runs) unset it.
export DM_SOIL_CACHE="$DM_BUILD/soil_cache"
rm -rf "$DM_SOIL_CACHE"
# every test's output is kept for the skip check at the end (test/check_skips.py); this run's only
rm -f "$DM_BUILD"/test_*.log "$DM_BUILD/catkin_test_results.log"
# The stages below run side by side on the machine's cores, more threads than cores: OpenMP threads
# that sleep at a barrier instead of spinning leave the cores to the work (results do not depend on it).
export OMP_WAIT_POLICY=PASSIVE
# The core suite is CPU-bound (its tests run side by side on both cores); the stages after it
# (builds, ROS and python tests) wait on processes, masters and a Slurm scheduler much of the
# time. So the core suite runs in the background beside them, and its outcome is read at the end.
say "test: core suite (ctest, no ROS master) started in the background (its log: $DM_BUILD/ctest.log)"
rm -f "$DM_BUILD/ctest.rc"
# its own process group (setsid), so that a failing stage below stops it and its tests too
setsid bash -c 'cd "$1/core" && ctest --output-on-failure --timeout 1200 -j2 >"$1/ctest.log" 2>&1; echo $? >"$1/ctest.rc"' \
  _ "$DM_BUILD" &
ctest_pid=$!
trap 'kill -- -"$ctest_pid" 2>/dev/null || true' EXIT
build_catkin
ros_env
say "test: catkin tests (roslaunch-check, rostest)"
(cd "$DM_WS" && catkin_make --use-ninja run_tests -j"$(nproc)" >"$DM_BUILD/run_tests.log" 2>&1) || true
if ! catkin_test_results --verbose "$DM_WS/build/test_results/dem_mobility" | tee "$DM_BUILD/catkin_test_results.log"; then
  tail -60 "$DM_BUILD/run_tests.log"
  echo "catkin tests failed; full log: $DM_BUILD/run_tests.log"
  exit 1
fi
say "test: the Python package dem_mobility_tools (python unit tests, no ROS; one tiny wheel run through the core; installed by pip, its console scripts)"
(cd "$DM_ROOT" && PYTHONPATH="$DM_ROOT/python${PYTHONPATH:+:$PYTHONPATH}" DM_RUN_SCENE="$DM_BUILD/core/src/tools/dm_run_scene" \
  python3 -m unittest discover -s test/python -v) 2>&1 | tee "$DM_BUILD/test_python.log"
say "test: the bag recorder on its own (a latched message delivered twice is recorded once)"
python3 "$DM_ROOT/test/ros/test_bag_recorder.py" 2>&1 | tee "$DM_BUILD/test_ros_test_bag_recorder.log"
say "test: end-to-end road runs through roslaunch"
DM_RUN_SCENE="$DM_BUILD/core/src/tools/dm_run_scene" python3 "$DM_ROOT/test/ros/test_road_runs.py" 2>&1 | tee "$DM_BUILD/test_ros_test_road_runs.log"
say "test: the cone index calibration sweep on tiny cases (roslaunch, bags, table, plots)"
python3 "$DM_ROOT/test/ros/test_cone_sweep.py" 2>&1 | tee "$DM_BUILD/test_ros_test_cone_sweep.log"
say "test: the single-wheel rig through roslaunch (tiny run: bag, result message and YAML; a bad slip)"
python3 "$DM_ROOT/test/ros/test_single_wheel.py" 2>&1 | tee "$DM_BUILD/test_ros_test_single_wheel.log"
say "test: the vehicle on the DEM soil patch through roslaunch (tiny: result and soil figures as the core runner's, bag, 1 vs 2 soil threads; a bad cone index; Ctrl-C in the preparation and while driving)"
DM_RUN_SCENE="$DM_BUILD/core/src/tools/dm_run_scene" python3 "$DM_ROOT/test/ros/test_soil_slope.py" 2>&1 | tee "$DM_BUILD/test_ros_test_soil_slope.log"
say "test: the speed-made-good map on ROS (mobility_map.launch: nav_msgs/OccupancyGrid as map_server reads the file)"
python3 "$DM_ROOT/test/ros/test_map_publisher.py" 2>&1 | tee "$DM_BUILD/test_ros_test_map_publisher.log"
say "test: catkin_lint"
lint=$(cd "$DM_WS/src" && catkin_lint dem_mobility 2>&1 | grep -v rosdep)
echo "$lint"
echo "$lint" | grep -q "found 0 problems" || { echo "catkin_lint reported problems"; exit 1; }
say "test: sanitizers and fuzzers (clang: ASan + UBSan, libFuzzer; beside the core suite)"
bash "$DM_ROOT/scripts/sanitize.sh"
say "test: core suite (ctest): waiting for it"
wait "$ctest_pid" || true
trap - EXIT
cat "$DM_BUILD/ctest.log"
[ "$(cat "$DM_BUILD/ctest.rc" 2>/dev/null)" = 0 ] || { echo "core suite failed (log: $DM_BUILD/ctest.log)"; exit 1; }
say "test: skipped tests (only those test/allowed_skips.yaml lists, with their reason, may be)"
# ctest's log names skipped and not-run entries; LastTest.log holds every test program's own output
# (GoogleTest's [  SKIPPED ] lines); the sanitizer runs are checked by scripts/sanitize.sh itself
python3 "$DM_ROOT/test/check_skips.py" "$DM_BUILD/ctest.log" "$DM_BUILD/core/Testing/Temporary/LastTest.log" \
  "$DM_BUILD/catkin_test_results.log" "$DM_BUILD/test_python.log" "$DM_BUILD"/test_ros_*.log
say "test: all passed"
