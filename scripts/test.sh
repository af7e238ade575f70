#!/usr/bin/env bash
# Installs what is missing (scripts/setup.sh), builds colmap-lidar and runs every test: the layering
# and function size checks, the unit tests beside the sources and the integration tests under tests/.
#   scripts/test.sh           every test (CTest labels unit, integration, slow)
#   scripts/test.sh --quick   without the slow ones (ctest -LE slow): a few minutes
#   SANITIZE=1                then the unit and integration tests again under ASan + UBSan
#                             (scripts/sanitize.sh: a second build of everything, about 30 min more
#                             on a fresh 2-core machine, which CI's budget of 45 min leaves no room for)
#   BUILD_DIR  build directory (default: build)
#   JOBS       parallel build jobs (default: nproc)
set -euo pipefail
cd "$(dirname "$0")/.."
ctest_selection=()
if [[ "${1:-}" == "--quick" ]]; then
  ctest_selection=(-LE slow)
elif [[ $# -gt 0 ]]; then
  echo "usage: scripts/test.sh [--quick]" >&2
  exit 2
fi
bash scripts/setup.sh
# The tests write their datasets under the temporary directory (a 40-frame drive takes about 350 MB
# at its peak): a full disk shows up as a failed image or cloud write, so say how much there is.
readonly kTmpDir="${TMPDIR:-/tmp}"
readonly kFreeGb=$(df -P -BG "$kTmpDir" | awk 'NR == 2 { sub("G", "", $4); print $4 }')
echo "[test] $kFreeGb GB free in $kTmpDir"
if [[ "$kFreeGb" -lt 5 ]]; then
  echo "[test] warning: less than 5 GB free in $kTmpDir; the slow tests may fail to write" >&2
fi
readonly kBuildDir="${BUILD_DIR:-build}"
echo "[test] layering check"
bash scripts/check_layering.sh
echo "[test] function size check"
python3 scripts/check_functions.py
echo "[test] configuring and building in $kBuildDir"
source scripts/configure.sh
configure_build "$kBuildDir"
cmake --build "$kBuildDir" -j "${JOBS:-$(nproc)}"
echo "[test] running the tests"
# In a subshell: BUILD_DIR may be nested or absolute, and the sanitizer pass runs from the root.
(cd "$kBuildDir" && ctest --output-on-failure -j "${JOBS:-$(nproc)}" "${ctest_selection[@]}")
if [[ ${#ctest_selection[@]} -eq 0 && "${SANITIZE:-0}" == 1 ]]; then
  echo "[test] the sanitizer pass (scripts/sanitize.sh)"
  bash scripts/sanitize.sh
fi
