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
