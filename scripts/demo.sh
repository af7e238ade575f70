#!/usr/bin/env bash
# The main job, on the embedded default dataset: installs what is missing, builds, simulates the
# paper's T-specimen capture (25 stations) into a workspace and runs the pipeline on it.
#   WORKSPACE      where to put it (default: workspace/)
#   LIDAR_POINTS   LiDAR rays per station (default 400000; the paper's captures have ~1.6 M)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
readonly kWorkspace="${WORKSPACE:-workspace}"
source scripts/configure.sh
configure_build build
cmake --build build -j "$(nproc)" --target colmap_lidar_cli
readonly cli=build/bin/colmap-lidar
start=$SECONDS

echo "== 1. simulate the default t_specimen dataset"
mkdir -p "$kWorkspace"
$cli simulate_dataset --scene t_specimen --output_path "$kWorkspace/dataset" \
  --lidar_points "${LIDAR_POINTS:-400000}" --overwrite 1

echo "== 2. the pipeline: import (COLMAP SIFT), stereo depth, depth priors, LiDAR registration,"
echo "         initialisation (hand-eye cam_from_lidar: the guess is not used), joint adjustment,"
echo "         dense model (LiDAR-refined stereo), evaluation"
$cli pipeline --dataset_path "$kWorkspace/dataset" --workspace_path "$kWorkspace" --PoseInitializer.use_guess 0 \
  --overwrite 1 2>&1 | grep -v '^I20'

echo "== 3. accuracy of the reconstruction against the simulator's ground truth"
$cli evaluate_calibration --dataset_path "$kWorkspace/dataset" --input_path "$kWorkspace/sparse/joint" \
  2>&1 | grep 'evaluate_calibration:'
$cli evaluate_model --model_path "$kWorkspace/dense/fused.ply" \
  --ground_truth_path "$kWorkspace/dataset/ground_truth/surface.ply" \
  --truth_from_model "$kWorkspace/evaluation/truth_from_model.txt" \
  --output_path "$kWorkspace/evaluation/model" 2>&1 | grep -A3 'evaluate_model: mean'

echo "== 4. the same stereo depth without LiDAR refinement, for comparison"
$cli densifier --input_path "$kWorkspace/sparse/joint" --dataset_path "$kWorkspace/dataset" \
  --depth_path "$kWorkspace/stereo" --output_path "$kWorkspace/dense_unrefined" \
  --refine_with_lidar 0 2>&1 | grep 'stations in'
$cli evaluate_model --model_path "$kWorkspace/dense_unrefined/fused.ply" \
  --ground_truth_path "$kWorkspace/dataset/ground_truth/surface.ply" \
  --truth_from_model "$kWorkspace/evaluation/truth_from_model.txt" \
  --output_path "$kWorkspace/evaluation/model_unrefined" 2>&1 | grep -A3 'evaluate_model: mean'

cat <<MSG

== Summary ($((SECONDS - start)) s)
  dataset          $kWorkspace/dataset (25 stations; images, LiDAR clouds, ground truth)
  stereo depth     $kWorkspace/stereo/{depth_maps,confidence_maps,previews}/, stereo.json
  database         $kWorkspace/database.db (COLMAP's images, SIFT, matches + depth_priors, lidar_frames, rig)
  LiDAR graph      $kWorkspace/lidar/{pairs.txt, lidar_poses.txt, summary.txt}
  initial model    $kWorkspace/sparse/initial (COLMAP model, cam_from_lidar.txt, initialization.json)
  refined model    $kWorkspace/sparse/joint (COLMAP model, cam_from_lidar.txt, report.json, plots)
  dense model      $kWorkspace/dense/{fused.ply, lidar_map.ply, densifier.json, stereo/previews/}
                   and COLMAP's dense workspace there (colmap stereo_fusion / poisson_mesher run on it)
  evaluation       $kWorkspace/evaluation/{metrics.json, truth_from_model.txt, model/}
MSG
