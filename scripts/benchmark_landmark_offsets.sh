#!/usr/bin/env bash
# Where COLMAP's landmarks sit relative to the true surface on the simulated mono street drive, with
# no estimate involved: per seed, the pipeline's front end (scripts/benchmark_uncertainty.sh, SCENES
# street_drive, made there unless WORK_DIR already has it), then COLMAP's point_triangulator on its
# database at the true camera poses, then per landmark its signed offset along the true surface's
# normal (scripts/landmark_offset_table.py), tabulated by the surface (road, walls) and by distance
# and obliqueness, and the keypoints' image rows against the landmarks' projections by the distance
# they are seen from. E_m pulls landmarks onto the LiDAR's surfaces; an offset common to a surface
# ends in cam_from_lidar's translation along its normal. Writes docs/benchmarks/landmark_offsets.md.
#   SEEDS     seeds 1..SEEDS (default 4)
#   WORK_DIR  keep the runs there (default: a temporary folder, removed); shared with
#             benchmark_uncertainty.sh
#   CLI, BUILD_DIR  as in benchmark_uncertainty.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
source scripts/configure.sh
source scripts/true_pose_model.sh
use_cli
use_work_dir
readonly kSeeds="${SEEDS:-4}"
readonly kColmap="$kColmapPrefix/bin/colmap"
for seed in $(seq 1 "$kSeeds"); do
  if [ ! -e "$work/street_drive-$seed/ws/steps/pose_initializer.done" ]; then
    echo "Front ends (and joint runs) of the street drive by scripts/benchmark_uncertainty.sh ..."
    CLI="$cli" WORK_DIR="$work" SCENES=street_drive DRIVE_SEEDS="$kSeeds" \
      DOC="$work/uncertainty.md" bash scripts/benchmark_uncertainty.sh >/dev/null
    break
  fi
done
arguments=()
for seed in $(seq 1 "$kSeeds"); do
  run="$work/street_drive-$seed"
  echo "[street_drive $seed] triangulating at the true poses ..."
  true_pose_landmarks "$kColmap" "$run"
  arguments+=("$seed:$run/true_pose_landmarks/triangulated:$run/dataset")
done
# The same rows at the joint adjuster's own poses (no truth needed), for the real KITTI sample when
# benchmark_uncertainty.sh has run it in WORK_DIR: the road is 1.65 m under both cars' camera.
adjusted=()
for name in kitti_odometry-mono kitti_odometry-stereo street_drive-1; do
  [ -e "$work/$name/joint-default/images.bin" ] || continue
  mkdir -p "$work/road_rows/$name"
  "$kColmap" model_converter --input_path "$work/$name/joint-default" \
    --output_path "$work/road_rows/$name" --output_type TXT > /dev/null 2>&1
  adjusted+=("$name:$work/road_rows/$name")
done
mkdir -p docs/benchmarks
readonly kDoc=docs/benchmarks/landmark_offsets.md
{
  echo "# Landmarks against the true surface, at the true poses"
  echo
  echo "Written by \`scripts/benchmark_landmark_offsets.sh\` on $(date +%F) ($(nproc) cores)."
  echo "The simulated street drive, one camera, 40 frames (the front ends of"
  echo "[uncertainty_drives.md](uncertainty_drives.md)); COLMAP's \`point_triangulator\` on each"
  echo "front end's database at the true camera poses (the landmarks only are adjusted). Per"
  echo "landmark, from its observation in the nearest camera: the signed offset along the true"
  echo "surface's normal (positive: towards the camera), from the rendered depth; landmarks more than"
  echo "5 cm off are left out as mismatches. sem: standard error of the mean. The last table gives"
  echo "every observation's keypoint row minus the landmark's projection, by the distance the"
  echo "keypoint is seen from (positive: lower in the image): an offset that changes with that"
  echo "distance is not absorbed by the landmark and moves the cameras (their direction of travel:"
  echo "[travel_direction.md](travel_direction.md))."
  echo
  python3 scripts/landmark_offset_table.py table "${arguments[@]}"
  if [ ${#adjusted[@]} -gt 0 ]; then
    echo
    echo "At the joint adjuster's poses (default options; the front ends of"
    echo "\`scripts/benchmark_uncertainty.sh\`), no truth involved: the keypoint rows against"
    echo "their landmark's projection for the landmarks 1.65 m (+- 0.35 m) under the observing"
    echo "camera, the road, by the distance they are seen from. kitti_odometry: the real KITTI"
    echo "odometry sample."
    echo
    python3 scripts/landmark_offset_table.py road_rows 1.65 "${adjusted[@]}"
  fi
} > "$kDoc"
cat "$kDoc"
