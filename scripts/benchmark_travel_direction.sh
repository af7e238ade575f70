#!/usr/bin/env bash
# cam_from_lidar's rotation error against the cameras' travel direction, per family and seed: the
# front ends and joint runs of scripts/benchmark_uncertainty.sh (made there unless WORK_DIR already
# has them), COLMAP's images-only bundle adjustment of each front end started at the true poses
# (scripts/true_pose_model.sh), then scripts/travel_direction_table.py. On a drive that does not
# turn, E_l makes cam_from_lidar's pitch and yaw follow the direction of travel that the cameras are
# given; the images-only column shows where the images alone put it. Writes
# docs/benchmarks/travel_direction.md (DOC to write another page).
#   RUNS      families and their number of seeds, "SCENE:SEEDS ..." (default: the mono drives, 10
#             seeds each)
#   VARIANT, JOINT_OPTIONS  the joint adjuster's variant (default: default), as for
#             benchmark_uncertainty.sh
#   WORK_DIR  keep the runs there (default: a temporary folder, removed); shared with
#             benchmark_uncertainty.sh
#   PIXEL_SAMPLES, BUILD_DIR, CLI: as for benchmark_uncertainty.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
source scripts/configure.sh
source scripts/true_pose_model.sh
use_work_dir
readonly kRuns="${RUNS:-street_drive:10 straight_drive:10 kitti_layout_drive:10}"
readonly kVariant="${VARIANT:-default}"
readonly kColmap="$kColmapPrefix/bin/colmap"
arguments=()
for entry in $kRuns; do
  scene="${entry%%:*}" seeds="${entry#*:}"
  family_joint_runs "$scene" "$seeds" "$work/travel-$scene-$kVariant.tsv"
  for seed in $(seq 1 "$seeds"); do
    echo "[$scene $seed] COLMAP's images-only adjustment from the true poses ..."
    images_only_adjustment "$kColmap" "$work/$scene-$seed"
  done
  arguments+=("$scene:$work/travel-$scene-$kVariant.tsv:$work")
done
mkdir -p docs/benchmarks
readonly kDoc="${DOC:-docs/benchmarks/travel_direction.md}"
python3 scripts/travel_direction_table.py "$kVariant" "${arguments[@]}" > "$kDoc"
cat "$kDoc"
