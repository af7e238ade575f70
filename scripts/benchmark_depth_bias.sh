#!/usr/bin/env bash
# The stereo depth's bias field (joint_adjuster --estimate_depth_bias 1) against the default (the
# field held at zero), on the same front ends: the simulated stereo drives and the real KITTI
# odometry sample (scripts/benchmark_uncertainty.sh, whose variables apply: DRIVE_SEEDS, default
# 5; PIXEL_SAMPLES; WORK_DIR; CLI). Writes docs/benchmarks/depth_bias.md (DOC to write another page).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/configure.sh
use_work_dir
export WORK_DIR="$work" SCENES="street_drive_stereo kitti_odometry"
export DRIVE_SEEDS="${DRIVE_SEEDS:-5}"
DOC="$work/default.md" bash scripts/benchmark_uncertainty.sh > /dev/null
VARIANT=depth_bias JOINT_OPTIONS="--estimate_depth_bias 1" DOC="$work/depth_bias.md" \
  bash scripts/benchmark_uncertainty.sh > /dev/null
readonly kDoc="${DOC:-docs/benchmarks/depth_bias.md}"
{
  echo "# The stereo depth's bias field, estimated or held at zero"
  echo
  echo "Written by \`scripts/benchmark_depth_bias.sh\` on $(date +%F): the joint adjuster with"
  echo "\`--estimate_depth_bias 1\` and with its default, on the same front ends"
  echo "([joint_adjuster.md](../joint_adjuster.md), \"The stereo depth's bias field\")."
  echo
  echo "## Held at zero (the default)"
  tail -n +2 "$work/default.md"
  echo
  echo "## Estimated (\`--estimate_depth_bias 1\`)"
  tail -n +2 "$work/depth_bias.md"
} > "$kDoc"
cat "$kDoc"
