# Sourced by the benchmarks that look at COLMAP's own estimates on a simulated front end with the
# truth as the start (scripts/benchmark_landmark_offsets.sh, scripts/benchmark_travel_direction.sh).
#   true_pose_landmarks COLMAP RUN: COLMAP's point_triangulator on RUN/ws/database.db at the true
#     camera poses of RUN/dataset (the landmarks only are adjusted), into
#     RUN/true_pose_landmarks/triangulated (also as TXT); kept if already there.
#   family_joint_runs SCENE SEEDS RESULTS: the front ends and joint runs of
#     scripts/benchmark_uncertainty.sh for SCENE's seeds 1..SEEDS in $work (made there unless
#     already there; VARIANT and JOINT_OPTIONS as there), their results copied to RESULTS.
#   images_only_adjustment COLMAP RUN: then COLMAP's bundle_adjuster on that model (poses and
#     landmarks, the intrinsics fixed: the images' own optimum near the truth), into
#     RUN/true_pose_landmarks/adjusted (also as TXT); kept if already there.
true_pose_landmarks() {
  local colmap=$1 run=$2
  local out="$run/true_pose_landmarks"
  [ -e "$out/triangulated/points3D.txt" ] && return 0
  rm -rf "$out" && mkdir -p "$out/input" "$out/triangulated"
  "$colmap" model_converter --input_path "$run/ws/sparse/initial" --output_path "$out/input" \
    --output_type TXT > "$out/log.txt" 2>&1
  python3 scripts/landmark_offset_table.py true_model "$out/input" \
    "$run/dataset/ground_truth/cam_from_world.txt" "$out/true_poses"
  cp "$run/ws/database.db" "$out/database.db"  # the triangulator writes to its database
  "$colmap" point_triangulator --database_path "$out/database.db" \
    --image_path "$run/dataset/images" --input_path "$out/true_poses" \
    --output_path "$out/triangulated" --Mapper.ba_refine_focal_length 0 \
    --Mapper.ba_refine_extra_params 0 >> "$out/log.txt" 2>&1
  "$colmap" model_converter --input_path "$out/triangulated" \
    --output_path "$out/triangulated" --output_type TXT >> "$out/log.txt" 2>&1
}
images_only_adjustment() {
  local colmap=$1 run=$2
  local out="$run/true_pose_landmarks"
  true_pose_landmarks "$colmap" "$run"
  [ -e "$out/adjusted/images.txt" ] && return 0
  rm -rf "$out/adjusted" && mkdir -p "$out/adjusted"
  "$colmap" bundle_adjuster --input_path "$out/triangulated" --output_path "$out/adjusted" \
    --BundleAdjustment.refine_focal_length 0 --BundleAdjustment.refine_principal_point 0 \
    --BundleAdjustment.refine_extra_params 0 >> "$out/log.txt" 2>&1
  "$colmap" model_converter --input_path "$out/adjusted" --output_path "$out/adjusted" \
    --output_type TXT >> "$out/log.txt" 2>&1
}
family_joint_runs() {
  local scene=$1 seeds=$2
  echo "== $scene, $seeds seeds: front ends and joint runs (${VARIANT:-default})"
  WORK_DIR="$work" SCENES="$scene" SEEDS="$seeds" DRIVE_SEEDS="$seeds" \
    DOC="$work/uncertainty-${VARIANT:-default}.md" bash scripts/benchmark_uncertainty.sh > /dev/null
  cp "$work/results-${VARIANT:-default}.tsv" "$3"
}
