#!/usr/bin/env bash
# Installs the build tree into BUILD/test_install/prefix, then configures, builds and runs the consumer
# project (find_package(colmap_lidar), colmap_lidar::pipeline) against it; with FIXTURE (the pipeline's
# default workspace) the consumer also reruns the joint step there (tests/consumer/main.cc).
#   run_consumer_test.sh BUILD_DIR SOURCE_DIR COLMAP_PREFIX [FIXTURE]
set -euo pipefail
readonly kBuild="$1" kSource="$2" kColmapPrefix="$3"
readonly kWork="$kBuild/test_install"
rm -rf "$kWork"
cmake --install "$kBuild" --prefix "$kWork/prefix" >/dev/null
test -f "$kWork/prefix/lib/cmake/colmap_lidar/colmap_lidarConfig.cmake"
test -x "$kWork/prefix/bin/colmap-lidar"
test ! -e "$kWork/prefix/include/bridge/exe"
cmake -S "$kSource/tests/consumer" -B "$kWork/build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$kWork/prefix;$kColmapPrefix" >/dev/null
cmake --build "$kWork/build" >/dev/null
"$kWork/build/consumer" ${4:+"$4"}
