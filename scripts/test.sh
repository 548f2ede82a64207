#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test: the core GoogleTest suite with plain CMake
# (no ROS), then the catkin build of the whole package (ROS layer, messages).
source "$(dirname "$0")/lib.sh"
ensure_packages "${DM_CORE_PACKAGES[@]}" "${DM_ROS_PACKAGES[@]}"
build_core
say "test: core suite (ctest, no ROS master)"
(cd "$DM_BUILD/core" && ctest --output-on-failure --timeout 600)
build_catkin
say "test: all passed"
