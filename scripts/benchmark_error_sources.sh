#!/usr/bin/env bash
# Where cam_from_lidar's error on a simulated drive comes from: the joint adjuster on the same front
# end with the image data replaced, one error source at a time (scripts/synthetic_keypoints.py, at
# COLMAP's landmarks triangulated at the true poses, scripts/true_pose_model.sh):
#   default      SIFT's keypoints (the run of scripts/benchmark_uncertainty.sh)
#   exact_noise  exact projections of those landmarks plus Gaussian noise of SIFT's rms there
#   exact        exact projections, no noise (the landmarks keep SIFT's offsets from the surfaces)
#   surface      exact projections of the landmarks moved onto the true surfaces (families with
#                true depth maps), no noise: what is left is the LiDAR side and the estimator
# Writes docs/benchmarks/error_sources.md (DOC to write another page).
#   RUNS      families and their number of seeds, "SCENE:SEEDS ..." (default:
#             kitti_layout_drive:6 street_drive_20:3 straight_drive:6)
#   JOBS      joint runs at a time (default 2)
#   WORK_DIR  keep the runs there (default: a temporary folder, removed); shared with
#             benchmark_uncertainty.sh
#   PIXEL_SAMPLES, BUILD_DIR, CLI: as for benchmark_uncertainty.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
source scripts/configure.sh
source scripts/true_pose_model.sh
use_work_dir
use_cli
readonly kRuns="${RUNS:-kitti_layout_drive:6 street_drive_20:3 straight_drive:6}"
readonly kColmap="$kColmapPrefix/bin/colmap"

# synthetic_run RUN KIND: the joint adjuster on RUN's front end with KIND's keypoints, into
# RUN/sources-KIND; appends the error to $work/sources-<scene>-KIND.tsv.
synthetic_run() {
  local run=$1 kind=$2 scene seed noise=0 synthetic=surface
  scene=$(basename "$run") seed="${scene##*-}" scene="${scene%-*}"
  local out="$run/sources-$kind"
  [ "$kind" = exact_noise ] && noise=$(python3 scripts/synthetic_keypoints.py rms \
    "$run/true_pose_landmarks/triangulated")
  [ "$kind" != surface ] && synthetic=exact
  if [ ! -e "$out/joint/report.json" ]; then
    rm -rf "$out" && mkdir -p "$out/model"
    python3 - "$run/ws/database.db" "$out/database.db" <<'EOF'
import sqlite3, sys
source, target = sqlite3.connect(sys.argv[1]), sqlite3.connect(sys.argv[2])
source.backup(target)
EOF
    python3 scripts/synthetic_keypoints.py "$synthetic" "$run/true_pose_landmarks/triangulated" \
      "$out/database.db" "$run/true_pose_landmarks/input" "$out/model" "$run/dataset" "$noise" \
      "$seed" > "$out/log.txt"
    cp "$run"/ws/sparse/initial/*.txt "$run"/ws/sparse/initial/*.json "$out/model/" 2>/dev/null || true
    "$cli" joint_adjuster --database_path "$out/database.db" --input_path "$out/model" \
      --dataset_path "$run/dataset" --registration_path "$run/ws/lidar" \
      --output_path "$out/joint" >> "$out/log.txt" 2>&1 || true
  fi
  python3 scripts/extrinsic_error.py "$run/dataset/ground_truth/cam_from_lidar.txt" \
    "$out/joint/cam_from_lidar.txt" "$out/joint/report.json" "$scene" "$seed" \
    > "$out/error.tsv" 2>/dev/null || printf '%s\t%s\tFAILED\t%s\n' "$scene" "$seed" \
    "$(grep -m1 -o 'ERROR: .*' "$out/log.txt" | sed 's/\. Hold what.*//')" > "$out/error.tsv"
  nearest_landmark "$scene" "$seed" "$kind" "$out/joint" > "$out/nearest.tsv"
}

# nearest_landmark SCENE SEED KIND MODEL: a line of the nearest-landmark table.
nearest_landmark() {
  if [ -e "$4/points3D.bin" ]; then
    printf '%s\t%s\t%s\t%s\n' "$1" "$2" "$3" "$(python3 scripts/nearest_landmark.py "$4")"
  fi
}

arguments=()
for entry in $kRuns; do
  scene="${entry%%:*}" seeds="${entry#*:}"
  VARIANT=default JOINT_OPTIONS="" family_joint_runs "$scene" "$seeds" \
    "$work/sources-$scene-default.tsv"
  for seed in $(seq 1 "$seeds"); do
    nearest_landmark "$scene" "$seed" default "$work/$scene-$seed/joint-default"
  done > "$work/nearest-$scene.tsv"
  kinds="exact_noise exact"
  [ -d "$work/$scene-1/dataset/ground_truth/depth" ] && kinds="$kinds surface"
  for seed in $(seq 1 "$seeds"); do
    true_pose_landmarks "$kColmap" "$work/$scene-$seed"
  done
  for kind in $kinds; do
    echo "[$scene] joint runs on $kind keypoints ..."
    for seed in $(seq 1 "$seeds"); do
      synthetic_run "$work/$scene-$seed" "$kind" &
      while [ "$(jobs -rp | wc -l)" -ge "${JOBS:-2}" ]; do wait -n; done
    done
    wait
    for seed in $(seq 1 "$seeds"); do
      cat "$work/$scene-$seed/sources-$kind/error.tsv"
    done > "$work/sources-$scene-$kind.tsv"
    for seed in $(seq 1 "$seeds"); do
      cat "$work/$scene-$seed/sources-$kind/nearest.tsv"
    done >> "$work/nearest-$scene.tsv"
    arguments+=("$scene:$kind:$work/sources-$scene-$kind.tsv")
  done
  arguments+=("$scene:default:$work/sources-$scene-default.tsv")
done
mkdir -p docs/benchmarks
readonly kDoc="${DOC:-docs/benchmarks/error_sources.md}"
cat "$work"/nearest-*.tsv > "$work/nearest.tsv"
python3 scripts/error_sources_table.py "$work/nearest.tsv" "${arguments[@]}" > "$kDoc"
cat "$kDoc"
