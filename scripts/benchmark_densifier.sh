#!/usr/bin/env bash
# The densifier's per-station cost at real-capture sizes (1028x752 .. 4112x3008 images, 0.1 .. 1.6 M
# LiDAR points in view) on a synthetic step-edge scene. Writes docs/benchmarks/densifier.md.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
source scripts/configure.sh
configure_build build
cmake --build build --target densifier_benchmark >/dev/null
table=$(build/bin/densifier_benchmark)
mkdir -p docs/benchmarks
{
  echo "# Densifier: cost per station"
  echo
  echo "Written by \`scripts/benchmark_densifier.sh\` on $(date -u +%Y-%m-%d) ($(nproc) cores)."
  echo "Synthetic station (camera frame): a wall 3 m away and a 0.8 x 0.6 m box face at 2.4 m (step"
  echo "edges all round), LiDAR 0.15 m to the side with 1 cm range noise, points uniformly over the view;"
  echo "stereo = truth with 5 % holes and 2 % of pixels 2 cm off. \"build surface\": 5 mm thinning,"
  echo "shifted-neighbourhood PCA at 4 cm, curvature at 10 cm (lidar/lidar_surface.h). \"refine map\":"
  echo "splatting, fold 1 and fold 2 over every pixel (lidar/lidar_depth_refinement.h). Default options."
  echo "Reading the cloud and the maps and writing the outputs are not included."
  echo
  echo "$table"
} > docs/benchmarks/densifier.md
cat docs/benchmarks/densifier.md
