#!/usr/bin/env bash
# How far the camera's intrinsics, which the joint adjuster holds at the calibration's values, move
# cam_from_lidar on the real KITTI sample's two halves (frames 0-9 and 10-19, mono; the front ends and
# joint runs of scripts/benchmark_uncertainty.sh, family kitti_odometry_halves, made there unless
# WORK_DIR already has them): the joint adjuster again from the initial model with the principal
# point's x moved by CX_PX, and with both focal lengths scaled by 1 + F_SCALE. A change that moves an
# axis by different amounts in the two halves also moves the halves' difference, which the coverage
# page (uncertainty.md) reads as a test of the sigmas. Writes docs/benchmarks/intrinsics_sensitivity.md.
#   CX_PX     principal point shift [px] (default 2)
#   F_SCALE   relative focal length change (default 0.005)
#   WORK_DIR  keep the runs there (default: a temporary folder, removed); shared with
#             benchmark_uncertainty.sh
#   CLI, BUILD_DIR  as in benchmark_uncertainty.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
source scripts/configure.sh
use_cli
use_work_dir
readonly kColmap="$kColmapPrefix/bin/colmap"
readonly kCx="${CX_PX:-2}" kScale="${F_SCALE:-0.005}"
readonly kDoc="docs/benchmarks/intrinsics_sensitivity.md"
if [ ! -d "$PWD/../shared/data/kitti_odometry_04_sample" ]; then
  echo "../shared/data/kitti_odometry_04_sample is missing" >&2
  exit 1
fi
for half in 1 2; do
  if [ ! -e "$work/kitti_odometry_halves-mono-$half/joint-default/report.json" ]; then
    echo "Front ends and joint runs of the sample's halves by scripts/benchmark_uncertainty.sh ..."
    CLI="$cli" WORK_DIR="$work" SCENES=kitti_odometry_halves DOC="$work/uncertainty.md" \
      bash scripts/benchmark_uncertainty.sh >/dev/null
    break
  fi
done
results="$work/intrinsics_sensitivity.tsv"
: > "$results"
# change NAME AWK_PROGRAM: the joint adjuster on every half with the initial model's PINHOLE camera
# rewritten by AWK_PROGRAM (fields 5-8: fx fy cx cy).
change() {
  local name="$1" program="$2" half run model
  for half in 1 2; do
    run="$work/kitti_odometry_halves-mono-$half"
    model="$run/intrinsics-$name"
    rm -rf "$model" "$model-txt" && mkdir -p "$model" "$model-txt"
    "$kColmap" model_converter --input_path "$run/ws/sparse/initial" --output_path "$model-txt" \
      --output_type TXT >/dev/null
    if ! grep -q "^[0-9]* PINHOLE " "$model-txt/cameras.txt"; then
      echo "$model-txt/cameras.txt: a PINHOLE camera expected" >&2
      exit 1
    fi
    awk "\$2 == \"PINHOLE\" { $program } { print }" "$model-txt/cameras.txt" > "$model-txt/c"
    mv "$model-txt/c" "$model-txt/cameras.txt"
    "$kColmap" model_converter --input_path "$model-txt" --output_path "$model" \
      --output_type BIN >/dev/null
    cp "$run/ws/sparse/initial/"*.json "$run/ws/sparse/initial/cam_from_lidar.txt" "$model/"
    echo "[$name, frames of half $half] joint adjuster ..."
    if ! (cd "$run" && "$cli" joint_adjuster --database_path ws/database.db --input_path "$model" \
        --dataset_path dataset --registration_path ws/lidar --output_path "$model-joint" \
        > "$model-joint.log" 2>&1); then
      echo "joint_adjuster failed on $model (see $model-joint.log)" >&2
      exit 1
    fi
    python3 scripts/extrinsic_error.py "$run/dataset/ground_truth/cam_from_lidar.txt" \
      "$model-joint/cam_from_lidar.txt" "$model-joint/report.json" "$name" "$half" >> "$results"
  done
}
for half in 1 2; do
  run="$work/kitti_odometry_halves-mono-$half"
  python3 scripts/extrinsic_error.py "$run/dataset/ground_truth/cam_from_lidar.txt" \
    "$run/joint-default/cam_from_lidar.txt" "$run/joint-default/report.json" none "$half" >> "$results"
done
change "cx+$kCx" "\$7 = \$7 + $kCx"
change "f*(1+$kScale)" "\$5 = \$5 * (1 + $kScale); \$6 = \$6 * (1 + $kScale)"
python3 scripts/intrinsics_sensitivity_table.py "$results" > "$kDoc"
cat "$kDoc"
