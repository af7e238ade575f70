# Sourced by every script that builds colmap-lidar: one configuration of a build folder, so that
# scripts/demo.sh, scripts/test.sh and the benchmarks share build/ and compile nothing twice (the
# same compiler launcher and cache variables: a changed one would make CMake rebuild every object).
#   configure_build DIR [extra CMake arguments]
source "$(dirname "${BASH_SOURCE[0]}")/ccache_env.sh"
readonly kColmapPrefix="${COLMAP_LIDAR_COLMAP_PREFIX:-$HOME/.cache/colmap-lidar/colmap-3.10}"
configure_build() {
  local dir=$1
  shift
  cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "${ccache_launcher[@]}" \
    -DCMAKE_PREFIX_PATH="$kColmapPrefix${CMAKE_PREFIX_PATH:+;$CMAKE_PREFIX_PATH}" "$@" >/dev/null
}
# Configures DIR as above and builds the colmap-lidar executable in it.
build_cli() {
  configure_build "$1"
  cmake --build "$1" --target colmap_lidar_cli >/dev/null
}
# Sets `cli` to $CLI (another colmap-lidar executable, e.g. a variant built elsewhere) or else to
# the executable built in $BUILD_DIR (default build).
use_cli() {
  local build="${BUILD_DIR:-build}"
  if [ -z "${CLI:-}" ]; then build_cli "$build"; fi
  cli="${CLI:-$PWD/$build/bin/colmap-lidar}"
}
# Sets `work` to $WORK_DIR (created, kept) or else to a temporary folder removed on exit.
use_work_dir() {
  if [ -n "${WORK_DIR:-}" ]; then
    work="$WORK_DIR"
    mkdir -p "$work"
  else
    work=$(mktemp -d)
    trap 'rm -rf "$work"' EXIT
  fi
}
