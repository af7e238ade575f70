#!/usr/bin/env bash
# End-to-end coverage of the reported cam_from_lidar uncertainty: the front end, LiDAR registration,
# initialisation (hand-eye, no guess) and the joint adjuster on several seeds of simulated scenes; per
# run and axis the error against the truth in units of the reported sigma, then the 2-sigma coverage per
# axis. Writes docs/benchmarks/uncertainty.md (DOC to write another page).
#   SEEDS (default 10), SCENES (default "t_specimen bridge_pier"), STATIONS (default 8),
#   SCENES="street_drive": the simulated street drive instead (one camera, DRIVE_FRAMES frames,
#                  default 40, 120000 rays per sweep, no guess; the whole `pipeline` with sequential
#                  matching), e.g. SEEDS=4 SCENES=street_drive DOC=docs/benchmarks/drive_uncertainty.md
#   SCENES="street_drive_stereo": the same drive with the second camera (stereo depth, depth priors,
#                  the stereo-LiDAR alignment of the pose initialiser)
#   LIDAR_POINTS per station (default 300000), BUILD_DIR (default build),
#   WORK_DIR       keep the runs there (default: a temporary folder, removed); steps already done in
#                  WORK_DIR are not run again, so that a changed joint adjuster can be re-evaluated on the
#                  same front ends by deleting the runs' ws/joint folders
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
source scripts/configure.sh
readonly kBuild="${BUILD_DIR:-build}"
build_cli "$kBuild"
cli="$kBuild/bin/colmap-lidar"
use_work_dir
results="$work/results.tsv"
: > "$results"
# One seed of tripod stations: the steps one by one (uses scene, seed, run, ws, joint, step).
run_stations() {
  step "$run/dataset" $cli simulate_dataset --scene "$scene" --seed "$seed" \
    --num_stations "${STATIONS:-8}" --lidar_points "${LIDAR_POINTS:-300000}" \
    --output_path "$run/dataset" &&
  step "$ws/stereo" $cli stereo_depth --dataset_path "$run/dataset" --output_path "$ws/stereo" &&
  step "$ws/db.db" $cli import_dataset --dataset_path "$run/dataset" --database_path "$ws/db.db" \
    --SiftExtraction.num_threads 2 --SiftMatching.num_threads 2 &&
  step "$ws/priors.done" $cli depth_prior_extractor --database_path "$ws/db.db" \
    --depth_path "$ws/stereo" && touch "$ws/priors.done" &&
  step "$ws/lidar" $cli lidar_registrator --lidar_path "$run/dataset/lidar" \
    --output_path "$ws/lidar" --max_neighbors 4 &&
  step "$ws/initial" $cli pose_initializer --database_path "$ws/db.db" \
    --dataset_path "$run/dataset" --registration_path "$ws/lidar" --output_path "$ws/initial" \
    --use_guess 0 &&
  step "$joint" $cli joint_adjuster --database_path "$ws/db.db" --input_path "$ws/initial" \
    --dataset_path "$run/dataset" --output_path "$joint"
}
# One seed of the street drive (mono unless the scene is street_drive_stereo): the whole pipeline.
run_drive() {
  local mono=1
  [ "$scene" = street_drive_stereo ] && mono=0
  step "$run/dataset" $cli simulate_dataset --scene street --motion drive --mono "$mono" \
    --seed "$seed" --num_stations "${DRIVE_FRAMES:-40}" --lidar_points 120000 \
    --write_guess 0 --output_path "$run/dataset" &&
  step "$joint" $cli pipeline --dataset_path "$run/dataset" --workspace_path "$ws" \
    --Import.matcher sequential
}
for scene in ${SCENES:-t_specimen bridge_pier}; do
  for seed in $(seq 1 "${SEEDS:-10}"); do
    run="$work/$scene-$seed"
    echo "[$scene seed $seed] simulating and running the pipeline ..."
    ws="$run/ws"
    mkdir -p "$ws"
    step() {  # step OUTPUT COMMAND...: runs COMMAND unless OUTPUT exists
      local output="$1"
      shift
      [ -e "$output" ] || "$@" >> "$run/log.txt" 2>&1
    }
    if [ "$scene" = street_drive ] || [ "$scene" = street_drive_stereo ]; then
      joint="$ws/sparse/joint"
      front_and_back_end=run_drive
    else
      joint="$ws/joint"
      front_and_back_end=run_stations
    fi
    if ! "$front_and_back_end"; then
      echo "  failed (see the log below)"; tail -5 "$run/log.txt"
      printf '%s\t%s\tFAILED\n' "$scene" "$seed" >> "$results"
      continue
    fi
    python3 scripts/extrinsic_error.py "$run/dataset/ground_truth/cam_from_lidar.txt" \
      "$joint/cam_from_lidar.txt" "$joint/report.json" "$scene" "$seed" >> "$results"
    tail -1 "$results"
  done
done
mkdir -p docs/benchmarks
readonly kDoc="${DOC:-docs/benchmarks/uncertainty.md}"
python3 scripts/uncertainty_table.py "$results" "${STATIONS:-8}" "${LIDAR_POINTS:-300000}" > "$kDoc"
cat "$kDoc"
