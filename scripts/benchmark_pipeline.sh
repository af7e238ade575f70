#!/usr/bin/env bash
# The whole job at three sizes, step by step (wall, CPU, peak resident memory from the pipeline's
# WS/pipeline_steps.csv), with the accuracy at the end and, for the same left images, what COLMAP
# alone needs for a sparse model (feature_extractor + exhaustive_matcher + mapper, defaults). Appends
# one dated section per run to docs/benchmarks/pipeline.md, so that a regression shows.
#   scripts/benchmark_pipeline.sh [C] [A] [B]   (default: C A B)
#     A  25 stations around the T specimen, 1.6 M rays, --image_scale 2 (2056x1504): the seed's scale
#     B  100 stations around bridge_pier, 400 k rays, 1028x752: scale
#     C  the demo's default (25 stations, 400 k rays, 1028x752)
#   BENCH_DIR   where datasets and workspaces go (default: /tmp/colmap-lidar-benchmark)
#   BUILD_DIR   build directory (default: build)
#   COLMAP_ALONE_B=1   also run COLMAP alone on B (exhaustive matching of 100 images: ~30 min)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
readonly kColmapPrefix="${COLMAP_LIDAR_COLMAP_PREFIX:-$HOME/.cache/colmap-lidar/colmap-3.10}"
readonly kBench="${BENCH_DIR:-/tmp/colmap-lidar-benchmark}"
readonly kDoc=docs/benchmarks/pipeline.md
readonly kBuildDir="${BUILD_DIR:-build}"
cmake -S . -B "$kBuildDir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$kColmapPrefix" >/dev/null
cmake --build "$kBuildDir" -j "$(nproc)" --target colmap_lidar_cli >/dev/null
readonly cli="$PWD/$kBuildDir/bin/colmap-lidar"
readonly colmap="$kColmapPrefix/bin/colmap"
configs=("$@")
[ ${#configs[@]} -gt 0 ] || configs=(C A B)

simulate_args() {
  case "$1" in
    A) echo "--scene t_specimen --num_stations 25 --lidar_points 1600000 --image_scale 2" ;;
    B) echo "--scene bridge_pier --num_stations 100 --lidar_points 400000" ;;
    C) echo "--scene t_specimen --num_stations 25 --lidar_points 400000" ;;
    *) echo "unknown configuration '$1' (A, B or C)" >&2; exit 2 ;;
  esac
}

# Seconds of wall time of a command (its output goes to a log).
timed() {
  local log=$1 start
  shift
  start=$(date +%s.%N)
  "$@" >"$log" 2>&1
  awk -v a="$(date +%s.%N)" -v b="$start" 'BEGIN{printf "%.1f", a - b}' 
}

json_value() {  # file key
  python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print('%.4g' % d[sys.argv[2]])" "$1" "$2" \
    2>/dev/null || echo "n/a"
}

colmap_alone() {  # dataset folder -> "extract match mapper total" seconds
  local dir=$1/colmap_alone e m p
  rm -rf "$dir" && mkdir -p "$dir/sparse"
  e=$(timed "$dir/extract.log" "$colmap" feature_extractor --database_path "$dir/db.db" \
    --image_path "$1/dataset/images/left" --SiftExtraction.use_gpu 0)
  m=$(timed "$dir/match.log" "$colmap" exhaustive_matcher --database_path "$dir/db.db" \
    --SiftMatching.use_gpu 0)
  p=$(timed "$dir/mapper.log" "$colmap" mapper --database_path "$dir/db.db" \
    --image_path "$1/dataset/images/left" --output_path "$dir/sparse")
  printf '%.0f %.0f %.0f %.0f\n' "$e" "$m" "$p" "$(awk -v a="$e" -v b="$m" -v c="$p" 'BEGIN{print a + b + c}')"
}

run_config() {
  local name=$1 dir=$kBench/$1 args
  args=$(simulate_args "$name")
  mkdir -p "$dir"
  echo "[benchmark] $name: simulating ($args)" >&2
  # shellcheck disable=SC2086
  "$cli" simulate_dataset $args --output_path "$dir/dataset" --overwrite 1 >"$dir/simulate.log" 2>&1
  echo "[benchmark] $name: pipeline (no guess)" >&2
  rm -rf "$dir/ws"
  local total
  total=$(timed "$dir/pipeline.log" "$cli" pipeline --dataset_path "$dir/dataset" \
    --workspace_path "$dir/ws" --PoseInitializer.use_guess 0)
  local ce cm cp ct
  if [ "$name" = B ] && [ "${COLMAP_ALONE_B:-0}" != 1 ]; then
    # Exhaustive matching of 100 images is 4,950 pairs (about half an hour here); B's goals are
    # memory and time per station. COLMAP_ALONE_B=1 runs it anyway.
    ce=n/a cm=n/a cp=n/a ct=n/a
  else
    echo "[benchmark] $name: COLMAP alone on the left images" >&2
    read -r ce cm cp ct < <(colmap_alone "$dir")
  fi
  local cal=$dir/ws/evaluation/metrics.json dense=$dir/ws/evaluation/model/metrics.json
  echo
  echo "### $name: $args"
  echo
  echo "| step | wall s | CPU s | peak MiB |"
  echo "|---|---:|---:|---:|"
  grep -v '^#' "$dir/ws/pipeline_steps.csv" | awk -F, '{printf "| %s | %s | %s | %s |\n", $1, $3, $4, $5}'
  local peak
  peak=$(grep -v '^#' "$dir/ws/pipeline_steps.csv" | awk -F, 'BEGIN{m=0} {if ($5>m) m=$5} END{print m}')
  printf '| **pipeline** | **%.0f** | | **%s** |\n' "$total" "$peak"
  echo
  if [ "$ct" = n/a ]; then
    echo "- COLMAP alone: not run (COLMAP_ALONE_B=1 runs it)"
  else
    echo "- COLMAP alone (left images): extraction $ce s, exhaustive matching $cm s, mapper $cp s;" \
      "total $ct s. **pipeline / COLMAP = $(awk -v a="$total" -v b="$ct" 'BEGIN{printf "%.2f", a / b}')**"
  fi
  local stations
  stations=$(find "$dir/dataset/lidar" -type f | wc -l)
  echo "- per station: $(awk -v a="$total" -v n="$stations" 'BEGIN{printf "%.1f", a / n}') s"
  echo "- cam_from_lidar: $(json_value "$cal" cam_from_lidar_rotation_error_deg) deg," \
    "$(json_value "$cal" cam_from_lidar_translation_error_mm) mm; station positions" \
    "$(json_value "$cal" pose_position_error_mean_mm) mm mean; dense model" \
    "$(json_value "$dense" mean_m) m mean, completeness at 5 mm $(json_value "$dense" completeness_5mm)"
}

mkdir -p "$kBench" docs/benchmarks
section=$(
  echo
  echo "## $(date -u +%Y-%m-%d) ($(nproc) cores, $(free -g | awk '/Mem:/{print $2}') GiB, commit $(git rev-parse --short HEAD))"
  for name in "${configs[@]}"; do run_config "$name"; done
)
if [ ! -f "$kDoc" ]; then
  {
    echo "# The pipeline end to end: time, memory and accuracy per step"
    echo
    echo "Written by \`scripts/benchmark_pipeline.sh\` (one dated section per run, newest last). Each"
    echo "configuration is simulated, then \`colmap-lidar pipeline\` runs without a guess of"
    echo "cam_from_lidar; its steps' wall time, CPU time (both cores count) and peak resident memory"
    echo "come from the workspace's \`pipeline_steps.csv\`. \"COLMAP alone\" is COLMAP 3.10's own sparse"
    echo "model of the same left images with default options (CPU SIFT), for a ratio that does not"
    echo "depend on the machine. Accuracy: \`evaluate_calibration\` and \`evaluate_model\` against the"
    echo "simulator's truth."
  } >"$kDoc"
fi
echo "$section" >>"$kDoc"
echo "$section"
