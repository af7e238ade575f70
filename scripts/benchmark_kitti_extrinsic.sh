#!/usr/bin/env bash
# cam_from_lidar on the real KITTI odometry sample (../shared/data/kitti_odometry_04_sample: 20 frames
# of a straight drive, HDL-64, KITTI's calibration as the reference), stereo and mono, started from
# KITTI's calibration perturbed by GUESS_DEG (default 2) / GUESS_M (default 0.05) with SEEDS (default
# "0"). The pipeline runs once per rig and seed up to the joint adjuster; the joint adjuster then runs
# in each estimator variant on the same front end (default; fixed weights without the clock offset;
# nothing held: the hold thresholds lifted, so that every direction is estimated). Per run and
# camera axis: the error, the reported sigma and z = error / sigma ("undetermined": held at the
# start, no sigma). Then each rig once
# without a guess: the pose initialiser's start (the travel direction and the structure) and the
# joint adjuster from it, default and with nothing held. Writes docs/benchmarks/kitti_extrinsic.md.
#   WORK_DIR  keep the workspaces there (steps already done are not run again); default: temporary
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
source scripts/configure.sh
build_cli build
readonly cli="$PWD/build/bin/colmap-lidar"
readonly kSample="$PWD/../shared/data/kitti_odometry_04_sample"
use_work_dir
results="$work/results.tsv"
: > "$results"
# The estimator variants: a label and the joint adjuster's options.
variants=(
  "default|"
  "fixed weights, no clock offset|--estimate_variance_components 0 --estimate_time_offset 0"
  "nothing held|--hold_rotation_deg 1e9 --hold_translation_mm 1e9"
)

# Import and the pipeline's front end for one rig (stereo: USE_RIGHT 1) and seed; WRITE_GUESS 0: no
# guess in rig.json.
front_end() {
  local run=$1 use_right=$2 seed=$3 write_guess=${4:-1}
  [ -f "$run/ws/steps/pose_initializer.done" ] && return 0
  rm -rf "$run"
  mkdir -p "$run"
  "$cli" import_kitti --format odometry --sequence_path "$kSample" \
    --poses_path "$kSample/poses/04.txt" --output_path "$run/ds" --use_right "$use_right" \
    --write_guess "$write_guess" --guess_rotation_deg "${GUESS_DEG:-2}" --guess_translation_m "${GUESS_M:-0.05}" \
    --seed "$seed" > "$run/import.log" 2>&1
  "$cli" pipeline --dataset_path "$run/ds" --workspace_path "$run/ws" --Import.matcher sequential \
    > "$run/pipeline.log" 2>&1
}

# joint RUN RIG START VARIANT: the joint adjuster in VARIANT ("label|options") on RUN's front end;
# appends the errors to the results (START: the seed, or "no guess").
joint() {
  local run=$1 rig=$2 start=$3 label=${4%%|*} options=${4#*|}
  local out
  out="$run/joint-$(echo "$label" | tr -c 'a-z' '_')"
  echo "[$rig, $start] joint adjuster: $label"
  # shellcheck disable=SC2086
  "$cli" joint_adjuster --database_path "$run/ws/database.db" --input_path "$run/ws/sparse/initial" \
    --dataset_path "$run/ds" --output_path "$out" $options > "$out.log" 2>&1
  python3 scripts/extrinsic_error.py "$run/ds/ground_truth/cam_from_lidar.txt" \
    "$out/cam_from_lidar.txt" "$out/report.json" "$rig" "$start" "$label" >> "$results"
  tail -1 "$results"
}

for seed in ${SEEDS:-0}; do
  for rig in stereo mono; do
    run="$work/$rig-$seed"
    use_right=1
    [ "$rig" = mono ] && use_right=0
    echo "[$rig, seed $seed] front end"
    front_end "$run" "$use_right" "$seed"
    python3 scripts/extrinsic_error.py "$run/ds/ground_truth/cam_from_lidar.txt" "$run/ds/rig.json" \
      "" "$rig" "$seed" "start (the guess)" >> "$results"
    for variant in "${variants[@]}"; do joint "$run" "$rig" "$seed" "$variant"; done
  done
done
for rig in stereo mono; do
  run="$work/$rig-noguess"
  use_right=1
  [ "$rig" = mono ] && use_right=0
  echo "[$rig, no guess] front end"
  front_end "$run" "$use_right" 0 0
  python3 scripts/extrinsic_error.py "$run/ds/ground_truth/cam_from_lidar.txt" \
    "$run/ws/sparse/initial/cam_from_lidar.txt" "" "$rig" "no guess" \
    "start (travel direction and structure)" >> "$results"
  for variant in "${variants[0]}" "${variants[2]}"; do joint "$run" "$rig" "no guess" "$variant"; done
done
mkdir -p docs/benchmarks
python3 scripts/kitti_reference_uncertainty.py "$PWD/../shared/data/kitti_raw_2011_09_28_sample/calibration" \
  "$kSample/calib.txt" > "$work/reference.tsv"
python3 scripts/kitti_extrinsic_table.py "$results" "${GUESS_DEG:-2}" "${GUESS_M:-0.05}" \
  "$work/reference.tsv" > docs/benchmarks/kitti_extrinsic.md
echo "Wrote docs/benchmarks/kitti_extrinsic.md"
