#!/usr/bin/env bash
# A drive that never turns (simulate_dataset --motion straight_drive): whether the pipeline
# initialises cam_from_lidar without a guess, and whether from a guess GUESS_DEG (default 2) /
# GUESS_M (default 0.05) off it ends no farther from the truth than the guess on every axis, with its
# errors within 3 reported sigmas on the axes it determines. Mono and stereo, SEEDS seeds each
# (default 3), DRIVE_FRAMES frames (default 40) of 120000 rays. Per run and camera axis: the start's
# error, the result's error, its sigma and z; "undet." = held at the start and reported without a
# sigma. Writes docs/benchmarks/straight_drive.md (DOC to write another page).
#   PIXEL_SAMPLES  rays per pixel axis of the images (simulate_dataset --pixel_samples; default 4:
#             one ray aliases the road ahead of the car)
#   WORK_DIR  keep the runs there (datasets and workspaces already there are not made again)
#   BUILD_DIR (default build); CLI: another colmap-lidar executable instead of building one
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
source scripts/configure.sh
use_cli
use_work_dir
readonly kPixelSamples="${PIXEL_SAMPLES:-4}"
results="$work/results.tsv"
: > "$results"

# simulate RIG SEED MONO: the drive of that seed with rig.json's guess into $work/RIG-SEED-dataset
# (once; both runs of the seed copy it, the run without a guess dropping the guess from rig.json).
simulate() {
  local data="$work/$1-$2-dataset"
  [ -d "$data" ] || "$cli" simulate_dataset --scene street --motion straight_drive \
    --mono "$3" --seed "$2" --num_stations "${DRIVE_FRAMES:-40}" --lidar_points 120000 \
    --write_guess 1 --guess_rotation_deg "${GUESS_DEG:-2}" \
    --guess_translation_m "${GUESS_M:-0.05}" --pixel_samples "$kPixelSamples" \
    --output_path "$data" > "$data.log" 2>&1
}

# run RIG SEED GUESS (0|1): simulation and the pipeline into $work/RIG-SEED-guessGUESS; appends the
# start's and the result's errors to the results.
run() {
  local rig=$1 seed=$2 guess=$3
  local dir="$work/$rig-$seed-guess$guess" mono=1
  [ "$rig" = stereo ] && mono=0
  echo "[$rig $seed, guess $guess] simulation and pipeline ..."
  simulate "$rig" "$seed" "$mono"
  if [ ! -d "$dir/dataset" ]; then
    # Hard links, not copies of the images and sweeps; rig.json is replaced, never written through
    # its link.
    mkdir -p "$dir" && cp -rl "$work/$rig-$seed-dataset" "$dir/dataset"
    [ "$guess" = 1 ] || python3 -c 'import json, os, sys
rig = json.load(open(sys.argv[1])); rig.pop("cam_from_lidar_guess")
json.dump(rig, open(sys.argv[1] + ".new", "w"), indent=2); os.replace(sys.argv[1] + ".new", sys.argv[1])' \
      "$dir/dataset/rig.json"
  fi
  if [ ! -f "$dir/ws/sparse/joint/cam_from_lidar.txt" ] &&
      ! "$cli" pipeline --dataset_path "$dir/dataset" --workspace_path "$dir/ws" \
        --Import.matcher sequential >> "$dir.log" 2>&1; then
    printf '%s\t%s\t%s\tFAILED\t%s\n' "$rig" "$seed" "$guess" \
      "$(grep -m1 -i 'error' "$dir.log" | tr '\t' ' ')" >> "$results"
    tail -1 "$results"
    return 0
  fi
  local truth="$dir/dataset/ground_truth/cam_from_lidar.txt" start="$dir/ws/sparse/initial/cam_from_lidar.txt"
  [ "$guess" = 1 ] && start="$dir/dataset/rig.json"
  {
    printf '%s\t%s\t%s\tstart\t' "$rig" "$seed" "$guess"
    python3 scripts/extrinsic_error.py "$truth" "$start" ''
    printf '%s\t%s\t%s\tresult\t' "$rig" "$seed" "$guess"
    python3 scripts/extrinsic_error.py "$truth" "$dir/ws/sparse/joint/cam_from_lidar.txt" \
      "$dir/ws/sparse/joint/report.json"
  } >> "$results"
  tail -1 "$results"
}

for rig in mono stereo; do
  for seed in $(seq 1 "${SEEDS:-3}"); do
    for guess in 0 1; do
      run "$rig" "$seed" "$guess"
    done
  done
done
mkdir -p docs/benchmarks
readonly kDoc="${DOC:-docs/benchmarks/straight_drive.md}"
python3 scripts/straight_drive_table.py "$results" "${GUESS_DEG:-2}" "${GUESS_M:-0.05}" \
  "$kPixelSamples" > "$kDoc"
cat "$kDoc"
