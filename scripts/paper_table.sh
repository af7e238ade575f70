#!/usr/bin/env bash
# The seed paper's comparison on simulated data, in one run: for each column (a scene and a noise
# setting) one dataset, one front end (the pipeline: SIFT, stereo depth, depth priors, LiDAR
# registration, initialisation), then five back ends on the same front end:
#   1. stereo only      joint_adjuster --mode stereo_only, densifier --refine_with_lidar 0
#   2. guess, held      --mode precalibrated at rig.json's guess (3 deg / 5 cm off)
#   3. edges, held      calibrate_edges (Levinson & Thrun) from the guess, then --mode precalibrated
#   4. joint, no guess  pose_initializer --use_guess 0 (hand-eye), then --mode joint
#   5. joint, guess     the pipeline's own result
# Each row: cam_from_lidar error, station position error (mean), dense model mean error and
# completeness at 5 mm against the true surface, and the back end's time. A row that fails says so.
# Writes docs/benchmarks/paper_table.md (replaced; the figures are this run's) from the raw rows in
# TABLE_DIR/rows.tsv (copied to docs/benchmarks/paper_table_rows.tsv), with the reading in
# scripts/paper_table_reading.md below the tables (it names the run it was written for).
#   scripts/paper_table.sh            the five columns below (about 30 min on 2 cores)
#   COLUMNS="t_specimen:0.01:1" scripts/paper_table.sh   chosen columns, scene:range_noise_m:grey
#   TABLE_DIR  datasets and workspaces (default /tmp/colmap-lidar-paper-table)
#   BUILD_DIR  build directory (default build)
#   STATIONS, RAYS  per dataset (default 10 stations, 400000 rays)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
readonly kColmapPrefix="${COLMAP_LIDAR_COLMAP_PREFIX:-$HOME/.cache/colmap-lidar/colmap-3.10}"
readonly kDir="${TABLE_DIR:-/tmp/colmap-lidar-paper-table}"
readonly kBuildDir="${BUILD_DIR:-build}"
readonly kStations="${STATIONS:-10}" kRays="${RAYS:-400000}"
readonly kDoc=docs/benchmarks/paper_table.md
cmake -S . -B "$kBuildDir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$kColmapPrefix" >/dev/null
cmake --build "$kBuildDir" -j "$(nproc)" --target colmap_lidar_cli >/dev/null
readonly cli="$PWD/$kBuildDir/bin/colmap-lidar"
read -r -a columns <<<"${COLUMNS:-t_specimen:0.01:1 t_specimen:0.005:1 t_specimen:0.03:1 t_specimen:0.01:3 bridge_pier:0.01:1}"
mkdir -p "$kDir"
readonly rows="$kDir/rows.tsv"
printf 'column\trow\tstatus\trotation_deg\ttranslation_mm\tposition_mm\tdense_mean_mm\tcompleteness_5mm\tseconds\n' >"$rows"

run() {  # log, command...: the command's output to the log; false if it failed
  local log=$1
  shift
  "$@" >"$log" 2>&1
}

json() {  # file key -> value or n/a
  python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$1" "$2" 2>/dev/null ||
    echo n/a
}

# Evaluates model D/NAME/joint and D/NAME/dense and appends a row.
record() {  # column dir name label seconds
  local column=$1 d=$2 name=$3 label=$4 seconds=$5 e=$2/$3/eval status=ok
  run "$d/$name/evaluate.log" "$cli" evaluate_calibration --dataset_path "$d/dataset" \
    --input_path "$d/$name/joint" --output_path "$e" || status="evaluation failed"
  run "$d/$name/evaluate_model.log" "$cli" evaluate_model --model_path "$d/$name/dense/fused.ply" \
    --ground_truth_path "$d/dataset/ground_truth/surface.ply" \
    --truth_from_model "$e/truth_from_model.txt" --output_path "$e/model" ||
    status="dense evaluation failed"
  local r t
  r=$(json "$e/metrics.json" cam_from_lidar_rotation_error_deg)
  t=$(json "$e/metrics.json" cam_from_lidar_translation_error_mm)
  [ "$label" = "1. stereo only" ] && r="-" && t="-"
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$column" "$label" "$status" "$r" "$t" \
    "$(json "$e/metrics.json" pose_position_error_mean_mm)" \
    "$(python3 -c "import json,sys; print(1000*json.load(open(sys.argv[1]))['mean_m'])" \
      "$e/model/metrics.json" 2>/dev/null || echo n/a)" \
    "$(json "$e/model/metrics.json" completeness_5mm)" "$seconds" >>"$rows"
}

failed() {  # column label why
  printf '%s\t%s\t%s\tn/a\tn/a\tn/a\tn/a\tn/a\tn/a\n' "$1" "$2" "$3" >>"$rows"
}

# joint_adjuster (mode, start model, optional cam_from_lidar file) and densifier into D/NAME.
back_end() {  # column dir name label mode input [cam_from_lidar] [refine]
  local column=$1 d=$2 name=$3 label=$4 mode=$5 input=$6 extrinsic=${7:-} refine=${8:-1}
  local start extra=()
  [ -n "$extrinsic" ] && extra=(--cam_from_lidar "$extrinsic")
  rm -rf "${d:?}/$name/joint" "${d:?}/$name/dense" && mkdir -p "$d/$name"
  start=$(date +%s)
  if ! run "$d/$name/joint.log" "$cli" joint_adjuster --database_path "$d/ws/database.db" \
    --input_path "$input" --dataset_path "$d/dataset" --registration_path "$d/ws/lidar" \
    --output_path "$d/$name/joint" --mode "$mode" "${extra[@]}"; then
    failed "$column" "$label" "joint_adjuster failed: $(tail -1 "$d/$name/joint.log")"
    return
  fi
  if ! run "$d/$name/densifier.log" "$cli" densifier --input_path "$d/$name/joint" \
    --dataset_path "$d/dataset" --depth_path "$d/ws/stereo" --registration_path "$d/ws/lidar" \
    --output_path "$d/$name/dense" --refine_with_lidar "$refine"; then
    failed "$column" "$label" "densifier failed: $(tail -1 "$d/$name/densifier.log")"
    return
  fi
  record "$column" "$d" "$name" "$label" "$(($(date +%s) - start))"
}

run_column() {
  local column=$1 scene range grey d
  IFS=: read -r scene range grey <<<"$column"
  d="$kDir/${scene}_${range}_${grey}"
  mkdir -p "$d"
  echo "[paper_table] $column: simulating and the pipeline" >&2
  run "$d/simulate.log" "$cli" simulate_dataset --scene "$scene" --num_stations "$kStations" \
    --lidar_points "$kRays" --range_noise_m "$range" --pixel_noise "$grey" \
    --output_path "$d/dataset" --overwrite 1
  rm -rf "$d/ws"
  if ! run "$d/pipeline.log" "$cli" pipeline --dataset_path "$d/dataset" --workspace_path "$d/ws"; then
    for label in "1. stereo only" "2. guess, held" "3. edges, held" "4. joint, no guess" "5. joint, guess"; do
      failed "$column" "$label" "front end failed: $(grep -m1 ERROR "$d/pipeline.log" || tail -1 "$d/pipeline.log")"
    done
    return
  fi
  local initial=$d/ws/sparse/initial
  echo "[paper_table] $column: back ends" >&2
  back_end "$column" "$d" stereo_only "1. stereo only" stereo_only "$initial" "" 0
  back_end "$column" "$d" guess_held "2. guess, held" precalibrated "$initial"
  if run "$d/edges.log" "$cli" calibrate_edges --dataset_path "$d/dataset" --input_path "$initial" \
    --output_path "$d/edges"; then
    back_end "$column" "$d" edges_held "3. edges, held" precalibrated "$initial" \
      "$d/edges/cam_from_lidar.txt"
  else
    failed "$column" "3. edges, held" "calibrate_edges failed: $(tail -1 "$d/edges.log")"
  fi
  rm -rf "$d/no_guess_initial"
  # --use_guess 0 falls back to the guess when the hand-eye is impossible: that row then fails.
  local source
  if run "$d/no_guess_initial.log" "$cli" pose_initializer --database_path "$d/ws/database.db" \
    --dataset_path "$d/dataset" --registration_path "$d/ws/lidar" \
    --output_path "$d/no_guess_initial" --use_guess 0; then
    source=$(json "$d/no_guess_initial/initialization.json" extrinsic_source)
    if [[ "$source" == *guess* ]]; then
      failed "$column" "4. joint, no guess" "no hand-eye: $source"
    else
      back_end "$column" "$d" joint_no_guess "4. joint, no guess" joint "$d/no_guess_initial"
    fi
  else
    failed "$column" "4. joint, no guess" "no hand-eye: $(tail -1 "$d/no_guess_initial.log")"
  fi
  # Row 5 is the pipeline's own joint model and dense model.
  mkdir -p "$d/pipeline"
  ln -sfn "$d/ws/sparse/joint" "$d/pipeline/joint"
  ln -sfn "$d/ws/dense" "$d/pipeline/dense"
  record "$column" "$d" pipeline "5. joint, guess" \
    "$(python3 -c "
import csv,sys
print(round(sum(float(r[2]) for r in csv.reader(open(sys.argv[1])) if r[0] in ('joint_adjuster','densifier'))))" \
      "$d/ws/pipeline_steps.csv" 2>/dev/null || echo n/a)"
}

for column in "${columns[@]}"; do run_column "$column"; done
python3 scripts/paper_table.py "$rows" "$kStations" "$kRays" "$(git rev-parse --short HEAD)" >"$kDoc.tmp"
mv "$kDoc.tmp" "$kDoc"
cp "$rows" docs/benchmarks/paper_table_rows.tsv
echo "[paper_table] wrote $kDoc" >&2
