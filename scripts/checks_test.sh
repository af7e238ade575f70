#!/usr/bin/env bash
# The source checks must fail on what they guard. On a copy of the sources, each planted violation
# alone makes its check exit 1 and name the file; the unplanted copy passes both.
#   scripts/check_layering.sh: an upward include inside bridge/, an include between two folders of
#     one level, a source directly in bridge/, COLMAP in lidar/, lidar/ beyond its utilities base in
#     colmap_ext/ or in the base itself;
#   scripts/check_functions.py: a function body of 61 lines, a function of 7 parameters.
set -uo pipefail
cd "$(dirname "$0")/.."
readonly kLayering="bash $PWD/scripts/check_layering.sh"
readonly kFunctions="python3 $PWD/scripts/check_functions.py"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0

fresh_copy() {
  rm -rf "$work/tree"
  mkdir -p "$work/tree"
  cp -r lidar colmap_ext bridge tests "$work/tree/"
}

# expect_failure CHECK FILE TEXT [WHAT]: TEXT appended to FILE in a fresh copy must make CHECK fail
# with a message naming FILE (and then WHAT).
expect_failure() {
  fresh_copy
  printf '%s\n' "$3" >> "$work/tree/$2"
  local output
  output=$($1 "$work/tree" 2>&1)
  if [[ $? -eq 0 || "$output" != *"$2"*"${4:-}"* ]]; then
    echo "FAIL: planting in $2 was not reported by $1:"$'\n'"$output"
    failures=$((failures + 1))
  else
    echo "ok: planting in $2 reported ${4:-}"
  fi
}

fresh_copy
for check in "$kLayering" "$kFunctions"; do
  if ! $check "$work/tree" >/dev/null; then
    echo "FAIL: the unplanted copy does not pass $check"
    failures=$((failures + 1))
  fi
done
expect_failure "$kLayering" bridge/joint/joint_adjuster.cc '#include "bridge/survey/survey_planner.h"'
expect_failure "$kLayering" bridge/simulation/scene.cc '#include "bridge/joint/joint_adjuster.h"'
expect_failure "$kLayering" bridge/survey/survey_planner.cc '#include "bridge/exe/steps.h"'
expect_failure "$kLayering" bridge/dense/densifier.cc '#include "bridge/initialization/hand_eye.h"'
expect_failure "$kLayering" lidar/kd_tree.cc '#include "colmap/scene/reconstruction.h"'
expect_failure "$kLayering" colmap_ext/stereo_depth.cc '#include "lidar/kd_tree.h"'
expect_failure "$kLayering" lidar/util/statistics.cc '#include "lidar/point_cloud.h"'
expect_failure "$kLayering" bridge/stray.cc '// a source outside the concern folders'
long_body=$(printf 'int PlantedLong() {\n'; for i in $(seq 1 59); do printf '  int v%d = %d;\n' "$i" "$i"; done;
            printf '  return 0;\n}')
expect_failure "$kFunctions" lidar/kd_tree.cc "$long_body" "body of 61 lines"
expect_failure "$kFunctions" bridge/joint/joint_adjuster.cc \
  "int PlantedWide(int a, int b, int c, int d, int e, int f, int g) { return a + b + c + d + e + f + g; }" \
  "7 parameters"
exit $((failures > 0))
