#!/usr/bin/env bash
# The libFuzzer harnesses of fuzz/ (docs/reliability.md).
#   scripts/fuzz.sh build                 configure and build build-fuzz/ (clang)
#   scripts/fuzz.sh run NAME [SECONDS] [libFuzzer flags...]
#       fuzzes harness NAME (default 600 s) from fuzz/corpus/NAME into a
#       scratch corpus build-fuzz/work/NAME/corpus; crash inputs land in
#       build-fuzz/work/NAME/ (crash-*, timeout-*, oom-*)
#   scripts/fuzz.sh merge NAME            minimises fuzz/corpus/NAME plus the
#       scratch corpus back into fuzz/corpus/NAME (-merge=1); scratch inputs
#       over 16 KB are left out so that the committed corpora stay small
#       (only the .sgw seeds, whole SGPR models, are larger)
#   scripts/fuzz.sh list                  the harness names
# Every run is capped: inputs at the harness's max_len, 2 GB of memory
# (-rss_limit_mb, and -malloc_limit_mb for one allocation) and 10 s per input.
set -euo pipefail
cd "$(dirname "$0")/.."

BUILD_DIR="${FUZZ_BUILD_DIR:-build-fuzz}"
# Cheaper AddressSanitizer bookkeeping while fuzzing (about twice the
# executions per second): no allocation stacks, a small quarantine. To see a
# crash in full, run the harness on the crash file with ASAN_OPTIONS unset.
export ASAN_OPTIONS="${ASAN_OPTIONS:-malloc_context_size=0:quarantine_size_mb=16}"

# Largest input per harness: a few hundred points, lines or nodes reach every
# check; .sgw needs room for a whole SGPR model (196426 bytes), ouster_packet
# for two 32-pixel packets or one 128-pixel one (up to 16640 bytes).
declare -A MAX_LEN=(
  [scan]=4096 [label]=1024 [kitti_poses]=4096 [tum_poses]=4096 [calib]=8192
  [times]=2048 [sgw]=200000 [graph_json]=8192 [config]=8192 [segmenter_spec]=4096 [sensor_profile]=4096
  [pcd]=4096 [ply]=4096 [pointcloud2]=4096 [kitti_raw]=2048 [rosbag]=16384 [map]=8192
  [pointcloud2_cdr]=4096 [mcap]=16384 [rosbag2]=32768
  [ouster_packet]=20000 [velodyne_packet]=8192 [path_rules]=256
)

build() {
  if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
    cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DSALOAM_FUZZ=ON \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG"
  fi
  local targets=()
  for name in "${!MAX_LEN[@]}"; do targets+=("fuzz_$name"); done
  cmake --build "$BUILD_DIR" --target "${targets[@]}"
}

check_name() {
  [ -n "${MAX_LEN[$1]:-}" ] || { echo "unknown harness '$1' (scripts/fuzz.sh list)" >&2; exit 1; }
}

limits() {
  echo "-max_len=${MAX_LEN[$1]} -rss_limit_mb=2048 -malloc_limit_mb=2048 -timeout=10"
}

command="${1:-}"
[ $# -gt 0 ] && shift
case "$command" in
  build) build ;;
  list) printf '%s\n' "${!MAX_LEN[@]}" | sort ;;
  run)
    name="${1:?harness name}"; check_name "$name"; shift
    seconds="${1:-600}"; [ $# -gt 0 ] && shift
    work="$BUILD_DIR/work/$name"
    mkdir -p "$work/corpus"
    # shellcheck disable=SC2046
    "$BUILD_DIR/fuzz/fuzz_$name" $(limits "$name") -max_total_time="$seconds" -print_final_stats=1 \
      -artifact_prefix="$work/" "$@" "$work/corpus" "fuzz/corpus/$name"
    ;;
  merge)
    name="${1:?harness name}"; check_name "$name"
    work="$BUILD_DIR/work/$name"
    merged="$work/merged" small="$work/small"
    rm -rf "$merged" "$small" && mkdir -p "$merged" "$small"
    find "$work/corpus" -type f -size -16385c -exec cp {} "$small/" \;
    # shellcheck disable=SC2046
    "$BUILD_DIR/fuzz/fuzz_$name" $(limits "$name") -merge=1 "$merged" "fuzz/corpus/$name" "$small"
    rm -rf "fuzz/corpus/$name" && mkdir -p "fuzz/corpus/$name"
    cp "$merged"/* "fuzz/corpus/$name/"
    echo "fuzz/corpus/$name: $(ls "fuzz/corpus/$name" | wc -l) files, $(du -sb "fuzz/corpus/$name" | cut -f1) bytes"
    ;;
  *)
    echo "usage: scripts/fuzz.sh build | list | run NAME [SECONDS] [flags...] | merge NAME" >&2
    exit 1
    ;;
esac
