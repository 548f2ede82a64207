#!/usr/bin/env bash
# The core built with clang, AddressSanitizer and UndefinedBehaviorSanitizer in a build directory of
# its own ($DM_BUILD/sanitize; -O1, line tables, -fno-sanitize-recover: any report fails), and
# (issue 16):
#  - core test programs run under the sanitizers, leak detection on;
#  - the libFuzzer harnesses of the configuration loaders (test/fuzz: scene, vehicle, terrain,
#    soil, calibration table): every input of test/fuzz/regressions/<target>/ once, then a fixed
#    number of new inputs per harness, seeded with the shipped files (deterministic: -seed=1).
# Any sanitizer report, failing test, crash, leak or escaping exception exits non-zero; a fuzzer's
# finding is kept as $DM_BUILD/sanitize/fuzz/<target>-crash-* (copy it into
# test/fuzz/regressions/<target>/ once fixed: config_test reads those in every build).
#
#   ./scripts/sanitize.sh                 what ./scripts/test.sh runs: the quick test programs, the
#                                         soil code on small configurations (below) and
#                                         DM_FUZZ_RUNS (default 2000) inputs per harness
#   ./scripts/sanitize.sh --all           all the fast test programs (about 10 min of runs)
#   ./scripts/sanitize.sh TEST...         the test programs named (targets of test/core)
#   ./scripts/sanitize.sh --fuzz TARGET [SECONDS]   one harness for longer (default 600 s); its
#                                         corpus grows in $DM_BUILD/sanitize/fuzz/corpus/TARGET
# The timing tests of config_test (a signal 1-3 s into a run) assume a build at full speed, its
# full-disk road run takes 1.5 min under the sanitizers, and its checkpoint test's three 20 s road
# runs some 8 min each: they are left out here (the checkpoint reader's refusals of damaged
# files run in cosim_test's Checkpoint test). vehicle_test runs some 30 times slower under the sanitizers (its climbs take
# minutes each): name it to run it.
# The soil code runs on small configurations (GoogleTest cases of longer programs, each a log of its
# own, soil_<name>.log): the tire walls (the binned tire contact against the triangle scan, action
# and reaction), the soil preparation (the tiny bin poured, pressed by the lid and released, then
# exchanging with a tire; the dem_pour scene's test takes 2.5 min of CPU here: --all runs it) and
# the soil patch's emitter and input checks; some 2.5 min of CPU. The whole wheel rig on a tiny bin
# (2 min of CPU) and a small patch following the wheels (5 min) run with --all, or named:
#   ./scripts/sanitize.sh wheel_test     (every wheel_test case, those two among them)
# A skipped test in any log fails the run (test/check_skips.py).
source "$(dirname "$0")/lib.sh"
ensure_packages "${DM_CORE_PACKAGES[@]}" "${DM_SANITIZE_PACKAGES[@]}"
dir="$DM_BUILD/sanitize"
quick=(config_test contact_test joints_test integrator_test soil_law_test pair_kernel_test dem_particles_test
  powertrain_test)
# NAME=PROGRAM:GTEST_FILTER
soil=(tire_walls=wheel_test:TireContact.*
  soil_prep=wheel_test:DemSoilTerrain.AdvancesInWholeSoilStepsAndReturnsTheMeanReaction
  soil_patch_input=soil_patch_test:SoilPatch.PoursItsPartialTopLayerEvenlyAcrossTheWidth:VehicleOnSoil.RefusesBadInputNamingFileAndKey)
fuzz_targets=(scene vehicle terrain soil calibration)
fuzz_only="" fuzz_seconds=600
case "${1:-}" in
  --all) tests=("${quick[@]}" dem_pour_test cosim_test dem_test wheel_test) soil=() ;;
  --fuzz)
    fuzz_only="${2:?usage: sanitize.sh --fuzz TARGET [SECONDS] (targets: ${fuzz_targets[*]})}"
    fuzz_seconds="${3:-600}"
    [[ " ${fuzz_targets[*]} " == *" $fuzz_only "* ]] || { echo "sanitize.sh: no fuzz target '$fuzz_only' (${fuzz_targets[*]})"; exit 2; }
    tests=() soil=() ;;
  --help|-h) sed -n '2,32p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  "") tests=("${quick[@]}") ;;
  *) tests=("$@") soil=() ;;
esac
soil_programs=()
for c in "${soil[@]}"; do
  p="${c#*=}"; p="${p%%:*}"
  [[ " ${tests[*]} ${soil_programs[*]} " == *" $p "* ]] || soil_programs+=("$p")
done
san="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
say "build: clang, ASan + UBSan + libFuzzer in $dir (${tests[*]:-} ${soil_programs[*]:-} fuzz_*)"
ninja_folder "$dir"
cmake -G Ninja -S "$DM_ROOT" -B "$dir" -DCMAKE_CXX_COMPILER=clang++ -DDM_BUILD_ROS=OFF -DDM_BUILD_BENCH=OFF -DDM_BUILD_FUZZ=ON \
  -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE="-O1 -gline-tables-only $san -fsanitize=fuzzer-no-link" \
  -DCMAKE_EXE_LINKER_FLAGS_SANITIZE="-fsanitize=address,undefined" >/dev/null
targets=(fuzz_seeds)
for t in "${fuzz_targets[@]}"; do targets+=("fuzz_$t"); done
cmake --build "$dir" -j"$(nproc)" --target "${tests[@]}" "${soil_programs[@]}" "${targets[@]}" dm_run_scene
export ASAN_OPTIONS=detect_leaks=1:halt_on_error=1:abort_on_error=0
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
# The test programs and the harnesses run as many at a time as there are cores (each is one
# process on one core; one after the other they left a core idle for a minute at the end of the
# test command), each into its log; their reports follow in a fixed order once all have ended.
status="$dir/status"
rm -rf "$status"; mkdir -p "$status"
pool() {  # pool NAME COMMAND...: runs the command in the background once a core is free
  while [ "$(jobs -rp | wc -l)" -ge "$(nproc)" ]; do wait -n || true; done
  ( "${@:2}" && echo 0 >"$status/$1" || echo 1 >"$status/$1" ) &
}
run_test() {
  local filter=()
  [ "$1" = config_test ] && filter=(--gtest_filter=-Config.RunnerInterrupted*:Config.RunnerOnAFullDisk*:Config.RunnerStopped*)
  cd "$dir/test/core" && "./$1" "${filter[@]}" >"$dir/$1.log" 2>&1
}
run_soil() {  # run_soil NAME PROGRAM FILTER
  cd "$dir/test/core" && "./$2" --gtest_filter="$3" >"$dir/soil_$1.log" 2>&1
}
for t in "${tests[@]}"; do
  say "sanitize: $t"
  pool "$t" run_test "$t"
done
for c in "${soil[@]}"; do
  name="${c%%=*}" spec="${c#*=}"
  say "sanitize: soil, $name (${spec%%:*} --gtest_filter=${spec#*:})"
  pool "soil_$name" run_soil "$name" "${spec%%:*}" "${spec#*:}"
done

# the fuzzers: the shipped files as seeds, a corpus of their own per run (the quick run starts afresh
# each time so that it repeats; --fuzz keeps and grows its corpus)
fuzz="$dir/fuzz"
rm -rf "$fuzz/seeds"
"$dir/test/fuzz/fuzz_seeds" "$fuzz/seeds" >/dev/null
fuzz_flags=(-max_len=16384 -timeout=20 -rss_limit_mb=2048 -malloc_limit_mb=1024 -print_final_stats=1)
run_fuzz() {  # run_fuzz TARGET: its regression inputs once (their log: fuzz_TARGET.regressions.log), then its run
  local t="$1" bin="$dir/test/fuzz/fuzz_$1" log="$dir/fuzz_$1.log" run
  local regressions=("$DM_ROOT/test/fuzz/regressions/$t"/*)
  if [ -e "${regressions[0]}" ]; then
    "$bin" "${fuzz_flags[@]}" -artifact_prefix="$fuzz/$t-" "${regressions[@]}" >"$dir/fuzz_$t.regressions.log" 2>&1 \
      || { echo regressions >"$status/fuzz_$t.what"; return 1; }
  fi
  if [ -n "$fuzz_only" ]; then
    mkdir -p "$fuzz/corpus/$t"
    run=(-max_total_time="$fuzz_seconds" "$fuzz/corpus/$t" "$fuzz/seeds/$t")
  else
    rm -rf "$fuzz/corpus/quick_$t"; mkdir -p "$fuzz/corpus/quick_$t"
    run=(-runs="${DM_FUZZ_RUNS:-2000}" -seed=1 "$fuzz/corpus/quick_$t" "$fuzz/seeds/$t")
  fi
  "$bin" "${fuzz_flags[@]}" -artifact_prefix="$fuzz/$t-" "${run[@]}" >"$log" 2>&1
}
fuzzed=()
for t in "${fuzz_targets[@]}"; do
  [ -z "$fuzz_only" ] || [ "$t" = "$fuzz_only" ] || continue
  fuzzed+=("$t")
  regressions=("$DM_ROOT/test/fuzz/regressions/$t"/*)
  n=0; [ ! -e "${regressions[0]}" ] || n=${#regressions[@]}
  if [ -n "$fuzz_only" ]; then
    say "fuzz: $t, its $n regression input(s), then for $fuzz_seconds s (corpus $fuzz/corpus/$t)"
  else
    say "fuzz: $t, its $n regression input(s), then ${DM_FUZZ_RUNS:-2000} inputs"
  fi
  pool "fuzz_$t" run_fuzz "$t"
done
wait

failed=()
for t in "${tests[@]}"; do
  [ "$(cat "$status/$t")" = 0 ] && continue
  failed+=("$t")
  grep -E "ERROR: AddressSanitizer|runtime error|LeakSanitizer|FAILED" "$dir/$t.log" | head -20 || true
  echo "(log: $dir/$t.log)"
done
for c in "${soil[@]}"; do
  t="soil_${c%%=*}"
  [ "$(cat "$status/$t")" = 0 ] && { echo "$t: $(grep -E '^\[  PASSED  \]' "$dir/$t.log" || true)"; continue; }
  failed+=("$t")
  grep -E "ERROR: AddressSanitizer|runtime error|LeakSanitizer|FAILED" "$dir/$t.log" | head -20 || true
  echo "(log: $dir/$t.log)"
done
# a skipped test is a failure unless test/allowed_skips.yaml lists it
logs=()
for t in "${tests[@]}"; do logs+=("$dir/$t.log"); done
for c in "${soil[@]}"; do logs+=("$dir/soil_${c%%=*}.log"); done
if [ ${#logs[@]} -gt 0 ] && ! python3 "$DM_ROOT/test/check_skips.py" "${logs[@]}"; then
  failed+=("skips")
fi
for t in "${fuzzed[@]}"; do
  log="$dir/fuzz_$t.log"
  if [ "$(cat "$status/fuzz_$t")" = 0 ]; then
    echo -n "fuzz $t: "
    grep -E "^stat::number_of_executed_units|^stat::peak_rss_mb|^#[0-9]+ *DONE" "$log" | tr '\n' ' ' || true
    echo
  elif [ -f "$status/fuzz_$t.what" ]; then
    failed+=("fuzz_$t regressions"); tail -30 "$dir/fuzz_$t.regressions.log"
  else
    failed+=("fuzz_$t")
    grep -E -A12 "ERROR: (AddressSanitizer|libFuzzer|LeakSanitizer)|runtime error|uncaught exception|terminate called" "$log" | head -40 || tail -30 "$log"
    echo "(log: $log; the input: $(ls "$fuzz/$t"-* 2>/dev/null | head -3 | tr '\n' ' '))"
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "sanitize: failed: ${failed[*]}"
  exit 1
fi
say "sanitize: ${#tests[@]} test program(s), ${#soil[@]} soil configuration(s) and the fuzz harness(es): no report"
