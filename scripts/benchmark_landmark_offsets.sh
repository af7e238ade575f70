#!/usr/bin/env bash
# Where COLMAP's landmarks sit relative to the true surface on the simulated mono street drive, with
# no estimate involved: per seed, the pipeline's front end (scripts/benchmark_uncertainty.sh, SCENES
# street_drive, made there unless WORK_DIR already has it), then COLMAP's point_triangulator on its
# database at the true camera poses, then per landmark its signed offset along the true surface's
# normal (scripts/landmark_offset_table.py), tabulated by the surface (road, walls) and by distance
# and obliqueness. E_m pulls landmarks onto the LiDAR's surfaces; an offset common to a surface ends
# in cam_from_lidar's translation along its normal. Writes docs/benchmarks/landmark_offsets.md.
#   SEEDS     seeds 1..SEEDS (default 4)
#   WORK_DIR  keep the runs there (default: a temporary folder, removed); shared with
#             benchmark_uncertainty.sh
#   CLI, BUILD_DIR  as in benchmark_uncertainty.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
source scripts/configure.sh
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
  out="$run/true_pose_landmarks"
  echo "[street_drive $seed] triangulating at the true poses ..."
  if [ ! -e "$out/triangulated/points3D.txt" ]; then
    rm -rf "$out" && mkdir -p "$out/input" "$out/triangulated"
    "$kColmap" model_converter --input_path "$run/ws/sparse/initial" --output_path "$out/input" \
      --output_type TXT > "$out/log.txt" 2>&1
    python3 scripts/landmark_offset_table.py true_model "$out/input" \
      "$run/dataset/ground_truth/cam_from_world.txt" "$out/true_poses"
    cp "$run/ws/database.db" "$out/database.db"  # the triangulator writes to its database
    "$kColmap" point_triangulator --database_path "$out/database.db" \
      --image_path "$run/dataset/images" --input_path "$out/true_poses" \
      --output_path "$out/triangulated" --Mapper.ba_refine_focal_length 0 \
      --Mapper.ba_refine_extra_params 0 >> "$out/log.txt" 2>&1
    "$kColmap" model_converter --input_path "$out/triangulated" \
      --output_path "$out/triangulated" --output_type TXT >> "$out/log.txt" 2>&1
  fi
  arguments+=("$seed:$out/triangulated:$run/dataset")
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
  echo "5 cm off are left out as mismatches. sem: standard error of the mean."
  echo
  python3 scripts/landmark_offset_table.py table "${arguments[@]}"
} > "$kDoc"
cat "$kDoc"
