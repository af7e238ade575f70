#!/usr/bin/env bash
# A variant of the joint adjuster against its default on the same front ends: per family, the
# front ends and runs of scripts/benchmark_uncertainty.sh with the default options and with the
# variant's, then scripts/variant_table.py compares the two. Writes docs/benchmarks/VARIANT.md (DOC
# to write another page).
#   VARIANT        the variant's name (required), e.g. oblique_offset
#   JOINT_OPTIONS  its joint_adjuster options (required), e.g. "--estimate_oblique_offset 1"
#   RUNS           families and their number of seeds, "SCENE:SEEDS ..." (default: the drives, 10
#                  seeds each, and the real KITTI sample; kitti_odometry takes any number)
#   WORK_DIR       keep front ends and runs there (default: a temporary folder, removed); front ends
#                  and runs already there are not made again
#   PIXEL_SAMPLES, BUILD_DIR, CLI: as for benchmark_uncertainty.sh
set -euo pipefail
cd "$(dirname "$0")/.."
: "${VARIANT:?name the variant (VARIANT=...)}"
: "${JOINT_OPTIONS:?give the joint_adjuster options of the variant (JOINT_OPTIONS=...)}"
source scripts/configure.sh
use_work_dir
readonly kRuns="${RUNS:-street_drive:10 street_drive_stereo:10 straight_drive:10 kitti_layout_drive:10 kitti_odometry:1}"
: > "$work/variant-default.tsv"
: > "$work/variant-$VARIANT.tsv"
for entry in $kRuns; do
  scene="${entry%%:*}" seeds="${entry#*:}"
  for name in default "$VARIANT"; do
    options=""
    [ "$name" = default ] || options="$JOINT_OPTIONS"
    echo "== $scene, $seeds seeds, $name"
    WORK_DIR="$work" VARIANT="$name" JOINT_OPTIONS="$options" SCENES="$scene" SEEDS="$seeds" \
      DRIVE_SEEDS="$seeds" DOC="$work/uncertainty-$name.md" bash scripts/benchmark_uncertainty.sh
    cat "$work/results-$name.tsv" >> "$work/variant-$name.tsv"
  done
done
mkdir -p docs/benchmarks
python3 scripts/variant_table.py "$work/variant-default.tsv" "$work/variant-$VARIANT.tsv" \
  "$VARIANT" "$JOINT_OPTIONS" > "${DOC:-docs/benchmarks/$VARIANT.md}"
echo "wrote ${DOC:-docs/benchmarks/$VARIANT.md}"
