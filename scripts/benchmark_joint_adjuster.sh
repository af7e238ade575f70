#!/usr/bin/env bash
# Joint problem vs COLMAP's plain bundle adjustment on the same reconstruction (simulated default scene):
# time of set-up + 1 and + 10 iterations, and the overhead ratio. Writes docs/benchmarks/joint_adjuster.md.
#   STATIONS (default 10), LIDAR_POINTS per station (default 300000)
#   BASELINE_REV   a git revision whose benchmark also runs on the same data (built in a worktree under
#                  build-baseline/), for a before/after table in one run
#   BASELINE_BENCHMARK  instead of BASELINE_REV: an already built joint_adjuster_benchmark of the
#                  baseline (its revision is read from BASELINE_REV_NAME, default "baseline")
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
source scripts/configure.sh
configure_build build
cmake --build build --target joint_adjuster_benchmark colmap_lidar_cli >/dev/null
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cli=build/bin/colmap-lidar
echo "simulating ${STATIONS:-10} stations and running the front end ..."
$cli simulate_dataset --output_path "$work/dataset" --num_stations "${STATIONS:-10}" \
  --lidar_points "${LIDAR_POINTS:-300000}" >/dev/null
$cli stereo_depth --dataset_path "$work/dataset" --output_path "$work/stereo" >/dev/null
$cli import_dataset --dataset_path "$work/dataset" --database_path "$work/db.db" >/dev/null 2>&1
$cli depth_prior_extractor --database_path "$work/db.db" --depth_path "$work/stereo" >/dev/null
run_benchmark() {
  "$1" "$work/dataset" "$work/db.db" "$2" 2>/dev/null |
    grep -v '^\(Round\|  solve\|Depth priors\|Pose graph\|  cloud\)'
}
table=$(run_benchmark build/bin/joint_adjuster_benchmark "$work/now")
baseline=""
if [ -n "${BASELINE_BENCHMARK:-}" ]; then
  rev="${BASELINE_REV_NAME:-baseline}"
  baseline=$(run_benchmark "$BASELINE_BENCHMARK" "$work/baseline")
elif [ -n "${BASELINE_REV:-}" ]; then
  rev=$(git rev-parse --short "$BASELINE_REV")
  rm -rf build-baseline && git worktree prune
  git worktree add --detach build-baseline/src "$rev" >/dev/null 2>&1
  cmake -S build-baseline/src -B build-baseline/build -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_PREFIX_PATH="$kColmapPrefix" >/dev/null
  cmake --build build-baseline/build --target joint_adjuster_benchmark >/dev/null
  baseline=$(run_benchmark build-baseline/build/bin/joint_adjuster_benchmark "$work/baseline")
  git worktree remove --force build-baseline/src
fi
mkdir -p docs/benchmarks
{
  echo "# Joint adjuster vs COLMAP's bundle adjustment"
  echo
  echo "Written by \`scripts/benchmark_joint_adjuster.sh\` on $(date -u +%Y-%m-%d) ($(nproc) cores)."
  echo "Simulated t_specimen capture, ${STATIONS:-10} stations, ${LIDAR_POINTS:-300000} LiDAR rays per station,"
  echo "full-resolution images (COLMAP SIFT, default options). Both solve the same reconstruction (true"
  echo "poses, landmarks from \`colmap point_triangulator\`) with intrinsics fixed and the first pose"
  echo "constant. COLMAP: \`BundleAdjuster::Solve\`. Joint: COLMAP's \`SetUpProblem\` plus our depth-prior"
  echo "and LiDAR point-to-plane blocks and \`cam_from_lidar\`, then \`ceres::Solve\`; the time also covers"
  echo "adding the blocks and the outlier check, not the (once per round) LiDAR association. \"Per"
  echo "iteration (Ceres)\" is the mean of Ceres' own iteration times (the initial evaluation left out);"
  echo "the baseline's older benchmark divides the whole solve time by the iterations instead."
  echo
  echo "$table"
  if [ -n "$baseline" ]; then
    echo
    echo "### Before: revision $rev on the same data, in the same run"
    echo
    echo "$baseline"
  fi
} > docs/benchmarks/joint_adjuster.md
cat docs/benchmarks/joint_adjuster.md
