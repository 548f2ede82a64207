# Shared helpers of the set-up scripts (sourced, not run).
set -euo pipefail
DM_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
DM_BUILD="${DM_BUILD:-$DM_ROOT/build}"
# the catkin workspace lives outside the checkout (its src/ links back to the checkout; inside it,
# roslaunch's file search would loop through the link): one per checkout
DM_WS="${DM_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/dem_mobility/ws-$(printf %s "$DM_ROOT" | md5sum | cut -c1-8)}"
# Debian's python3 (catkin_pkg, rosbag) before any pyenv/venv python on PATH
export PATH="/usr/bin:$PATH"

DM_CORE_PACKAGES=(cmake ninja-build make g++ libeigen3-dev libyaml-cpp-dev libgtest-dev libbenchmark-dev universal-ctags)
DM_ROS_PACKAGES=(catkin ros-core-dev rosbash libroscpp-dev libnodeletlib-dev librosbag-dev libtf2-ros-dev
  libtf2-eigen-dev libnodeletlib-tools ros-geometry-msgs ros-sensor-msgs ros-visualization-msgs ros-message-generation
  ros-nav-msgs python3-nav-msgs python3-tf2-msgs ros-rosgraph-msgs ros-tf2-msgs libtopic-tools-dev pluginlib-dev
  python3-rosbag python3-roslaunch python3-rostest python3-catkin-pkg python3-std-msgs python3-geometry-msgs python3-nodelet python3-matplotlib python3-numpy python3-yaml python3-tqdm
  python3-scipy python3-setuptools python3-venv python3-pip)
# the maps of the design of experiments (GDAL's tools and python bindings)
DM_MAP_PACKAGES=(gdal-bin python3-gdal)
# the Slurm backend of the design of experiments and its single-node test cluster
DM_SLURM_PACKAGES=(slurmctld slurmd slurm-client munge)
# only for the checks of the test command (package lint, rviz screenshot under Xvfb)
DM_CHECK_PACKAGES=(catkin-lint rviz xvfb imagemagick)
# the sanitizer build and the fuzz harnesses (scripts/sanitize.sh): clang, its OpenMP and libFuzzer
DM_SANITIZE_PACKAGES=(clang libomp-dev libclang-rt-dev)
# only for the dem_step benchmark (the side-by-side LAMMPS run)
DM_BENCH_PACKAGES=(lammps openmpi-bin)

say() { printf '\n==> [%s] %s\n' "$(date -u +%H:%M:%S)" "$*"; }

# Installs the Debian packages that are missing (apt-get update once, only if something is).
ensure_packages() {
  local missing=()
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    say "packages: all ${#@} present"
    return
  fi
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  say "packages: installing ${missing[*]}"
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
}

# The builds use Ninja: a target's sources compile while the libraries it links are still being
# built (Make waits for them), and it does not scan dependencies in a make process per target. On
# the 2 cores: the core 125 -> 114 s, the catkin layer 76 -> 62 s, the sanitizer build 187 -> 112 s
# (docs/performance.md). A build folder configured with another generator (Make, before) is
# emptied first: CMake refuses to switch the generator of a folder.
ninja_folder() {
  local cache="$1/CMakeCache.txt"
  if [ -f "$cache" ] && ! grep -qx 'CMAKE_GENERATOR:INTERNAL=Ninja' "$cache"; then
    say "build: $1 was configured for another generator than Ninja: emptied"
    rm -rf "$1"
  fi
}

# Plain CMake build of the ROS-free core and its tests (no catkin); its benchmarks too with
# DM_CORE_BENCH=ON (scripts/bench.sh sets it; the tests and the main job do not need them).
DM_CORE_BENCH="${DM_CORE_BENCH:-OFF}"
build_core() {
  case "$DM_CORE_BENCH" in ON|OFF) ;; *)
    echo "scripts/lib.sh: DM_CORE_BENCH must be ON or OFF, not '$DM_CORE_BENCH'" >&2; exit 2 ;;
  esac
  say "build: core (plain CMake, Ninja, Release) in $DM_BUILD/core"
  ninja_folder "$DM_BUILD/core"
  cmake -G Ninja -S "$DM_ROOT" -B "$DM_BUILD/core" -DDM_BUILD_ROS=OFF -DCMAKE_BUILD_TYPE=Release \
    -DDM_BUILD_BENCH="$DM_CORE_BENCH" >/dev/null
  cmake --build "$DM_BUILD/core" -j"$(nproc)"
}

# catkin workspace whose src/ links to this checkout; builds the ROS layer. It links build_core's
# libdm_core.a (DM_CORE_PREBUILT; it brings build_core up to date first) and leaves the core tests
# and benchmarks to build_core: nothing is compiled twice.
build_catkin() {
  local ws="$DM_WS"
  build_core >/dev/null  # (up to date already when the caller has just built it: seconds)
  say "build: catkin workspace $ws"
  mkdir -p "$ws/src" "$DM_BUILD"
  touch "$DM_BUILD/CATKIN_IGNORE"  # catkin must not take build/ for part of the package
  ln -sfn "$DM_ROOT" "$ws/src/dem_mobility"
  ninja_folder "$ws/build"
  (cd "$ws" && catkin_make --use-ninja -DCMAKE_BUILD_TYPE=Release -DCATKIN_ENABLE_TESTING=ON -DDM_BUILD_TESTS=OFF -DDM_BUILD_BENCH=OFF -DDM_CORE_PREBUILT="$DM_BUILD/core/src/core/libdm_core.a" -j"$(nproc)" >"$DM_BUILD/catkin_make.log" 2>&1) \
    || { tail -40 "$DM_BUILD/catkin_make.log"; echo "catkin_make failed; full log: $DM_BUILD/catkin_make.log"; exit 1; }
  tail -3 "$DM_BUILD/catkin_make.log"
}

# The ROS environment of the catkin workspace (its setup scripts read unset variables).
ros_env() {
  set +u
  # shellcheck disable=SC1091
  source "$DM_WS/devel/setup.bash"
  set -u
}

# Prints a result YAML's key (top level, scalar).
yaml_get() { python3 -c 'import sys, yaml; print(yaml.safe_load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"; }
