#!/usr/bin/env bash
# Builds colmap-lidar with AddressSanitizer and UndefinedBehaviorSanitizer (our code only; COLMAP stays the
# normal build) in build-asan/ and runs the unit and integration tests there (CTest labels; the slow
# ones are left out), so that every reader, functor and command these tests reach runs under the
# sanitizers. Any sanitizer report fails the run. scripts/test.sh runs it after the normal tests.
#   LABELS  ctest -L regex of the labels to run (default: unit|integration)
#   TESTS   ctest -R regex instead of the labels (e.g. TESTS=integration/joint_adjuster_exact)
#   JOBS    parallel build and test jobs (default: nproc)
#   FULL    1: also the slowest tests under the sanitizers (see below)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
readonly kColmapPrefix="${COLMAP_LIDAR_COLMAP_PREFIX:-$HOME/.cache/colmap-lidar/colmap-3.10}"
readonly kJobs="${JOBS:-$(nproc)}"
# -O1 and line tables only (-g1): a sanitizer report still names the function, file and line, and
# the build takes far less than with full debug information. Under ASan, Eigen stops trusting
# malloc's alignment and frees through its own header, so an Eigen matrix that the system's Ceres
# allocates and our code frees (GradientChecker's results) would be freed wrongly: keep the ABI of
# the libraries we link (glibc's malloc aligns to 16 bytes, as ASan's does).
readonly kFlags="-O1 -g1 -fsanitize=address,undefined -fno-omit-frame-pointer \
-fno-sanitize-recover=undefined -DEIGEN_MALLOC_ALREADY_ALIGNED=1"
source scripts/ccache_env.sh
# The tests labelled slow are neither run nor built here, unless FULL=1, LABELS or TESTS ask for more.
skip_slow=ON
[[ "${FULL:-0}" == 1 || -n "${LABELS:-}" || -n "${TESTS:-}" ]] && skip_slow=OFF
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=None "${ccache_launcher[@]}" \
  -DCOLMAP_LIDAR_SKIP_SLOW_TESTS="$skip_slow" \
  -DCMAKE_CXX_FLAGS="$kFlags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_PREFIX_PATH="$kColmapPrefix" >/dev/null
echo "[sanitize] building in build-asan (ASan + UBSan)"
cmake --build build-asan -j "$kJobs" --target all
cd build-asan
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/../scripts/lsan_suppressions.txt"
selection=(-L "${LABELS:-unit|integration}" -LE slow)
if [[ -n "${TESTS:-}" ]]; then selection=(-R "$TESTS"); fi
echo "[sanitize] running ${selection[*]} under the sanitizers"
# Tests under scripts/ check shell scripts, not our binaries; integration/install builds a consumer
# project against the installed (here: instrumented) libraries without the sanitizer flags.
excluded="^scripts/|^integration/install/"
# Unless FULL=1, the tests that take minutes under the sanitizers and run no code that a lighter
# test of the same binary does not run too are left out: the other joint_adjuster_exact and
# front_end tests; the KITTI importer's frame selection on the simulated drive (its import of the
# same drive stays); the images of the smaller scenes (the T specimen's run the same renderer; each
# scene's geometry test stays); the stereo-LiDAR alignment's coverage over seeded scenes (the
# functions of its single-scene tests, called many times); the pose initialiser and the whole
# pipeline on the real KITTI odometry sample (the pipeline's tests are labelled slow and left out
# here anyway).
if [[ "${FULL:-0}" != 1 ]]; then
  excluded+="|^integration/kitti_sample/|JointAdjusterOptionsTest|FrontEndTest\\.(DepthPriors|Sequential)"
  excluded+="|JointAdjusterExactTest\\.(Unobservable|DepthGate|DepthPriorsComeBack|CappedOutlier)"
  excluded+="|AllScenes/.*bridge_pier|SimulatorImageTest.*(square_pillar|cylinder_pillar)|SurveyPlannerTest\\.ASurfaceCloud"
  excluded+="|KittiImportTest\\.SelectsFrames|ExtrinsicAlignmentTest\\.(ReportedSigmas|StationClustered)"
  excluded+="|KittiOdometrySampleTest\\.(StraightDrive|SelectedFrames)"
fi
ctest "${selection[@]}" -E "$excluded" --output-on-failure -j "$kJobs"
