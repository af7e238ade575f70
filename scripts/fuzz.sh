#!/usr/bin/env bash
# Fuzzes every parser of user files with libFuzzer (tests/fuzz): builds the targets with clang,
# AddressSanitizer and UndefinedBehaviorSanitizer in build-fuzz, seeds each corpus with
# tests/fuzz/corpus/<target>/ (small valid files of the format and regression_* inputs that once crashed
# us or made us allocate), and runs each target for SECONDS_PER_TARGET (default 60) with
# a 1 GiB allocation limit (a header claiming 10^12 points must be refused, not allocated) and a 10 s
# per-input timeout. Findings are written to build-fuzz/findings/<target>/ and fail the script; once
# fixed, copy each into tests/fuzz/corpus/<target>/regression_<what>.<ext> (unit/fuzz_corpus replays
# the corpus in every test run and requires regression_* inputs to be refused with the file named).
# Prints the executions and the outcome per target.
#   SECONDS_PER_TARGET  (default 60)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
readonly kColmapPrefix="${COLMAP_LIDAR_COLMAP_PREFIX:-$HOME/.cache/colmap-lidar/colmap-3.10}"
readonly kSeconds="${SECONDS_PER_TARGET:-60}"
readonly kTargets=(fuzz_cloud_pcd fuzz_cloud_ply fuzz_cloud_bin fuzz_cloud_xyz fuzz_rig_json
                   fuzz_cam_from_world_txt fuzz_cam_from_lidar_txt fuzz_pairs_txt fuzz_depth_map)
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCOLMAP_LIDAR_FUZZ=ON -DCOLMAP_LIDAR_BUILD_TESTS=OFF \
  -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer" \
  -DCMAKE_PREFIX_PATH="$kColmapPrefix" >/dev/null
cmake --build build-fuzz -j "$(nproc)" --target "${kTargets[@]}"

export ASAN_OPTIONS="detect_leaks=0:allocator_may_return_null=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
status=0
for target in "${kTargets[@]}"; do
  corpus=build-fuzz/corpus/$target findings=build-fuzz/findings/$target
  mkdir -p "$corpus" "$findings"
  cp tests/fuzz/corpus/"$target"/* "$corpus/"
  log=build-fuzz/$target.log
  if build-fuzz/bin/$target "$corpus" -max_total_time="$kSeconds" -malloc_limit_mb=1024 \
      -rss_limit_mb=2048 -timeout=10 -artifact_prefix="$findings/" -print_final_stats=1 >"$log" 2>&1; then
    result=clean
  else
    result="FINDING (see $log, $findings)"
    status=1
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  printf '%-26s %10s executions in %s s: %s\n' "$target" "$runs" "$kSeconds" "$result"
done
exit $status
