#!/usr/bin/env bash
# Whether the reported cam_from_lidar sigmas hold, over seeds and scene families: per family and seed
# the front end is made once (simulation, the pipeline's steps up to the initial model), then the
# joint adjuster alone runs on it; per run and camera axis the error against the truth, the reported
# sigma and z = error / sigma; per family how many errors lie beyond 2 sigma, the rms z and the
# undetermined axes. Writes docs/benchmarks/uncertainty.md (DOC to write another page).
#   SCENES  families (default: all of them):
#     t_specimen, bridge_pier  tripod stations of a stereo pod (STATIONS, default 8; LIDAR_POINTS per
#                              station, default 300000), hand-eye initialisation without a guess
#     street_drive             the simulated street drive, one camera (DRIVE_FRAMES, default 40;
#                              120000 rays per sweep), no guess, the whole pipeline's front end
#     street_drive_stereo      the same drive with the second camera
#     street_drive_20          its first 20 frames (those of kitti_layout_drive) in the simulator's
#                              own layout, with true depth maps; not among the defaults
#     straight_drive           the street drive in one lane without a turn (simulate_dataset
#                              --motion straight_drive), one camera, no guess
#     kitti_layout_drive       20 frames of the street drive written in KITTI raw's layout (one
#                              camera), imported by import_kitti with its seeded 1 deg / 5 cm guess
#     kitti_odometry           the real sample ../shared/data/kitti_odometry_04_sample, stereo and
#                              mono, no guess, against KITTI's calibration (one run per rig, no seeds)
#     kitti_odometry_halves    its frames 0-9 and 10-19 as two drives (seeds stereo-1, stereo-2,
#                              mono-1, mono-2): the difference of the halves' estimates tests the
#                              sigmas without the reference
#   SEEDS   seeds 1..SEEDS of the simulated families (default 10); DRIVE_SEEDS those of the drives
#           (default SEEDS)
#   VARIANT the joint adjuster's run is RUN/joint-VARIANT (default: default), with JOINT_OPTIONS
#           (extra joint_adjuster options): variants of the estimator compared on the same front ends
#   START   initial (default): the joint adjuster starts from the pose initialiser's cam_from_lidar;
#           truth: from the true one (the reference). Started at the truth, an estimator whose result
#           does not depend on its start stays within its sigmas; how far it walks away shows what
#           the associations and the model's errors add. Use with its own VARIANT.
#   PIXEL_SAMPLES  rays per pixel axis of the simulated drives' images (simulate_dataset
#           --pixel_samples; default 4: one ray aliases the road ahead of the car)
#   WORK_DIR  keep the runs there (default: a temporary folder, removed); front ends and joint runs
#           already there are not made again (whatever PIXEL_SAMPLES they were made with)
#   BUILD_DIR (default build); CLI: another colmap-lidar executable instead of building one (a
#           variant of the estimator built elsewhere)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
source scripts/configure.sh
use_cli
readonly kSample="$PWD/../shared/data/kitti_odometry_04_sample"
readonly kVariant="${VARIANT:-default}"
readonly kPixelSamples="${PIXEL_SAMPLES:-4}"
use_work_dir
results="$work/results-$kVariant.tsv"
: > "$results"

# step OUTPUT COMMAND...: runs COMMAND (output to RUN/log.txt) unless OUTPUT exists.
step() {
  local output="$1"
  shift
  [ -e "$output" ] || "$@" >> "$run/log.txt" 2>&1
}
# Each front end sets the joint adjuster's inputs: dataset, ws (database.db, initial model) and
# registration (lidar_registrator's folder, empty: the dataset's clouds).
stations_front_end() {
  dataset="$run/dataset" registration="$run/ws/lidar"
  step "$dataset" "$cli" simulate_dataset --scene "$scene" --seed "$seed" \
    --num_stations "${STATIONS:-8}" --lidar_points "${LIDAR_POINTS:-300000}" --output_path "$dataset" &&
  step "$run/ws/stereo" "$cli" stereo_depth --dataset_path "$dataset" --output_path "$run/ws/stereo" &&
  step "$run/ws/db.db" "$cli" import_dataset --dataset_path "$dataset" --database_path "$run/ws/db.db" \
    --SiftExtraction.num_threads 2 --SiftMatching.num_threads 2 &&
  step "$run/ws/priors.done" "$cli" depth_prior_extractor --database_path "$run/ws/db.db" \
    --depth_path "$run/ws/stereo" && touch "$run/ws/priors.done" &&
  step "$registration" "$cli" lidar_registrator --lidar_path "$dataset/lidar" \
    --output_path "$registration" --max_neighbors 4 &&
  step "$run/ws/initial" "$cli" pose_initializer --database_path "$run/ws/db.db" \
    --dataset_path "$dataset" --registration_path "$registration" --output_path "$run/ws/initial" \
    --use_guess 0 &&
  database="$run/ws/db.db" initial="$run/ws/initial"
}
# The pipeline on DATASET into RUN/ws up to its initial model (the benchmark's runs start there).
pipeline_front_end() {
  database="$run/ws/database.db" initial="$run/ws/sparse/initial" registration="$run/ws/lidar"
  step "$run/ws/steps/pose_initializer.done" "$cli" pipeline --dataset_path "$dataset" \
    --workspace_path "$run/ws" --Import.matcher sequential --stop_after pose_initializer
}
drive_front_end() {
  local mono=1 motion=drive frames="${DRIVE_FRAMES:-40}"
  [ "$scene" = street_drive_stereo ] && mono=0
  [ "$scene" = street_drive_20 ] && frames=20
  [ "$scene" = straight_drive ] && motion=straight_drive
  dataset="$run/dataset"
  step "$dataset" "$cli" simulate_dataset --scene street --motion "$motion" --mono "$mono" \
    --seed "$seed" --num_stations "$frames" --lidar_points 120000 --write_guess 0 \
    --pixel_samples "$kPixelSamples" --output_path "$dataset" && pipeline_front_end
}
kitti_layout_front_end() {
  dataset="$run/dataset"
  step "$run/kitti" "$cli" simulate_dataset --scene street --motion drive --layout kitti --mono 1 \
    --seed "$seed" --num_stations 20 --lidar_points 120000 --pixel_samples "$kPixelSamples" \
    --output_path "$run/kitti" &&
  step "$dataset" "$cli" import_kitti --kitti_path "$run/kitti/drive" \
    --calib_path "$run/kitti/calibration" --output_path "$dataset" --write_guess 1 \
    --guess_rotation_deg 1 --seed "$seed" && pipeline_front_end
}
kitti_odometry_front_end() {  # seed: stereo | mono, or with the half: stereo-1 | stereo-2 | ...
  local use_right=1 frames=()
  [ "${seed%-*}" = mono ] && use_right=0
  [ "$seed" != "${seed%-1}" ] && frames=(--first 0 --last 9)
  [ "$seed" != "${seed%-2}" ] && frames=(--first 10 --last 19)
  dataset="$run/dataset"
  step "$dataset" "$cli" import_kitti --format odometry --sequence_path "$kSample" \
    --poses_path "$kSample/poses/04.txt" --output_path "$dataset" --use_right "$use_right" \
    "${frames[@]}" && pipeline_front_end
}

for scene in ${SCENES:-t_specimen bridge_pier street_drive street_drive_stereo straight_drive kitti_layout_drive kitti_odometry kitti_odometry_halves}; do
  seeds=$(seq 1 "${SEEDS:-10}")
  case "$scene" in
    t_specimen | bridge_pier) front_end=stations_front_end ;;
    street_drive | street_drive_stereo | straight_drive | street_drive_20)
      front_end=drive_front_end seeds=$(seq 1 "${DRIVE_SEEDS:-${SEEDS:-10}}") ;;
    kitti_layout_drive)
      front_end=kitti_layout_front_end seeds=$(seq 1 "${DRIVE_SEEDS:-${SEEDS:-10}}") ;;
    kitti_odometry) front_end=kitti_odometry_front_end seeds="stereo mono" ;;
    kitti_odometry_halves)
      front_end=kitti_odometry_front_end seeds="stereo-1 stereo-2 mono-1 mono-2" ;;
    *) echo "unknown scene $scene" >&2; exit 2 ;;
  esac
  if [ "${scene%_halves}" = kitti_odometry ] && [ ! -d "$kSample" ]; then
    echo "[$scene] skipped: $kSample is missing"
    continue
  fi
  for seed in $seeds; do
    run="$work/$scene-$seed"
    joint="$run/joint-$kVariant"
    mkdir -p "$run"
    echo "[$scene $seed] front end and joint adjuster ($kVariant) ..."
    start_option=()
    if [ "${START:-initial}" = truth ]; then
      start_option=(--cam_from_lidar "$run/dataset/ground_truth/cam_from_lidar.txt")
    fi
    # shellcheck disable=SC2086
    if ! "$front_end" || ! step "$joint" "$cli" joint_adjuster --database_path "$database" \
        --input_path "$initial" --dataset_path "$dataset" --registration_path "$registration" \
        --output_path "$joint" ${JOINT_OPTIONS:-} "${start_option[@]}"; then
      echo "  failed (see the log below)"; tail -5 "$run/log.txt"
      printf '%s\t%s\tFAILED\n' "$scene" "$seed" >> "$results"
      continue
    fi
    python3 scripts/extrinsic_error.py "$dataset/ground_truth/cam_from_lidar.txt" \
      "$joint/cam_from_lidar.txt" "$joint/report.json" "$scene" "$seed" >> "$results"
    tail -1 "$results"
  done
done
mkdir -p docs/benchmarks
readonly kDoc="${DOC:-docs/benchmarks/uncertainty.md}"
reference=""
readonly kOtherDay="$PWD/../shared/data/kitti_raw_2011_09_28_sample/calibration"
if [ -d "$kSample" ] && [ -d "$kOtherDay" ]; then  # the real sample's reference's own uncertainty
  reference="$work/reference.tsv"
  python3 scripts/kitti_reference_uncertainty.py "$kOtherDay" "$kSample/calib.txt" > "$reference"
fi
START="${START:-initial}" PIXEL_SAMPLES="$kPixelSamples" REFERENCE_TSV="$reference" \
  python3 scripts/uncertainty_table.py "$results" "$kVariant" "${JOINT_OPTIONS:-}" > "$kDoc"
cat "$kDoc"
