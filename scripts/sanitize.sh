#!/usr/bin/env bash
# The core tests built with AddressSanitizer and UndefinedBehaviorSanitizer (issue 16), in a build
# directory of their own ($DM_BUILD/sanitize; RelWithDebInfo, -fno-sanitize-recover: any report
# fails the test), run with leak detection on. Any report or failing test exits non-zero.
#   ./scripts/sanitize.sh              the fast tests (about 16 minutes here: the build 5.5, the runs 10)
#   ./scripts/sanitize.sh dem_test     the tests named (targets of test/core)
# Not yet part of ./scripts/test.sh: the build alone would add some 5 minutes to the suite.
# The timing tests of config_test (a signal 1-3 s into a run) assume a build at full speed: they
# are left out here. vehicle_test runs some 30 times slower under the sanitizers (its climbs take
# minutes each): name it to run it.
source "$(dirname "$0")/lib.sh"
ensure_packages "${DM_CORE_PACKAGES[@]}"
tests=("$@")
[ ${#tests[@]} -gt 0 ] || tests=(config_test contact_test joints_test integrator_test soil_law_test pair_kernel_test
  dem_particles_test powertrain_test dem_pour_test cosim_test dem_test wheel_test)
dir="$DM_BUILD/sanitize"
flags="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
say "build: core tests with ASan and UBSan in $dir (${tests[*]})"
cmake -S "$DM_ROOT" -B "$dir" -DDM_BUILD_ROS=OFF -DDM_BUILD_BENCH=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
cmake --build "$dir" -j"$(nproc)" --target "${tests[@]}" dm_run_scene
export ASAN_OPTIONS=detect_leaks=1:halt_on_error=1:abort_on_error=0
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
failed=()
for t in "${tests[@]}"; do
  say "sanitize: $t"
  filter=()
  [ "$t" = config_test ] && filter=(--gtest_filter=-Config.RunnerInterrupted*)
  if ! (cd "$dir/test/core" && "./$t" "${filter[@]}" >"$dir/$t.log" 2>&1); then
    failed+=("$t")
    grep -E "ERROR: AddressSanitizer|runtime error|LeakSanitizer|FAILED" "$dir/$t.log" | head -20 || true
    echo "(log: $dir/$t.log)"
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "sanitize: failed: ${failed[*]}"
  exit 1
fi
say "sanitize: ${#tests[@]} test programs, no report"
