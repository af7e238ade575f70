#!/usr/bin/env bash
# Builds colmap-lidar with AddressSanitizer and UndefinedBehaviorSanitizer (our code only; COLMAP stays the
# normal build) in build-asan/ and runs the given CTest regex there (default: the unit tests and the
# joint adjuster's synthetic-data tests, which include the capped outlier loop that once evaluated a
# freed landmark). Any sanitizer report fails the run.
#   TESTS   ctest -R regex (default below)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
readonly kColmapPrefix="${COLMAP_LIDAR_COLMAP_PREFIX:-$HOME/.cache/colmap-lidar/colmap-3.10}"
readonly kTests="${TESTS:-^(lidar|colmap_ext|bridge)/|integration/joint_adjuster_exact}"
readonly kFlags="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS="$kFlags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_PREFIX_PATH="$kColmapPrefix" >/dev/null
# Only what the selected tests need: every test executable, not the benchmarks.
cmake --build build-asan -j "$(nproc)" --target all
cd build-asan
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/../scripts/lsan_suppressions.txt"
ctest -R "$kTests" -E "scripts/" --output-on-failure -j "$(nproc)"
