#!/usr/bin/env bash
# Fails when a layer includes (or links) what it must not:
#   lidar/       no COLMAP, no colmap_ext/bridge/tests; its public headers (.h) include only Eigen and std
#   lidar/util/  the utilities base: nothing of lidar/ outside lidar/util/
#   colmap_ext/  of lidar/ only lidar/util/; no bridge/ or tests/
#   bridge/      no tests/; no source file outside its folders; the folders in levels, each including
#                only folders of lower levels:
#                  1  simulation (the simulator), initialization, joint, dense, baselines, evaluation
#                  2  survey (the survey planner: the joint problem on the simulator's worlds),
#                     pipeline (the steps as library calls)
#                  3  exe (the commands; nothing outside it includes it, and the bridge library's
#                     sources list none of its files)
#   all layers   no struct or class name defined in two headers (one namespace: an ODR violation)
# Prints every violation as file:line and exits 1 if there is any.
#   scripts/check_layering.sh [ROOT]   checks the tree at ROOT (default: this repository)
set -uo pipefail
cd "${1:-$(dirname "$0")/..}"
status=0
violation() { echo "layering: $1"; status=1; }

check_includes() {  # folder, regex of forbidden includes, what
  local hits
  # Unit tests (*_test.cc) may include the shared test helpers in tests/testing/, nothing else of tests/.
  hits=$(grep -rnE "^\s*#\s*include\s*[<\"]($2)" --include='*.h' --include='*.cc' "$1" |
         grep -vE '_test\.cc:[0-9]+:\s*#\s*include\s*"tests/testing/' || true)
  [ -z "$hits" ] || violation "$1 must not include $3:"$'\n'"$hits"
}

check_includes lidar 'colmap/|colmap_ext/|bridge/|tests/' "COLMAP, colmap_ext, bridge or tests"
check_includes colmap_ext 'lidar/[^u]|lidar/u[^t]|bridge/|tests/' \
  "lidar (other than the utilities base lidar/util/), bridge or tests"
check_includes lidar/util 'lidar/[^u]|lidar/u[^t]' "lidar/ outside the utilities base"
hits=$(grep -rnE '^\s*#\s*include\s*"tests/' --include='*.h' --include='*.cc' bridge |
       grep -vE '_test\.cc:[0-9]+:\s*#\s*include\s*"tests/testing/' || true)
[ -z "$hits" ] || violation "bridge/ must not include tests/:"$'\n'"$hits"

hits=$(find bridge -maxdepth 1 -type f \( -name '*.h' -o -name '*.cc' \) | sort)
[ -z "$hits" ] || violation "sources directly in bridge/ (they belong in a concern folder):"$'\n'"$hits"

# bridge/'s folders by level: a folder includes only folders of lower levels.
declare -A level=([simulation]=1 [initialization]=1 [joint]=1 [dense]=1 [baselines]=1
                  [evaluation]=1 [survey]=2 [pipeline]=2 [exe]=3)
folders=$(printf '%s\n' "${!level[@]}" | sort)
for folder in $folders; do
  [ -d "bridge/$folder" ] || violation "bridge/$folder is missing (the levels name it)"
  above=$(for other in $folders; do
            [[ $other != "$folder" && ${level[$other]} -ge ${level[$folder]} ]] && echo "$other"
          done | paste -sd'|')
  [ -z "$above" ] ||
    check_includes "bridge/$folder" "bridge/($above)/" "a bridge/ folder of its level or above"
done
for dir in bridge/*/; do
  name=$(basename "$dir")
  [[ -n "${level[$name]:-}" ]] || violation "bridge/$name has no level in scripts/check_layering.sh"
done

# Commands apart from algorithms: only bridge/exe/ includes bridge/exe/.
hits=$(grep -rnE '^\s*#\s*include\s*"bridge/exe/' --include='*.h' --include='*.cc' \
         lidar colmap_ext bridge tests | grep -v '^bridge/exe/' || true)
[ -z "$hits" ] || violation "only the commands (bridge/exe/) may include bridge/exe/:"$'\n'"$hits"
sed -n '/colmap_lidar_add_library(NAME bridge$/,/^)/p' bridge/CMakeLists.txt |
  grep -qE '_commands?\.cc|main\.cc' &&
  violation "the bridge library compiles a command (they belong in bridge/exe/)"

# lidar's public headers speak Eigen: no PCL, FLANN, nanoflann, OpenCV or Ceres in lidar/*.h.
hits=$(grep -nE '^\s*#\s*include\s*<(pcl/|flann/|nanoflann|opencv2/|ceres/)' lidar/*.h lidar/util/*.h ||
       true)
[ -z "$hits" ] || violation "lidar public headers must include only Eigen and std:"$'\n'"$hits"

# Link lines: lidar links no COLMAP; colmap_ext does not link lidar; bridge library no simulator.
grep -qE 'colmap::colmap|colmap_lidar::(colmap_ext|bridge|simulator)' lidar/CMakeLists.txt &&
  violation "lidar/CMakeLists.txt links COLMAP or another layer"
grep -qE 'colmap_lidar::(lidar|bridge|simulator)' colmap_ext/CMakeLists.txt &&
  violation "colmap_ext/CMakeLists.txt links lidar (other than colmap_lidar::util), bridge or the simulator"
grep -qE 'colmap::colmap|colmap_lidar::(lidar|colmap_ext|bridge|simulator)' lidar/util/CMakeLists.txt &&
  violation "lidar/util/CMakeLists.txt links COLMAP or a layer above the utilities base"
sed -n '/colmap_lidar_add_library(NAME bridge$/,/^)/p' bridge/CMakeLists.txt | grep -q 'simulator' &&
  violation "the bridge library links the simulator"

# One definition per type name: the layers share the namespace colmap_lidar, and two headers defining
# one struct or class name is an ODR violation the linker does not report (it merges their inline
# functions: a vector of one type reallocated with the other's layout).
hits=$(grep -HnoE '^(struct|class) [A-Za-z0-9_]+( final)? ?[:{]' lidar/*.h lidar/util/*.h colmap_ext/*.h \
         bridge/*/*.h \
         | awk -F'[: ]' '{print $4, $1 ":" $2}' | sort |
       awk '{n[$1]++; where[$1] = where[$1] " " $2} END {for (t in n) if (n[t] > 1) print t ":" where[t]}')
[ -z "$hits" ] || violation "type names defined in more than one header:"$'\n'"$hits"

[ $status -eq 0 ] && echo "layering: ok (lidar/util -> lidar | colmap_ext -> bridge -> bridge/exe (CLI))"
exit $status
