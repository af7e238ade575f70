#!/usr/bin/env bash
# Fuzzes every parser of user files with libFuzzer (tests/fuzz): builds the targets with clang,
# AddressSanitizer and UndefinedBehaviorSanitizer in build-fuzz, seeds each corpus with small valid
# files of its format (written by this script) and tests/fuzz/regressions/, and runs each target for SECONDS (default 60) with
# a 1 GiB allocation limit (a header claiming 10^12 points must be refused, not allocated) and a 10 s
# per-input timeout. Findings are written to build-fuzz/findings/<target>/ and fail the script; copy
# them into tests/fuzz/regressions/<target>/ once fixed (tests/fuzz_regression_test.cc replays them).
# Prints executions per target (docs/reliability.md keeps them).
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

# Seeds: small valid files of each format, written here (the simulator's files are the same formats).
seeds=build-fuzz/seeds
rm -rf "$seeds" && mkdir -p "$seeds"
one='\x00\x00\x80\x3f' two='\x00\x00\x00\x40'
header='VERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\n'
printf "${header}DATA ascii\n1 2 3 4\n5 6 7 8\n" >"$seeds/ascii.pcd"
printf "${header}DATA binary\n$one$two$one$two$two$one$two$one" >"$seeds/binary.pcd"
printf 'ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n1 2 3 0 0 1\n4 5 6 0 1 0\n' >"$seeds/ascii.ply"
printf "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n$one$two$one$two$one$two" >"$seeds/le.ply"
printf "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty double x\nproperty double y\nproperty double z\nproperty uchar red\nend_header\n\x3f\xf0\0\0\0\0\0\0\x3f\xf0\0\0\0\0\0\0\x3f\xf0\0\0\0\0\0\0\x7f" >"$seeds/be.ply"
printf "$one$two$one$two$two$one$two$one" >"$seeds/a.bin"
printf '1 2 3\n4 5 6 7\n# comment\n1,2,3\n' >"$seeds/a.xyz"
cat >"$seeds/rig.json" <<'JSON'
{"left": {"model": "PINHOLE", "width": 640, "height": 480, "params": [500, 500, 320, 240]},
 "right": {"model": "PINHOLE", "width": 640, "height": 480, "params": [500, 500, 320, 240]},
 "right_from_left": {"rotation": [1, 0, 0, 0], "translation": [-0.3, 0, 0]},
 "cam_from_lidar_guess": {"rotation": [0.5, -0.5, 0.5, -0.5], "translation": [0, -0.1, 0]},
 "lidar": {"model": "VLP-16", "range_noise_m": 0.01, "sweep": {"start_azimuth_deg": 180, "counter_clockwise": true}}}
JSON
printf '# station qw qx qy qz tx ty tz\n000 1 0 0 0 0 0 0\n001 0.99 0.1 0 0 1 2 3\n' >"$seeds/poses.txt"
printf '# qw qx qy qz tx ty tz\n0.5 -0.5 0.5 -0.5 0.1 -0.2 0.05\n' >"$seeds/cam_from_lidar.txt"
printf '# target source qw qx qy qz tx ty tz inliers overlap rmse_m noise_m constraint_ratio weakest_axis determined bsc\n000 001 1 0 0 0 1 0 0 500 0.6 0.01 0.01 0.5 0,0,1 determined bsc\n' >"$seeds/pairs.txt"
printf '2&2&1&' >"$seeds/depth.bin" && printf "$one$two$one$two" >>"$seeds/depth.bin"
seed_files() {  # target -> seed files
  case "$1" in
    fuzz_cloud_pcd) echo "$seeds/ascii.pcd $seeds/binary.pcd" ;;
    fuzz_cloud_ply) echo "$seeds/ascii.ply $seeds/le.ply $seeds/be.ply" ;;
    fuzz_cloud_bin) echo "$seeds/a.bin" ;;
    fuzz_cloud_xyz) echo "$seeds/a.xyz" ;;
    fuzz_rig_json) echo "$seeds/rig.json" ;;
    fuzz_cam_from_world_txt) echo "$seeds/poses.txt" ;;
    fuzz_cam_from_lidar_txt) echo "$seeds/cam_from_lidar.txt" ;;
    fuzz_pairs_txt) echo "$seeds/pairs.txt" ;;
    fuzz_depth_map) echo "$seeds/depth.bin" ;;
  esac
}
export ASAN_OPTIONS="detect_leaks=0:allocator_may_return_null=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
status=0
for target in "${kTargets[@]}"; do
  corpus=build-fuzz/corpus/$target findings=build-fuzz/findings/$target
  mkdir -p "$corpus" "$findings"
  for f in $(seed_files "$target"); do cp "$f" "$corpus/"; done
  if [ -d "tests/fuzz/regressions/$target" ]; then cp tests/fuzz/regressions/$target/* "$corpus/" 2>/dev/null || true; fi
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
