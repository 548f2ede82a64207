#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs the paper's road scene (the HMMWV on a
# rigid road at a grade, 1 m/s^2 toward 25 m/s for 40 s), printing its speed-made-good.
# Extra arguments are scene overrides, e.g. ./scripts/run.sh grade_deg=12
source "$(dirname "$0")/lib.sh"
ensure_packages "${DM_CORE_PACKAGES[@]}"
build_core
out="$DM_ROOT/results/road_slope"
mkdir -p "$out"
say "run: road scene (results in $out)"
"$DM_BUILD/core/src/core/dm_run_scene" "$DM_ROOT/config/scenes/road_slope.yaml" "$@" \
  --out "$out/result.yaml" --history "$out/history.csv"
say "result: $out/result.yaml"
cat "$out/result.yaml"
