#!/usr/bin/env bash
# A build of one commit kept apart from the working checkout, for sweeps whose runs outlive a
# session: a run's checkpoint is taken up only by the build that wrote it (common/checkpoint.h),
# while the working checkout is rebuilt as it changes, and a sweep's --resume refuses a scene file
# that changed under its runs. The pinned build does not change, so its runs go on across sessions.
#
#   scripts/pinned.sh [COMMIT] -- COMMAND ARGS...
#       builds COMMIT (default: HEAD of this checkout) once, in
#       ${XDG_CACHE_HOME:-~/.cache}/dem_mobility/pinned-<commit> (a clone, its build and its catkin
#       workspace), then runs COMMAND in that build's ROS environment, in the current directory,
#       with the pinned dem_mobility_tools first on PYTHONPATH: `python3 -m dem_mobility_tools...`
#       runs the pinned code, and relative paths (--out, --keep, --install) are this checkout's.
#       A sweep's --keep DIR --commit commits into the checkout that holds DIR (this one); each
#       kept run names the pinned commit it was made with (kept_from_commit).
#   scripts/pinned.sh --list      the pinned builds there are
#
# Example (the 0.05 m table, resumable across sessions):
#   scripts/pinned.sh -- python3 -m dem_mobility_tools.calibration.cone_index --fidelity medium_cal \
#     --f 0.05,0.3,1,2,3,5,7,10 --mu 0.1 --seeds 1,2,3 --jobs 1 --dem-threads 2 \
#     --out /work/tmp/medium_cal --keep config/calibration/runs/medium_cal --commit --resume
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cache="${XDG_CACHE_HOME:-$HOME/.cache}/dem_mobility"
export PATH="/usr/bin:$PATH"

if [ "${1:-}" = "--list" ]; then
  for d in "$cache"/pinned-*/; do
    [ -d "$d" ] || continue
    printf '%s  %s  %s\n' "$(basename "$d")" "$([ -f "$d/built" ] && echo built || echo 'not built')" \
      "$(git -C "$d/src" log -1 --format='%cd %s' --date=short 2>/dev/null || true)"
  done
  exit 0
fi
rev=HEAD
if [ "${1:-}" != "--" ]; then
  rev="${1:-}"
  shift || true
fi
[ "${1:-}" = "--" ] || { echo "usage: scripts/pinned.sh [COMMIT] -- COMMAND ARGS... | --list" >&2; exit 2; }
shift
[ $# -gt 0 ] || { echo "scripts/pinned.sh: no command to run" >&2; exit 2; }
commit="$(git -C "$here" rev-parse --verify "$rev^{commit}" 2>/dev/null)" \
  || { echo "scripts/pinned.sh: $rev: not a commit of $here" >&2; exit 2; }
dir="$cache/pinned-${commit:0:12}"
mkdir -p "$cache"
# one build at a time (two sweeps started together wait for the one build)
exec 9>"$dir.lock"
flock 9
if [ ! -f "$dir/built" ]; then
  echo "pinned: building $commit in $dir (once)" >&2
  rm -rf "$dir"
  mkdir -p "$dir"
  git clone -q --no-checkout "$here" "$dir/src"
  git -C "$dir/src" checkout -q "$commit"
  # its own build folder and catkin workspace (lib.sh names them after the checkout's path)
  (cd "$dir/src" && DM_BUILD="$dir/build" bash -c 'source scripts/lib.sh; build_catkin' >"$dir/build.log" 2>&1) \
    || { tail -30 "$dir/build.log" >&2; echo "scripts/pinned.sh: the build failed; its log: $dir/build.log" >&2; exit 1; }
  echo "$commit" >"$dir/built"
fi
flock -u 9
src="$dir/src"
export DM_BUILD="$dir/build"
# shellcheck disable=SC1091
source "$src/scripts/lib.sh"
ros_env
export PYTHONPATH="$src/python${PYTHONPATH:+:$PYTHONPATH}"
export DM_PINNED_COMMIT="$commit"
exec "$@"
