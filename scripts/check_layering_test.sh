#!/usr/bin/env bash
# The layering check must fail on what it guards: on a copy of the sources, each planted violation
# alone (an upward include inside bridge/, an include between two folders of one level, a source
# directly in bridge/, COLMAP in lidar/) makes scripts/check_layering.sh exit 1 and name the file;
# the unplanted copy passes.
set -uo pipefail
cd "$(dirname "$0")/.."
readonly kCheck="$PWD/scripts/check_layering.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0

fresh_copy() {
  rm -rf "$work/tree"
  mkdir -p "$work/tree"
  cp -r lidar colmap_ext bridge tests "$work/tree/"
}

# plant FILE LINE: appends LINE to FILE in a fresh copy; the check must fail naming FILE.
expect_failure() {
  fresh_copy
  echo "$2" >> "$work/tree/$1"
  local output
  output=$(bash "$kCheck" "$work/tree" 2>&1)
  if [[ $? -eq 0 || "$output" != *"$1"* ]]; then
    echo "FAIL: planting '$2' in $1 was not reported:"$'\n'"$output"
    failures=$((failures + 1))
  else
    echo "ok: '$2' in $1 reported"
  fi
}

fresh_copy
if ! bash "$kCheck" "$work/tree" >/dev/null; then
  echo "FAIL: the unplanted copy does not pass"
  failures=$((failures + 1))
fi
expect_failure bridge/joint/joint_adjuster.cc '#include "bridge/survey/survey_planner.h"'
expect_failure bridge/simulation/scene.cc '#include "bridge/joint/joint_adjuster.h"'
expect_failure bridge/survey/survey_planner.cc '#include "bridge/exe/steps.h"'
expect_failure bridge/dense/densifier.cc '#include "bridge/initialization/hand_eye.h"'
expect_failure lidar/kd_tree.cc '#include "colmap/scene/reconstruction.h"'
expect_failure bridge/stray.cc '// a source outside the concern folders'
exit $((failures > 0))
