#!/usr/bin/env bash
# Runs the benchmarks and prints one line per figure: NAME FIGURE VALUE UNIT.
#   ./scripts/bench.sh            all benchmarks
#   ./scripts/bench.sh vehicle_step
source "$(dirname "$0")/lib.sh"
ensure_packages "${DM_CORE_PACKAGES[@]}"
build_core >/dev/null
want="${1:-all}"
echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(uname -m) $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
ran=0
for b in vehicle_step; do
  if [ "$want" = all ] || [ "$want" = "$b" ]; then
    "$DM_BUILD/core/bench/${b}_bench"
    ran=1
  fi
done
[ "$ran" = 1 ] || { echo "unknown benchmark '$want' (have: vehicle_step)" >&2; exit 2; }
