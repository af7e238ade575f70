# Sourced by scripts/test.sh and scripts/sanitize.sh: compile through ccache (installed by
# scripts/setup.sh) when present, with its cache in ~/.cache/colmap-lidar/ccache, so that a file that
# did not change is not compiled again, also from another checkout of the repository (CI's). Sets
# `ccache_launcher` to the CMake arguments to pass (empty without ccache).
export CCACHE_DIR="${CCACHE_DIR:-$HOME/.cache/colmap-lidar/ccache}"
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}"
export CCACHE_NOHASHDIR="${CCACHE_NOHASHDIR:-1}"
export CCACHE_MAXSIZE="${CCACHE_MAXSIZE:-10G}"
ccache_launcher=()
if command -v ccache >/dev/null; then
  ccache_launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
